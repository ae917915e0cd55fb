"""sympy expressions and straight-line programs as C99: the one C printer.

Every C the package writes goes through :class:`CPrinter`: the C source of the equations
(:mod:`robodyn.equations.render_c`), of a frame's kinematics (the same module), and the
compiled engine's kernels (:mod:`robodyn.compiled.codegen`).

- Numbers are doubles that read back exactly: ``repr(float(x))`` (``0.41``, ``2.0``); an
  exact rational is ``(p/q)``, a correctly rounded division. Renderers that want one
  literal a constant pass expressions through :func:`robodyn.equations.model.numeric`
  first.
- ``x**2`` is ``(x*x)``, ``x**-1`` is ``(1.0/x)``, other whole powers ``pow(x, n)``;
  ``sin``/``cos`` as they are (libm's), or with a prefix (``CPrinter(trig="rd_")``: the
  compiled kernels' own, :mod:`robodyn.compiled.codegen`); anything else (``sqrt``, ``π``, ...) goes to
  ``sympy.ccode`` (a printer of its own: the slowest step of a compile when used for
  everything).
- :func:`vector_lines` turns printed statements into the same statements on SIMD vectors
  of doubles (one state a lane, :mod:`robodyn.compiled.simd`).
- Symbols are printed by the names the caller gives (``q[3]``, ``t12``): no name from a
  URDF reaches the code unless a caller puts it there. A symbol without a name is printed
  as sympy names it, so callers name every symbol.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping

import sympy as sp

from robodyn.equations.program import Assignment


def c_number(value: float) -> str:
    """A double literal that reads back to exactly ``value``.

    Args:
        value: The number.
    """
    return repr(float(value))


def c_combination(terms: Iterable[tuple[float, str]]) -> str:
    """``c0*x0 + c1*x1 + ...`` with unit coefficients left out; ``0.0`` for no terms.

    Args:
        terms: ``(coefficient, C name)`` pairs.
    """
    parts = [name if coefficient == 1.0 else f"{c_number(coefficient)}*{name}" for coefficient, name in terms]
    return " + ".join(parts) if parts else "0.0"


#: Precedence of printed C (higher binds tighter): a sum, a product, a negation, an atom
#: (a symbol, a number, a call or anything parenthesised).
_ADD, _MUL, _UNARY, _ATOM = 1, 2, 3, 4


class CPrinter:
    """Prints expressions as C99 doubles, symbols by the given names.

    Args:
        names: Symbol -> C text (an identifier or an array entry such as ``q[2]``).
        trig: A prefix for ``sin`` and ``cos`` calls: ``"rd_"`` prints ``rd_sin(x)``, the
            compiled kernels' own (:mod:`robodyn.compiled.codegen`); empty for libm's.
    """

    def __init__(self, names: Mapping[sp.Symbol, str], *, trig: str = "") -> None:
        self.names = dict(names)
        self.trig = trig
        self._printed: dict[sp.Symbol, str] = {}

    def expression(self, expr: sp.Expr) -> str:
        """C for one expression.

        Args:
            expr: The expression (anything :func:`sympy.sympify` takes).
        """
        return self._print(sp.sympify(expr))[0]

    def _print(self, expr: sp.Expr) -> tuple[str, int]:
        """C text and its precedence (:data:`_ADD` < :data:`_MUL` < :data:`_UNARY` < :data:`_ATOM`)."""
        if expr.is_Symbol:
            return self.names.get(expr, str(expr)), _ATOM
        if expr.is_Integer or expr.is_Float:
            text = c_number(float(expr))
            return text, _UNARY if text.startswith("-") else _ATOM
        if expr.is_Rational:
            return f"({c_number(expr.p)}/{c_number(expr.q)})", _ATOM
        if expr.is_Add:
            return self._sum(expr.args), _ADD
        if expr.is_Mul:
            return self._product(expr.args)
        if expr.is_Pow and expr.exp == 2:
            base = self._operand(expr.base, _ATOM)
            return f"({base}*{base})", _ATOM
        if expr.is_Pow and expr.exp == -1:
            return f"(1.0/{self._operand(expr.base, _MUL + 1)})", _ATOM
        if expr.is_Pow and expr.exp.is_Integer:
            return f"pow({self.expression(expr.base)}, {int(expr.exp)})", _ATOM
        if isinstance(expr, sp.cos | sp.sin) and len(expr.args) == 1:
            return f"{self.trig}{type(expr).__name__}({self.expression(expr.args[0])})", _ATOM
        named = {symbol: sp.Symbol(self.names[symbol]) for symbol in expr.free_symbols if symbol in self.names}
        text = sp.ccode(expr.xreplace(named), standard="C99")
        called = expr.is_Pow or expr.is_NumberSymbol or isinstance(expr, sp.Function)  # sqrt(x), M_PI, fabs(x)
        return (text, _ATOM) if called else (f"({text})", _ATOM)

    def _operand(self, expr: sp.Expr, needed: int) -> str:
        """``expr`` in parentheses unless it binds at least as tightly as ``needed``."""
        text, precedence = self._print(expr)
        return text if precedence >= needed else f"({text})"

    def _sum(self, terms: tuple[sp.Expr, ...]) -> str:
        """``a + b - c``: a term with a negative coefficient is subtracted (exactly the same
        double as adding its negative), evaluated left to right as sympy lists the terms."""
        text = self._operand(terms[0], _ADD)
        for term in terms[1:]:
            if term.is_Number and term < 0:
                text += " - " + self._operand(-term, _MUL)
            elif term.is_Mul and term.args[0].is_Number and term.args[0] < 0:
                coefficient = -term.args[0]
                factors = term.args[1:] if coefficient == 1 else (coefficient, *term.args[1:])
                product, precedence = self._product(factors) if len(factors) > 1 else self._print(factors[0])
                text += " - " + (product if precedence >= _MUL else f"({product})")
            else:
                text += " + " + self._operand(term, _ADD)
        return text

    def _product(self, factors: tuple[sp.Expr, ...]) -> tuple[str, int]:
        """``a*b*c`` (left to right), ``-a*b`` for a coefficient of -1."""
        if factors[0] == -1 and len(factors) > 1:
            rest = self._product(factors[1:])[0] if len(factors) > 2 else self._operand(factors[1], _UNARY)
            return "-" + rest, _UNARY
        return "*".join(self._operand(factor, _MUL) for factor in factors), _MUL

    def assignment(self, symbol: sp.Symbol, expr: sp.Expr) -> str:
        """``const double <name> = <expr>;`` (printed once per symbol, then reused).

        Args:
            symbol: The symbol assigned (named by :attr:`names`).
            expr: Its expression.
        """
        if symbol not in self._printed:
            self._printed[symbol] = self.expression(expr)
        return f"const double {self.names[symbol]} = {self._printed[symbol]};"

    def statements(self, assignments: Iterable[Assignment], *, indent: str = "    ") -> list[str]:
        """A straight-line program's assignments as C declarations, one a line.

        Args:
            assignments: ``(symbol, expression)`` pairs, in the program's order.
            indent: Text before each line.
        """
        return [indent + self.assignment(symbol, expr) for symbol, expr in assignments]


#: Calls the vector form takes lane by lane (the same libm call on each lane's double).
LANE_CALLS = ("pow", "sqrt", "fabs")
#: The compiled kernels' own sin and cos (``CPrinter(trig="rd_")``), which the caller defines
#: on vectors as the same operations (libm's ``sin``/``cos`` have no vector form here).
OWN_CALLS = {"rd_sin": "sin", "rd_cos": "cos"}
_CALL = re.compile(r"\b([A-Za-z_]\w*)\(")
_CONSTANT = re.compile(r"^(.*= )([^=]+);$")
#: What a constant's C may consist of besides operators: numbers, ``M_*`` constants, lane calls.
_NOT_NAMES = re.compile(r"\bM_[A-Z0-9_]+\b|\b(?:" + "|".join((*LANE_CALLS, *OWN_CALLS)) + r")\(|\b\d+\.?\d*(?:[eE][-+]?\d+)?")


def vector_lines(lines: Iterable[str], *, vector: str, prefix: str, kernels: Iterable[str] = ()) -> list[str] | None:
    """Statements printed by :class:`CPrinter` (and the kernels' loops around them) on
    vectors of doubles, one state a lane: the same operations in the same order, so every
    lane rounds as the scalar statement does.

    ``double`` becomes ``vector`` (a GCC/Clang vector type); a call of a :data:`LANE_CALLS`
    function ``f`` becomes ``{prefix}f`` (the caller defines it, lane by lane), ``rd_sin`` and
    ``rd_cos`` (:data:`OWN_CALLS`) become ``{prefix}sin`` and ``{prefix}cos``; a call of one
    of ``kernels`` (``rd_mass``) becomes the vector kernel (``{prefix}mass``); a constant
    right-hand side becomes ``{prefix}splat(c)``.

    Args:
        lines: The scalar C lines.
        vector: The name of the vector type (e.g. ``"rds4"``).
        prefix: Prefix of the lane-wise functions the caller defines (e.g. ``"rds4_"``).
        kernels: Names of the scalar kernels called (``"rd_mass"``), renamed to their vector forms.

    Returns:
        The lines, or None if one has a call or an operator (``?:``) the vector form does not take.
    """
    renamed = {kernel: prefix + kernel.split("_", 1)[1] for kernel in kernels}
    renamed.update({name: prefix + name for name in LANE_CALLS}, **{word: word for word in ("for", "if", "while")})
    renamed.update({name: prefix + function for name, function in OWN_CALLS.items()})
    out = []
    for line in lines:
        if "?" in line:
            return None
        line = re.sub(r"\bdouble\b", vector, line)
        constant = _CONSTANT.match(line)
        if constant and not re.search(r"[A-Za-z_]", _NOT_NAMES.sub("", constant.group(2))):
            out.append(f"{constant.group(1)}{prefix}splat({constant.group(2)});")  # a constant (2.5, M_SQRT2)
            continue
        if any(name not in renamed for name in _CALL.findall(line)):
            return None
        out.append(_CALL.sub(lambda match: renamed[match.group(1)] + "(", line))
    return _paired(out, prefix)


def _paired(lines: list[str], prefix: str) -> list[str]:
    """``sin(x)`` and ``cos(x)`` of one ``x`` as one ``{prefix}sincos`` statement where the
    first of the two stood (the scalar kernel's compiler pairs them into ``sincos`` too)."""
    pattern = re.compile(rf"^(\s*)const (\w+) (\w+) = {re.escape(prefix)}(sin|cos)\((\w+)\);$")
    found: dict[tuple[str, str], tuple[int, str]] = {}
    for index, line in enumerate(lines):
        match = pattern.match(line)
        if match:
            found.setdefault((match.group(4), match.group(5)), (index, match.group(3)))
    replaced: dict[int, str | None] = {}
    for (function, argument), (index, name) in found.items():
        other = found.get(("cos", argument)) if function == "sin" else None
        if other is None:
            continue
        first, second = sorted([index, other[0]])
        match = pattern.match(lines[first])
        assert match is not None
        indent, vector = match.group(1), match.group(2)
        replaced[first] = f"{indent}{vector} {name}, {other[1]}; {prefix}sincos({argument}, &{name}, &{other[1]});"
        replaced[second] = None
    kept = (replaced.get(index, line) for index, line in enumerate(lines))
    return [line for line in kept if line is not None]
