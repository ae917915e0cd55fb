"""sympy expressions and straight-line programs as C99: the one C printer.

Every C the package writes goes through :class:`CPrinter`: the C source of the equations
(:mod:`robodyn.equations.render_c`), of a frame's kinematics (the same module), and the
compiled engine's kernels (:mod:`robodyn.compiled.codegen`).

- Numbers are doubles that read back exactly: ``repr(float(x))`` (``0.41``, ``2.0``); an
  exact rational is ``(p/q)``, a correctly rounded division. Renderers that want one
  literal a constant pass expressions through :func:`robodyn.equations.model.numeric`
  first.
- ``x**2`` is ``(x*x)``, ``x**-1`` is ``(1.0/x)``, other whole powers ``pow(x, n)``;
  ``sin``/``cos`` as they are; anything else (``sqrt``, ``π``, ...) goes to
  ``sympy.ccode`` (a printer of its own: the slowest step of a compile when used for
  everything).
- Symbols are printed by the names the caller gives (``q[3]``, ``t12``): no name from a
  URDF reaches the code unless a caller puts it there. A symbol without a name is printed
  as sympy names it, so callers name every symbol.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping

import sympy as sp

from robodyn.equations.program import Assignment


def c_number(value: float) -> str:
    """A double literal that reads back to exactly ``value``."""
    return repr(float(value))


def c_combination(terms: Iterable[tuple[float, str]]) -> str:
    """``c0*x0 + c1*x1 + ...`` with unit coefficients left out; ``0.0`` for no terms."""
    parts = [name if coefficient == 1.0 else f"{c_number(coefficient)}*{name}" for coefficient, name in terms]
    return " + ".join(parts) if parts else "0.0"


class CPrinter:
    """Prints expressions as C99 doubles, symbols by the given names.

    Args:
        names: Symbol -> C text (an identifier or an array entry such as ``q[2]``).
    """

    def __init__(self, names: Mapping[sp.Symbol, str]) -> None:
        self.names = dict(names)
        self._printed: dict[sp.Symbol, str] = {}

    def expression(self, expr: sp.Expr) -> str:
        """C for one expression."""
        expr = sp.sympify(expr)
        if expr.is_Symbol:
            return self.names.get(expr, str(expr))
        if expr.is_Integer or expr.is_Float:
            return c_number(float(expr))
        if expr.is_Rational:
            return f"({c_number(expr.p)}/{c_number(expr.q)})"
        if expr.is_Add:
            return "(" + " + ".join(self.expression(arg) for arg in expr.args) + ")"
        if expr.is_Mul:
            return "(" + "*".join(self.expression(arg) for arg in expr.args) + ")"
        if expr.is_Pow and expr.exp == 2:
            base = self.expression(expr.base)
            return f"({base}*{base})"
        if expr.is_Pow and expr.exp == -1:
            return f"(1.0/{self.expression(expr.base)})"
        if expr.is_Pow and expr.exp.is_Integer:
            return f"pow({self.expression(expr.base)}, {int(expr.exp)})"
        if isinstance(expr, sp.cos | sp.sin) and len(expr.args) == 1:
            return f"{type(expr).__name__}({self.expression(expr.args[0])})"
        named = {symbol: sp.Symbol(self.names[symbol]) for symbol in expr.free_symbols if symbol in self.names}
        return sp.ccode(expr.xreplace(named), standard="C99")

    def assignment(self, symbol: sp.Symbol, expr: sp.Expr) -> str:
        """``const double <name> = <expr>;`` (printed once per symbol, then reused)."""
        if symbol not in self._printed:
            self._printed[symbol] = self.expression(expr)
        return f"const double {self.names[symbol]} = {self._printed[symbol]};"

    def statements(self, assignments: Iterable[Assignment], *, indent: str = "    ") -> list[str]:
        """A straight-line program's assignments as C declarations, one a line."""
        return [indent + self.assignment(symbol, expr) for symbol, expr in assignments]
