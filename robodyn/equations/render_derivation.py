"""The Lagrangian derivation of :mod:`robodyn.equations.derivation` as text, LaTeX, PDF or JSON.

:func:`derivation` gives a :class:`Derivation` (the steps, ``to_dict()`` and, in notebooks,
``_repr_latex_``); :func:`derivation_document` is the one call behind
``robodyn equations MODEL --derivation``. Every name from the URDF passes
:mod:`robodyn.common.text`; numbers are exact until printed, then floats of
``precision`` significant digits (17 in JSON, as the equations' JSON). The text and JSON
forms are in :mod:`robodyn.equations.derivation_text`, the LaTeX and PDF forms in
:mod:`robodyn.equations.derivation_latex` (their names are re-exported here).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import fields
from typing import Any, Literal

from robodyn.common.text import json_text
from robodyn.equations.derivation import DerivationSteps, derive_steps
from robodyn.equations.derivation_latex import latex_math, to_latex, to_pdf
from robodyn.equations.derivation_text import STEP_OF, STEP_TITLES, TRACE, errata_at, printed_tau, to_dict, to_text
from robodyn.equations.printing import DEFAULT_PRECISION, check_precision
from robodyn.exceptions import InputError

DerivationFormat = Literal["text", "latex", "pdf", "json"]
#: The formats of :func:`render_derivation`.
DERIVATION_FORMATS = ("text", "latex", "pdf", "json")


class Derivation(DerivationSteps):
    """The steps of :class:`DerivationSteps`, as a dictionary and in notebooks as LaTeX."""

    def to_dict(self) -> dict[str, Any]:
        """Every step (see :func:`to_dict`)."""
        return to_dict(self)

    def _repr_latex_(self) -> str:
        """The derivation for notebooks (Jupyter renders this with MathJax)."""
        return latex_math(self)


def derivation(
    source: str | os.PathLike,
    *,
    keep_params: bool = False,
    gravity: Sequence[float] | None = None,
    lock: dict[str, float] | None = None,
) -> Derivation:
    """The Lagrangian derivation of a small robot (arguments as :func:`derive_steps`)."""
    steps = derive_steps(source, keep_params=keep_params, gravity=gravity, lock=lock)
    return Derivation(**{f.name: getattr(steps, f.name) for f in fields(steps)})


def derivation_document(
    source: str | os.PathLike,
    *,
    format: DerivationFormat = "text",
    keep_params: bool = False,
    gravity: Sequence[float] | None = None,
    lock: dict[str, float] | None = None,
    precision: int = DEFAULT_PRECISION,
) -> str | bytes:
    """The derivation of a robot in one of :data:`DERIVATION_FORMATS` (``"pdf"`` gives bytes).

    Args:
        source, keep_params, gravity, lock: As for
            :func:`robodyn.equations.derivation.derive_steps`.
        format: One of :data:`DERIVATION_FORMATS`.
        precision: Significant digits of the printed floats.

    Raises:
        InputError: For an unknown format or precision, or a robot too large.
        MissingToolError: For ``"pdf"`` without pdflatex.
    """
    _check(format, precision)
    return render_derivation(derivation(source, keep_params=keep_params, gravity=gravity, lock=lock), format, precision=precision)


def _check(format: str, precision: int) -> None:
    check_precision(precision)
    if format not in DERIVATION_FORMATS:
        raise InputError("format", f"one of {', '.join(DERIVATION_FORMATS)} for a derivation", repr(format))


def render_derivation(
    steps: DerivationSteps, format: DerivationFormat = "text", *, precision: int = DEFAULT_PRECISION
) -> str | bytes:
    """``steps`` as text, a LaTeX document, a PDF (bytes) or JSON.

    Args:
        steps: The derivation (:func:`derivation`).
        format: One of :data:`DERIVATION_FORMATS`.
        precision: Significant digits of the printed floats.
    """
    _check(format, precision)
    if format == "text":
        return to_text(steps, precision=precision)
    if format == "latex":
        return to_latex(steps, precision=precision)
    if format == "pdf":
        return to_pdf(steps, precision=precision)
    return json_text(to_dict(steps), indent=2) + "\n"


__all__ = [
    "DERIVATION_FORMATS",
    "STEP_OF",
    "STEP_TITLES",
    "TRACE",
    "Derivation",
    "DerivationFormat",
    "derivation",
    "derivation_document",
    "errata_at",
    "latex_math",
    "printed_tau",
    "render_derivation",
    "to_dict",
    "to_latex",
    "to_pdf",
    "to_text",
]
