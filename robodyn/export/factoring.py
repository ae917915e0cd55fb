"""Common numeric factors taken out of sums before the exported programs are printed.

A sum such as ``c a + c b − c d`` (the programs' constants: masses, lengths, inertias, each
once per term it scales) becomes ``c (a + b − d)``: one multiplication instead of three, and
one constant where ``c`` and ``−c`` were two. It is applied to every assignment and output of
the exported programs (:mod:`robodyn.export.programs`), so each graph (CasADi's SX, JAX's)
has fewer operations for the same value (the rounding differs by an ulp or so per term: the
functions stay within 1e-14 of Pinocchio, as the export's tests check).
"""

from __future__ import annotations

import dataclasses
from collections import defaultdict

import sympy as sp

from robodyn.equations.program import Program


def factored_expression(expr: sp.Basic) -> sp.Basic:
    """``expr`` with the common factors of each sum taken out (unevaluated, so sympy does not
    distribute them again); everything else as it is."""
    if not expr.args or expr.is_Number or expr.is_Symbol:
        return expr
    args = [factored_expression(arg) for arg in expr.args]
    if not expr.is_Add:
        return expr.func(*args, evaluate=False) if args != list(expr.args) else expr
    terms = []
    for term in args:
        coefficient, rest = term.as_coeff_Mul()
        factors = list(rest.args) if rest.is_Mul else ([] if rest == 1 else [rest])
        if abs(coefficient) != 1:
            factors.append(abs(coefficient))
        terms.append((coefficient < 0, factors))
    return _horner(terms)


#: A term of a sum: (negative, its factors: numbers > 0 and other expressions).
_Term = tuple[bool, list[sp.Basic]]


def _product(term: _Term) -> sp.Basic:
    negative, factors = term
    numbers = [f for f in factors if f.is_Number]
    others = [f for f in factors if not f.is_Number]
    number = sp.Mul(*numbers) if numbers else sp.Integer(1)
    if negative:
        number = -number
    if number == 1:
        return sp.Mul(*others, evaluate=False) if len(others) > 1 else (others[0] if others else sp.Integer(1))
    return sp.Mul(number, *others, evaluate=False) if others else number


def _horner(terms: list[_Term]) -> sp.Basic:
    """The sum of ``terms``, the factor most of them share taken out first, and so on inside
    and outside (greedy: each factor shared by ``k`` terms saves ``k − 1`` products)."""
    counts: dict[sp.Basic, int] = defaultdict(int)
    for _, factors in terms:
        for factor in set(factors):
            counts[factor] += 1
    best = max(counts.items(), key=lambda item: (item[1], str(item[0])), default=(None, 0))
    if best[1] < 2:
        return sp.Add(*(_product(term) for term in terms), evaluate=False) if len(terms) > 1 else _product(terms[0])
    factor = best[0]
    inside, outside = [], []
    for negative, factors in terms:
        if factor in factors:
            rest = list(factors)
            rest.remove(factor)
            inside.append((negative, rest))
        else:
            outside.append((negative, factors))
    if all(negative for negative, _ in inside):  # −f (a + b), not f (−a − b)
        inside = [(False, rest) for _, rest in inside]
        shared: _Term = (True, [factor, _horner(inside)])
    else:
        shared = (False, [factor, _horner(inside)])
    product = _product(shared)
    return sp.Add(product, _horner(outside), evaluate=False) if outside else product


def factored(program: Program) -> Program:
    """The program with :func:`factored_expression` applied to every assignment and output."""
    return dataclasses.replace(
        program,
        assignments=tuple((symbol, factored_expression(expr)) for symbol, expr in program.assignments),
        outputs={name: tuple(factored_expression(sp.sympify(e)) for e in exprs) for name, exprs in program.outputs.items()},
    )
