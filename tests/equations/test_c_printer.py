"""The one C printer: the same doubles as before, and as sympy's own printer.

Printed C is evaluated here by Python (the same IEEE doubles, left to right, no fused
multiply-add; ``math`` is the C library's), so its numbers can be compared exactly without
a compiler; the compiled files are tested in test_equations*.py and the compiled tests.
"""

from __future__ import annotations

import math

import pytest
import sympy as sp

from robodyn.equations import derive_equations
from robodyn.equations.c_printer import CPrinter, c_combination, c_number
from robodyn.equations.kinematics import derive_kinematics
from robodyn.equations.model import numeric

_C_NAMES = {"pow": math.pow, "sin": math.sin, "cos": math.cos, "sqrt": math.sqrt, "fabs": math.fabs, "M_PI": math.pi}


def _parenthesised(expr: sp.Expr, names: dict[sp.Symbol, str]) -> str:
    """The compiled engine's printer before it became :class:`CPrinter`: every sum and
    product in parentheses (the reference for the evaluation order)."""
    if expr.is_Symbol:
        return names[expr]
    if expr.is_Integer or expr.is_Float:
        return repr(float(expr))
    if expr.is_Rational:
        return f"({float(expr.p)!r}/{float(expr.q)!r})"
    if expr.is_Add:
        return "(" + " + ".join(_parenthesised(a, names) for a in expr.args) + ")"
    if expr.is_Mul:
        return "(" + "*".join(_parenthesised(a, names) for a in expr.args) + ")"
    if expr.is_Pow and expr.exp == 2:
        base = _parenthesised(expr.base, names)
        return f"({base}*{base})"
    if expr.is_Pow and expr.exp == -1:
        return f"(1.0/{_parenthesised(expr.base, names)})"
    if expr.is_Pow and expr.exp.is_Integer:
        return f"pow({_parenthesised(expr.base, names)}, {int(expr.exp)})"
    assert isinstance(expr, sp.cos | sp.sin), expr
    return f"{type(expr).__name__}({_parenthesised(expr.args[0], names)})"


def _run(text: str, values: dict[str, float]) -> float:
    return float(eval(text, {"__builtins__": {}}, {**_C_NAMES, **values}))  # printed by our printer from sympy


def _expressions_and_names(name: str) -> tuple[list[sp.Expr], dict[sp.Symbol, str]]:
    equations = derive_equations(name, form="compact")
    names = {s: f"q{i}" for i, s in enumerate(equations.q)} | {s: f"v{i}" for i, s in enumerate(equations.qd)}
    values: dict[sp.Symbol, sp.Expr] = {}
    expressions = []
    for symbol, expr in equations.assignments:  # each in the inputs only (small robots: short)
        values[symbol] = expr.xreplace(values)
        expressions.append(values[symbol])
    return expressions + [e.xreplace(values) for e in (*equations.M, *equations.Cv, *equations.G)], names


@pytest.mark.parametrize("name", ["rp_arm", "double_pendulum"])
def test_the_printer_evaluates_exactly_as_the_fully_parenthesised_one(name, rng):
    """Fewer parentheses and subtraction, but the very same doubles, bit for bit."""
    expressions, names = _expressions_and_names(name)
    printer = CPrinter(names)
    for _ in range(5):
        values = {text: float(rng.normal()) for text in names.values()}
        for expr in expressions:
            assert _run(printer.expression(expr), values) == _run(_parenthesised(expr, names), values), expr


def test_the_printer_agrees_with_sympys_ccode(rng):
    kinematics = derive_kinematics("ur5", "tool0")
    names = {s: f"q{i}" for i, s in enumerate(kinematics.q)}
    printer = CPrinter(names)
    renamed = {s: sp.Symbol(text) for s, text in names.items()}
    values = {text: float(rng.uniform(-3, 3)) for text in names.values()}
    for expr in (*kinematics.position, *kinematics.jacobian):
        expr = numeric(expr)
        ours, theirs = _run(printer.expression(expr), values), _run(sp.ccode(expr.xreplace(renamed), standard="C99"), values)
        assert ours == pytest.approx(theirs, rel=1e-13, abs=1e-15)


def test_numbers_read_back_exactly_and_anything_unusual_goes_to_sympy():
    x = sp.Symbol("x", real=True)
    printer = CPrinter({x: "q[0]"})
    assert float(c_number(0.1 + 0.2)) == 0.1 + 0.2
    assert printer.expression(sp.Rational(3, 20) * x) == "(3.0/20.0)*q[0]"
    assert (
        printer.expression(sp.sqrt(x) + sp.pi) == "M_PI + sqrt(q[0])"
        or printer.expression(sp.sqrt(x) + sp.pi) == "sqrt(q[0]) + M_PI"
    )
    assert printer.expression(-(x**2) - 1) in ("-1.0 - (q[0]*q[0])", "-(q[0]*q[0]) - 1.0")
    assert c_combination([(1.0, "a"), (-2.0, "b")]) == "a + -2.0*b" and c_combination([]) == "0.0"


def test_an_unnamed_symbol_is_printed_by_its_own_name_so_callers_name_every_one():
    """The renderers map every symbol to ``q[i]``, ``v[i]`` or ``tN``; a joint's own name would
    otherwise reach the code (the renderers' tests check none does)."""
    x = sp.Symbol("q_shoulder", real=True)
    assert CPrinter({}).expression(2 * x) == "2.0*q_shoulder"
    assert CPrinter({x: "q[0]"}).expression(2 * x) == "2.0*q[0]"


def test_negative_control_a_printer_summing_in_another_order_is_caught(rng):
    """Sums printed in reverse order change the last bits somewhere: the exact comparison
    above would catch a printer that reorders."""
    expressions, names = _expressions_and_names("double_pendulum")
    values = {text: float(rng.normal()) for text in names.values()}

    def reversed_sums(expr: sp.Expr) -> str:
        if expr.is_Add:
            return "(" + " + ".join(reversed([reversed_sums(a) for a in expr.args])) + ")"
        if expr.is_Mul:
            return "(" + "*".join(reversed_sums(a) for a in expr.args) + ")"
        if expr.is_Function:
            return f"{type(expr).__name__}({reversed_sums(expr.args[0])})"
        return _parenthesised(expr, names)

    assert any(_run(reversed_sums(e), values) != _run(_parenthesised(e, names), values) for e in expressions)
