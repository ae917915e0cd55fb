"""One entry point for every output format of the equations, and the number printing
they share: exact numbers become floats only here, with ``precision`` significant digits
for people (text, LaTeX, PDF) and 17 for machines (JSON, Python, C)."""

from __future__ import annotations

import sympy as sp
from sympy.printing.str import StrPrinter

from robodyn.equations.model import Equations, numeric
from robodyn.exceptions import InputError

FORMATS = ("text", "latex", "pdf", "json", "python", "c")
#: Significant digits of the numbers in text and LaTeX by default.
DEFAULT_PRECISION = 6


def format_float(value: float, precision: int) -> str:
    """``value`` with ``precision`` significant digits, integers without ``.0``."""
    text = f"{value:.{precision}g}"
    return text


class TextPrinter(StrPrinter):
    """sympy's ``str`` with floats of ``precision`` significant digits."""

    def __init__(self, precision: int) -> None:
        super().__init__()
        self.precision = precision

    def _print_Float(self, expr: sp.Float) -> str:
        return format_float(float(expr), self.precision)


def check_precision(precision: int) -> int:
    """``precision`` if it is 1..17 significant digits, else :class:`InputError`."""
    if isinstance(precision, bool) or not isinstance(precision, int) or not 1 <= precision <= 17:
        raise InputError("precision", "a whole number of significant digits from 1 to 17", repr(precision))
    return precision


def to_text_expr(expr: sp.Expr, precision: int) -> str:
    """One expression as text (floats of ``precision`` digits)."""
    return TextPrinter(precision).doprint(numeric(expr))


def render(equations: Equations, format: str = "text", *, precision: int = DEFAULT_PRECISION) -> str | bytes:
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
    from robodyn.equations import render_c, render_json, render_latex, render_python, render_text

    check_precision(precision)
    renderers = {
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


def code_ready(equations: Equations) -> None:
    """Refuse code output for kept parameters (code needs numbers)."""
    if equations.parameters:
        raise InputError("keep_params", "not used with code output (code needs numbers)", "kept parameters")


def numbered(equations: Equations) -> tuple[dict[sp.Symbol, sp.Symbol], list[tuple[sp.Symbol, sp.Expr]]]:
    """Joint symbols as array accesses ``q[i]``, ``v[i]``; the assignments' names as ``tN``;
    numbers as 17-digit floats. No name from the URDF survives."""
    substitutions = {}
    for index, (q, qd) in enumerate(zip(equations.q, equations.qd, strict=True)):
        substitutions[q] = sp.Symbol(f"q[{index}]")
        substitutions[qd] = sp.Symbol(f"v[{index}]")
    renamed = {symbol: sp.Symbol(f"t{index}") for index, (symbol, _) in enumerate(equations.assignments)}
    substitutions.update(renamed)
    assignments = [(renamed[symbol], numeric(expr.xreplace(substitutions))) for symbol, expr in equations.assignments]
    return substitutions, assignments
