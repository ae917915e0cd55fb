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


SYMBOLS = sp.symbols("a b c d e")


def random_sum(rng, depth: int = 0) -> sp.Expr:
    """A sum of 2–6 terms, each a number (±1, a fraction, sometimes negative) times 0–3 factors
    drawn from a few symbols, a sine and (at depth 0) another such sum: shared factors likely."""
    terms = []
    for _ in range(rng.integers(2, 7)):
        number = [sp.Integer(1), sp.Integer(-1), sp.Rational(int(rng.integers(-9, 10)) or 1, int(rng.integers(1, 5)))][
            rng.integers(3)
        ]
        factors = [SYMBOLS[k] for k in rng.integers(0, len(SYMBOLS), size=rng.integers(0, 4))]
        if rng.random() < 0.2:
            factors.append(sp.sin(SYMBOLS[0]))
        if depth == 0 and rng.random() < 0.25:
            factors.append(random_sum(rng, 1))
        terms.append(sp.Mul(number, *factors))
    return sp.Add(*terms)


def test_random_sums_keep_their_value_and_never_gain_an_operation_or_lead_with_a_negative_term(rng):
    point = dict(zip(SYMBOLS, (sp.Float(value, 30) for value in rng.normal(size=len(SYMBOLS))), strict=True))
    for _ in range(25):
        expr = random_sum(rng)
        out = factored_expression(expr)
        assert sp.expand(out - expr) == 0  # the same polynomial in the symbols and sin(a)
        assert abs(float((out - expr).xreplace(point).evalf(30))) <= 1e-20 * max(1.0, abs(float(expr.xreplace(point))))
        assert sp.count_ops(out) <= sp.count_ops(expr)
        for add in out.atoms(sp.Add):
            # a negative term first only when every term is negative
            if any(not (t.is_Number and t < 0) and not (t.is_Mul and t.args[0].is_Number and t.args[0] < 0) for t in add.args):
                first = add.args[0]
                assert not (first.is_Number and first < 0) and not (
                    first.is_Mul and first.args[0].is_Number and first.args[0] < 0
                )
    # the check can fail: one coefficient changed is another polynomial
    assert (
        sp.expand(
            factored_expression(3 * SYMBOLS[0] * SYMBOLS[1] + 3 * SYMBOLS[0]) - (3 * SYMBOLS[0] * SYMBOLS[1] + 2 * SYMBOLS[0])
        )
        != 0
    )


def test_a_symbol_shared_by_two_terms_comes_out_once():
    a, p, r = sp.symbols("a p r")
    for expr in (a * p + a * r, a * p * x + a * r * y, a * sp.sin(x) * p - a * r):
        text = CPrinter({a: "a", p: "p", r: "r", x: "x", y: "y"}).expression(factored_expression(expr))
        assert text.count("a") == 1 and sp.expand(factored_expression(expr) - expr) == 0
    # the check can fail: the unfactored sum has a twice
    assert CPrinter({a: "a", p: "p", r: "r"}).expression(a * p + a * r).count("a") == 2


def test_of_factors_shared_alike_the_last_by_name_comes_out_first_whatever_the_hash_order():
    # the greedy choice ties broken by name, so the exported source is the same in every process
    for index in range(20):
        first, second, p, r = sp.symbols(f"s{index} t{index} p r")
        out = factored_expression(first * second * p + first * second * r)
        assert out.is_Mul and out.args[0] == second and sp.expand(out - first * second * (p + r)) == 0


def test_every_assignment_and_output_of_a_program_is_factored_and_a_negation_reaches_later_assignments(rng):
    t, u, s, w, k = sp.symbols("t u s w k")
    program = Program(
        {"q": (x, y)},
        ((u, x * sp.sin(y)), (t, -u), (s, t * y + 3 * x * y + 3 * y), (w, x * y), (k, sp.cos(x))),
        {"tau": (5 * s * x + 5 * w, k * w)},
    )
    out = factored(program)
    assert [symbol for symbol, _ in out.assignments] == [u, s, w, k]  # only t = -u is gone
    printer = CPrinter({x: "x", y: "y", u: "u", s: "s", w: "w", k: "k"})
    assert printer.expression(dict(out.assignments)[s]).count("y") == 1  # y (3 x + 3 − u): y once
    assert printer.expression(out.outputs["tau"][0]).count("5") == 1  # 5 (s x + w)
    for _ in range(3):
        values = dict(zip((x, y), map(sp.Float, rng.normal(size=2)), strict=True))
        assert np.allclose(_run(out, values), _run(program, values), rtol=1e-14, atol=0)
