"""The passes that shorten a straight-line program: what they keep and what they cost."""

from __future__ import annotations

import sympy as sp

from robodyn import reference
from robodyn.equations import sharing
from robodyn.equations.compact import derive_compact
from robodyn.equations.program import Program
from tests.conftest import ROOT


def _every_symbol(expr: sp.Expr) -> sp.Expr:
    """The collection as it was before symbols were skipped: every symbol tried, in name order."""
    if not expr.is_Add:
        return expr
    best = expr
    for symbol in sorted(expr.free_symbols, key=str):
        candidate = sp.collect(best, symbol)
        if sp.count_ops(candidate) < sp.count_ops(best):
            best = candidate
    return best


def _shared(source: str) -> Program:
    """A zoo robot's compact program after ``sympy.cse`` and copy removal: what ``reuse_products`` collects."""
    program = derive_compact(reference.load(source), cse=False).program()
    return sharing.without_copies(sharing.share_subexpressions(program))


def test_collecting_only_repeated_factors_gives_what_trying_every_symbol_gave(monkeypatch):
    program = _shared(str(ROOT / "tests/data/rrp_arm.urdf"))
    expressions = [e for _, e in program.assignments] + program.output_expressions()
    sums = [e for e in expressions if e.is_Add]
    assert sums
    collected = [e for e in sums if _every_symbol(e) != e]
    assert collected  # some sums do get collected: the comparison below means something
    assert all(sharing._collected(e) == _every_symbol(e) for e in sums)
    # Negative control: skipping the symbols that are repeated factors changes the result.
    monkeypatch.setattr(sharing, "_repeated_factors", lambda expr: set())
    assert any(sharing._collected(e) != _every_symbol(e) for e in collected)


def test_a_factor_to_different_powers_is_not_repeated():
    a, b, c, x = sp.symbols("a b c x", real=True)
    assert sharing._repeated_factors(a * x + b * x**2 + c) == set()
    assert sharing._repeated_factors(a * x**2 + b * x**2 + c) == {x}
    assert sharing._repeated_factors(a * x + b * x + a) == {a, x}  # a: a factor of a*x and of a
