"""Common factors taken out of the exported programs' sums: the same values, fewer operations."""

from __future__ import annotations

import dataclasses

import numpy as np
import sympy as sp

from robodyn.equations.c_printer import CPrinter
from robodyn.equations.program import Program
from robodyn.export.factoring import factored, factored_expression

x, y, z, w = sp.symbols("x y z w")


def _value(expr: sp.Basic, values: dict) -> float:
    return float(expr.xreplace(values).doit().evalf(30))


def test_shared_factors_come_out_once_and_the_value_is_kept(rng):
    expr = sp.Rational(3, 7) * x * y + sp.Rational(3, 7) * z - sp.Rational(3, 7) * w + x * z - sp.Rational(5, 2) * y
    out = factored_expression(expr)
    assert sp.count_ops(out) < sp.count_ops(expr)
    for _ in range(5):
        values = dict(zip((x, y, z, w), map(sp.Float, rng.normal(size=4)), strict=True))
        assert np.isclose(_value(out, values), _value(expr, values), rtol=1e-14)
    assert sp.expand(out) == sp.expand(expr)


def test_a_negative_control_another_coefficient_is_told_apart():
    expr = sp.Rational(3, 7) * x + sp.Rational(3, 7) * z
    assert sp.expand(factored_expression(expr)) != sp.expand(sp.Rational(3, 7) * x + sp.Rational(3, 8) * z)


def test_a_program_keeps_its_assignments_and_outputs():
    t = sp.Symbol("t")
    program = Program({"q": (x, y)}, ((t, 2 * x * sp.sin(y) + 2 * y),), {"tau": (3 * t + 3 * x,)})
    out = factored(program)
    assert [s for s, _ in out.assignments] == [t]
    assert sp.expand(out.assignments[0][1]) == sp.expand(program.assignments[0][1])
    assert sp.expand(out.outputs["tau"][0]) == 3 * t + 3 * x


def _run(program: Program, values: dict) -> list[float]:
    known = dict(values)
    for symbol, expr in program.assignments:
        known[symbol] = expr.xreplace(known)
    return [_value(sp.sympify(e).xreplace(known), {}) for e in program.outputs["tau"]]


def test_a_negation_is_folded_into_its_uses_and_no_program_value_changes(rng):
    t, u, s = sp.symbols("t u s")
    program = Program(
        {"q": (x, y)},
        ((u, x * sp.sin(y)), (t, -u), (s, -sp.Rational(3, 7) * x - sp.Rational(2, 5) * y)),
        {"tau": (x - t, u - t, t * t + s, s * y)},
    )
    out = factored(program)
    assert [symbol for symbol, _ in out.assignments] == [u, s]  # t = -u is gone
    assert sp.expand(dict(out.assignments)[s]) == sp.Rational(3, 7) * x + sp.Rational(2, 5) * y  # s holds the positive
    first, *rest = out.outputs["tau"]
    flipped = dataclasses.replace(out, outputs={"tau": (2 * x - first, *rest)})  # negative control: x + t
    for _ in range(5):
        values = dict(zip((x, y), map(sp.Float, rng.normal(size=2)), strict=True))
        assert np.allclose(_run(out, values), _run(program, values), rtol=1e-14, atol=0)
        assert not np.allclose(_run(flipped, values), _run(program, values), rtol=1e-14, atol=0)


def test_a_sum_is_printed_with_a_positive_term_first_so_its_negative_constants_are_subtracted():
    expr = -sp.Rational(3, 7) * x + y * z
    text = CPrinter({x: "x", y: "y", z: "z"}).expression(factored_expression(expr))
    assert text == "y*z - (3.0/7.0)*x"
    assert "(-" not in CPrinter({x: "x", y: "y", z: "z"}).expression(factored_expression(-sp.Rational(3, 7) - x * y + z))
