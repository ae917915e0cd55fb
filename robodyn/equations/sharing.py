"""Making a straight-line program shorter, keeping what it computes.

- :func:`share_subexpressions`: ``sympy.cse`` over every assignment and output, then only
  what the outputs need, in dependency order;
- :func:`reuse_products`: where ``t = a*b`` is assigned, later products containing ``a*b``
  use ``t``; each expression collected on a symbol where that saves operations;
- :func:`without_copies`: assignments of a bare symbol or number, and repeats of an
  expression already assigned, substituted away.

Each takes and returns a :class:`robodyn.equations.program.Program`.
"""

from __future__ import annotations

import sympy as sp

from robodyn.equations.program import Assignment, Program, in_order


def share_subexpressions(program: Program) -> Program:
    """Share repeated subexpressions (new symbols ``t0``, ``t1``, ...) and keep only what the
    outputs need, in dependency order.

    Args:
        program: The straight-line program (assignments and outputs).
    """
    names = [name for name, _ in program.assignments]
    outputs = program.output_expressions()
    taken = {s for _, e in program.assignments for s in e.free_symbols} | set(names)
    extra, reduced = sp.cse(
        [expr for _, expr in program.assignments] + outputs,
        symbols=sp.numbered_symbols("t", real=True, exclude=taken),
        order="none",
    )
    definitions = dict(extra)
    definitions.update(zip(names, reduced[: len(names)], strict=True))
    flat = reduced[len(names) :]
    return program.with_outputs(flat, in_order(definitions, flat))


def _fold_pairs(mul: sp.Expr, pairs: dict[frozenset, sp.Symbol]) -> sp.Expr:
    """A product with every pair of factors already assigned as ``t = a*b`` replaced by ``t``."""
    factors = list(mul.args)
    changed = True
    while changed:
        changed = False
        symbols = [f for f in factors if f.is_Symbol]
        for i, a in enumerate(symbols):
            for b in symbols[i + 1 :]:
                t = pairs.get(frozenset((a, b)))
                if t is not None:
                    factors.remove(a)
                    factors.remove(b)
                    factors.append(t)
                    changed = True
                    break
            if changed:
                break
    return sp.Mul(*factors)


def _collectable(expr: sp.Expr) -> set[sp.Basic]:
    """The symbols ``sympy.collect`` may take out of a sum (on any other it returns the sum as
    it is): those that are a factor, to the same power, of at least two terms, and every
    symbol inside a compound factor of a term (``y*(a*x + b*x)`` gives ``x*y*(a + b)``)."""
    seen: set[tuple[sp.Basic, sp.Basic]] = set()
    found: set[sp.Basic] = set()
    for term in expr.args:
        for factor in term.args if term.is_Mul else (term,):
            base, exponent = (factor.base, factor.exp) if factor.is_Pow else (factor, sp.S.One)
            if base.is_Symbol:
                if (base, exponent) in seen:
                    found.add(base)
                seen.add((base, exponent))
            elif not base.is_Number:
                found |= factor.free_symbols
    return found


def _collected(expr: sp.Expr) -> sp.Expr:
    """``expr`` collected on whichever of its symbols (in name order) saves operations.

    Only symbols that can be collected are tried (:func:`_collectable`): the same
    result as trying every symbol, without a ``collect`` and a ``count_ops`` per symbol
    (that was most of a compile's time)."""
    if not expr.is_Add:
        return expr
    best, best_ops = expr, None
    for symbol in sorted(expr.free_symbols, key=str):
        if not best.is_Add or symbol not in _collectable(best):
            continue
        candidate = sp.collect(best, symbol)
        if best_ops is None:
            best_ops = sp.count_ops(best)
        candidate_ops = sp.count_ops(candidate)
        if candidate_ops < best_ops:
            best, best_ops = candidate, candidate_ops
    return best


def reuse_products(program: Program) -> Program:
    """See the module: assigned products reused, expressions collected.

    Args:
        program: The straight-line program (assignments and outputs).
    """
    pairs: dict[frozenset, sp.Symbol] = {}

    def tidy(expr: sp.Expr) -> sp.Expr:
        if pairs:
            expr = expr.replace(lambda e: e.is_Mul and len(e.args) > 2, lambda e: _fold_pairs(e, pairs))
        return _collected(expr)

    assignments: list[Assignment] = []
    for symbol, expr in program.assignments:
        expr = tidy(expr)
        assignments.append((symbol, expr))
        if expr.is_Mul and len(expr.args) == 2 and all(a.is_Symbol for a in expr.args):
            pairs[frozenset(expr.args)] = symbol
    return program.with_outputs([tidy(e) for e in program.output_expressions()], assignments)


def without_copies(program: Program) -> Program:
    """Substitute away assignments of a bare symbol or number (``a = b``) and repeats of an
    expression already assigned.

    Args:
        program: The straight-line program (assignments and outputs).
    """
    copies: dict[sp.Symbol, sp.Expr] = {}
    seen: dict[sp.Expr, sp.Symbol] = {}
    kept: list[Assignment] = []
    for symbol, expr in program.assignments:
        expr = expr.xreplace(copies)
        if expr.is_Symbol or expr.is_Number:
            copies[symbol] = expr
        elif expr in seen:
            copies[symbol] = seen[expr]
        else:
            seen[expr] = symbol
            kept.append((symbol, expr))
    return program.with_outputs([sp.sympify(e).xreplace(copies) for e in program.output_expressions()], kept)


def shortened(program: Program) -> Program:
    """All three, in the order that works best: shared, copies removed, products reused,
    copies removed again.

    Args:
        program: The straight-line program (assignments and outputs).
    """
    return without_copies(reuse_products(without_copies(share_subexpressions(program))))
