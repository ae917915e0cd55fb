"""The passes that shorten a straight-line program: what they keep and what they cost."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
import sympy as sp

from robodyn import reference
from robodyn.equations import sharing
from robodyn.equations.compact import derive_compact
from robodyn.equations.program import Program
from tests.conftest import ROOT
from tests.random_robots import urdf_from_seed


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
    """A robot's compact program after ``sympy.cse`` and copy removal: what ``reuse_products`` collects."""
    program = derive_compact(reference.load(source), cse=False).program()
    return sharing.without_copies(sharing.share_subexpressions(program))


def _random_chain(path: Path) -> str:
    """A random 12-joint chain (oblique axes, every third joint prismatic) written to ``path``."""
    urdf = re.sub(r'(<joint name="j(\d+)"[^>]*><parent link=")link\d+"', lambda m: f'{m.group(1)}link{int(m.group(2)) - 1}"',
                  urdf_from_seed(12, 12, ["revolute", "revolute", "prismatic"]))  # fmt: skip
    path.write_text(urdf, encoding="utf-8")
    return str(path)


def test_collecting_only_collectable_symbols_gives_what_trying_every_symbol_gave(monkeypatch):
    _same_as_every_symbol(_shared(str(ROOT / "tests/data/rrp_arm.urdf")), monkeypatch)


@pytest.mark.slow
def test_collecting_only_collectable_symbols_gives_what_trying_every_symbol_gave_on_a_long_chain(monkeypatch, tmp_path):
    _same_as_every_symbol(_shared(_random_chain(tmp_path / "chain.urdf")), monkeypatch)


def _same_as_every_symbol(program: Program, monkeypatch) -> None:
    expressions = [e for _, e in program.assignments] + program.output_expressions()
    sums = [e for e in expressions if e.is_Add]
    assert sums
    collected = [e for e in sums if _every_symbol(e) != e]
    assert collected  # some sums do get collected: the comparison below means something
    assert all(sharing._collected(e) == _every_symbol(e) for e in sums)
    # Negative control: skipping the symbols that are repeated factors changes the result.
    monkeypatch.setattr(sharing, "_collectable", lambda expr: set())
    assert any(sharing._collected(e) != _every_symbol(e) for e in collected)


def test_collectable_symbols_are_repeated_factors_or_inside_a_compound_factor():
    a, b, c, x, y = sp.symbols("a b c x y", real=True)
    assert sharing._collectable(a * x + b * x**2 + c) == set()  # x to different powers: nothing to take out
    assert sp.collect(a * x + b * x**2 + c, x) == a * x + b * x**2 + c
    assert sharing._collectable(a * x**2 + b * x**2 + c) == {x}
    assert sharing._collectable(a * x + b * x + a) == {a, x}  # a: a factor of a*x and of a
    nested = y * (a * x + b * x) + c  # collect takes x out of the compound factor
    assert sp.collect(nested, x) != nested
    assert x in sharing._collectable(nested)
