"""The base parameters as text, LaTeX or JSON (``robodyn identify --base-parameters``).

Parameter names come from the URDF, so they are escaped for each output: unprintable
characters as ``\\uXXXX`` escapes in text, LaTeX's special characters in LaTeX (names are set
in ``\\texttt``), and JSON's own string escaping.
"""

from __future__ import annotations

import json
from typing import Any

from robodyn.common.text import latex_text, printable
from robodyn.exceptions import InputError
from robodyn.ident.base import SYMBOLIC_MAX_JOINTS, BaseParameters

FORMATS = ("text", "latex", "json")


def _terms(base: BaseParameters, row: Any) -> list[tuple[Any, str]]:
    """(exact coefficient, standard name) of a row of the map."""
    from robodyn.ident.base import _exact

    return [(_exact(c), name) for c, name in zip(row, base.standard_names, strict=True) if c != 0.0]


def render_base_parameters(base: BaseParameters, format: str = "text") -> str:
    """The base parameters: count, how they were found, each name, URDF value and (up to
    ``SYMBOLIC_MAX_JOINTS`` joints) its expression in the standard parameters.

    Args:
        base: The base parameters.
        format: ``"text"``, ``"latex"`` or ``"json"``.

    Raises:
        InputError: For an unknown format.
    """
    if format not in FORMATS:
        raise InputError("format", f"one of {', '.join(FORMATS)}", repr(format))
    symbolic = base.robot.nv <= SYMBOLIC_MAX_JOINTS
    rows = [_terms(base, row) if symbolic else None for row in base.mapping]
    if format == "json":
        return (
            json.dumps(
                {
                    "robot": base.robot.name,
                    "count": base.count,
                    "standard_count": len(base.standard_names),
                    "samples": base.samples,
                    "tolerance": base.tolerance,
                    "base_parameters": [
                        {
                            "name": name,
                            "value": float(value),
                            "combination": None if terms is None else [{"coefficient": str(c), "parameter": n} for c, n in terms],
                        }
                        for name, value, terms in zip(base.names, base.values, rows, strict=True)
                    ],
                },
                indent=2,
            )
            + "\n"
        )
    header = (
        f"{base.count} base parameters of {len(base.standard_names)} standard ({base.samples} random states, "
        f"rank tolerance {base.tolerance:g}, checked on two draws)"
    )
    if format == "latex":
        lines = [f"% {latex_text(base.robot.name)}: {latex_text(header)}", r"\begin{align*}"]
        for name, terms in zip(base.names, rows, strict=True):
            rhs = _signed([(c, rf"\texttt{{{latex_text(n)}}}") for c, n in terms], latex=True) if terms else "0"
            lines.append(rf"\beta_{{\texttt{{{latex_text(name)}}}}} &= {rhs} \\")
        lines.append(r"\end{align*}")
        return "\n".join(lines) + "\n"
    width = max(len(printable(name)) for name in base.names)
    lines = [f"{printable(base.robot.name)}: {header}", ""]
    for name, value, terms in zip(base.names, base.values, rows, strict=True):
        line = f"{printable(name):{width}s} {value:>12.6g}"
        if terms is not None:
            line += "   = " + _signed([(c, printable(n)) for c, n in terms], latex=False)
        lines.append(line)
    return "\n".join(lines) + "\n"


def _signed(terms: list[tuple[Any, str]], *, latex: bool) -> str:
    """``c1 a + c2 b − c3 c`` with exact coefficients (1 left out)."""
    import sympy as sp

    text = ""
    for index, (coefficient, name) in enumerate(terms):
        negative = coefficient < 0
        magnitude = -coefficient if negative else coefficient
        if magnitude == 1:
            factor = ""
        elif isinstance(magnitude, sp.Rational):
            factor = sp.latex(magnitude) + r"\," if latex else f"{magnitude}*"
        else:  # a float from the least-squares fit: 12 significant digits are exact to its rounding
            factor = f"{float(magnitude):.12g}" + (r"\," if latex else "*")
        sign = ("-" if negative else "") if index == 0 else (" - " if negative else " + ")
        text += f"{sign}{factor}{name}"
    return text


__all__ = ["FORMATS", "render_base_parameters"]
