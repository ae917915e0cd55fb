"""Straight-line programs: evaluation, dependencies, and the passes that shorten them."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest
import sympy as sp

from robodyn import reference
from robodyn.equations.compact import derive_compact
from robodyn.equations.program import Program, ProgramBuilder, evaluate, in_order, needed, operation_count
from robodyn.equations.sharing import shortened
from tests.conftest import ROOT

x, y = sp.symbols("x y", real=True)


def test_a_builder_names_only_what_is_worth_a_variable():
    builder = ProgramBuilder()
    assert builder.let(sp.Integer(3)) == 3
    assert builder.let(x) == x
    assert builder.let(2 * x) == 2 * x
    t = builder.let((x + y) ** 2, "p")
    assert t.name == "p1" and builder.assignments == [(t, x**2 + 2 * x * y + y**2)]


def test_pythagoras_shortens_where_a_pair_is_registered():
    c, s = sp.symbols("c s", real=True)
    plain, registered = ProgramBuilder(pythagoras=True), ProgramBuilder(pythagoras=True)
    registered.pair(c, s)
    expr = c**2 * x + s**2 * x
    assert registered.rewrite(expr) == x
    assert plain.rewrite(expr) == sp.expand(expr)


def test_needed_keeps_the_dependencies_of_the_outputs_in_order():
    a, b, c = sp.symbols("a b c", real=True)
    assignments = [(a, x + y), (b, a * x), (c, y + 1)]
    assert needed(assignments, [b + 1]) == [(a, x + y), (b, a * x)]
    assert needed(assignments, [c]) == [(c, y + 1)]
    assert in_order({b: a * x, a: x + y}, [b]) == [(a, x + y), (b, a * x)]


def test_evaluate_runs_the_assignments_in_order():
    a, b = sp.symbols("a b", real=True)
    program = Program({"q": (x, y)}, ((a, sp.cos(x) + y), (b, a**2)), {"out": (b, a - 1)})
    result = evaluate(program, {"q": [0.3, 2.0]})
    expected = np.cos(0.3) + 2.0
    np.testing.assert_allclose(result["out"], [expected**2, expected - 1], rtol=1e-15)
    assert operation_count(program) == 2 + 1 + 0 + 1  # cos and +, a**2, b, a - 1


def test_shortening_keeps_the_values_and_saves_operations(rng):
    model = reference.load(str(ROOT / "tests/data/rrp_arm.urdf"))
    long = derive_compact(model, cse=False).program()
    short = shortened(long)
    assert operation_count(short) < operation_count(long)
    q, v = rng.normal(size=(2, model.nv))
    for name, values in evaluate(long, {"q": q, "qd": v}).items():
        np.testing.assert_allclose(evaluate(short, {"q": q, "qd": v})[name], values, rtol=1e-12, atol=1e-12)


@pytest.mark.slow
def test_the_compact_equations_are_the_same_every_run():
    """No set order leaks into the program: two processes with different hash seeds print
    the same equations (so the same C, and the same compiled kernels)."""
    code = (
        "from robodyn.equations import derive_equations, render;"
        f"print(render(derive_equations({str(ROOT / 'tests/data/mimic_arm.urdf')!r}, form='compact'), 'c'))"
    )
    outputs = [
        subprocess.run(
            [sys.executable, "-c", code], env={**os.environ, "PYTHONHASHSEED": seed}, capture_output=True, text=True, check=True
        ).stdout
        for seed in ("1", "2")
    ]
    assert outputs[0] == outputs[1] and "inverse_dynamics" in outputs[0]
