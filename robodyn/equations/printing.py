"""Number printing the renderers share: exact numbers become floats only here, with
``precision`` significant digits for people (text, LaTeX, PDF) and 17 for machines
(JSON, Python, C); and the code renderers' common preparation."""

from __future__ import annotations

import sympy as sp
from sympy.printing.str import StrPrinter

from robodyn.equations.model import EquationsData, numeric
from robodyn.exceptions import InputError

#: Significant digits of the numbers in text and LaTeX by default.
DEFAULT_PRECISION = 6


def format_float(value: float, precision: int) -> str:
    """``value`` with ``precision`` significant digits, integers without ``.0``.

    Args:
        value: The number.
        precision: Significant digits.
    """
    return f"{value:.{precision}g}"


class TextPrinter(StrPrinter):
    """sympy's ``str`` with floats of ``precision`` significant digits."""

    def __init__(self, precision: int) -> None:
        super().__init__()
        self.precision = precision

    def _print_Float(self, expr: sp.Float) -> str:
        return format_float(float(expr), self.precision)


def check_precision(precision: int) -> int:
    """``precision`` if it is 1..17 significant digits, else :class:`InputError`.

    Args:
        precision: The number of significant digits asked for.
    """
    if isinstance(precision, bool) or not isinstance(precision, int) or not 1 <= precision <= 17:
        raise InputError("precision", "a whole number of significant digits from 1 to 17", repr(precision))
    return precision


def to_text_expr(expr: sp.Expr, precision: int) -> str:
    """One expression as text (floats of ``precision`` digits).

    Args:
        expr: The expression.
        precision: Significant digits of its floats.
    """
    return TextPrinter(precision).doprint(numeric(expr))


def code_ready(equations: EquationsData) -> None:
    """Refuse code output for kept parameters (code needs numbers).

    Args:
        equations: The derived equations of motion.
    """
    if equations.parameters:
        raise InputError("keep_params", "not used with code output (code needs numbers)", "kept parameters")


def numbered(equations: EquationsData) -> tuple[dict[sp.Symbol, sp.Symbol], list[tuple[sp.Symbol, sp.Expr]]]:
    """Joint symbols as array accesses ``q[i]``, ``v[i]``; the assignments' names as ``tN``;
    numbers as 17-digit floats. No name from the URDF survives.

    Args:
        equations: The derived equations of motion.
    """
    substitutions = {}
    for index, (q, qd) in enumerate(zip(equations.q, equations.qd, strict=True)):
        substitutions[q] = sp.Symbol(f"q[{index}]")
        substitutions[qd] = sp.Symbol(f"v[{index}]")
    renamed = {symbol: sp.Symbol(f"t{index}") for index, (symbol, _) in enumerate(equations.assignments)}
    substitutions.update(renamed)
    assignments = [(renamed[symbol], numeric(expr.xreplace(substitutions))) for symbol, expr in equations.assignments]
    return substitutions, assignments
