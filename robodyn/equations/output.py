"""One entry point for every output format of the equations."""

from __future__ import annotations

from collections.abc import Callable
from typing import Literal

from robodyn.equations import render_c, render_json, render_latex, render_python, render_text
from robodyn.equations.model import EquationsData
from robodyn.equations.printing import DEFAULT_PRECISION, check_precision
from robodyn.exceptions import InputError

Format = Literal["text", "latex", "pdf", "json", "python", "c"]
FORMATS: tuple[Format, ...] = ("text", "latex", "pdf", "json", "python", "c")


def render(equations: EquationsData, format: Format = "text", *, precision: int = DEFAULT_PRECISION) -> str | bytes:
    """The equations in one of :data:`FORMATS` (``"pdf"`` gives bytes).

    Args:
        equations: From :func:`robodyn.equations.derive_equations`.
        format: One of :data:`FORMATS`.
        precision: Significant digits of the numbers in text, LaTeX and PDF (1..17);
            JSON, Python and C always carry 17.

    Raises:
        InputError: For an unknown format or precision, or code output of kept parameters.
        MissingToolError: For ``"pdf"`` without a TeX engine.
    """
    check_precision(precision)
    renderers: dict[str, Callable[[EquationsData], str | bytes]] = {
        "text": lambda e: render_text.to_text(e, precision=precision),
        "latex": lambda e: render_latex.to_latex(e, precision=precision),
        "pdf": lambda e: render_latex.to_pdf(e, precision=precision),
        "json": render_json.to_json,
        "python": render_python.to_python,
        "c": render_c.to_c,
    }
    if format not in renderers:
        raise InputError("format", f"one of {', '.join(FORMATS)}", repr(format))
    return renderers[format](equations)
