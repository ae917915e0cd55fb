"""Common numeric factors taken out of sums before the exported programs are printed.

A sum such as ``c a + c b − c d`` (the programs' constants: masses, lengths, inertias, each
once per term it scales) becomes ``c (a + b − d)``: one multiplication instead of three, and
one constant where ``c`` and ``−c`` were two. It is applied to every assignment and output of
the exported programs (:mod:`robodyn.export.programs`), so each graph (CasADi's SX, JAX's)
has fewer operations for the same value (the rounding differs by an ulp or so per term: the
functions stay within 1e-14 of Pinocchio, as the export's tests check). Before that, the
program's negations are folded into their uses (:func:`negations_inlined`), and every sum is
printed with a term that is not negative first, so ``a − c x`` needs only ``c`` in the graph
(ur5's M + C v + G: 915 -> 893 CasADi instructions).
"""

from __future__ import annotations

import dataclasses
from collections import defaultdict

import sympy as sp

from robodyn.equations.program import Program


def factored_expression(expr: sp.Basic) -> sp.Basic:
    """``expr`` with the common factors of each sum taken out (unevaluated, so sympy does not
    distribute them again); everything else as it is.

    Args:
        expr: A sympy expression.
    """
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
        return _sum([_product(term) for term in terms])
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
    return _sum([product, _horner(outside)]) if outside else product


def _negative(expr: sp.Basic) -> bool:
    """A negative number or a product with a negative coefficient (printed as ``- c x``)."""
    return bool((expr.is_Number and expr < 0) or (expr.is_Mul and expr.args[0].is_Number and expr.args[0] < 0))


def _sum(parts: list[sp.Basic]) -> sp.Basic:
    """The unevaluated sum of ``parts`` (inner sums flattened) with a term that is not negative
    first: the printer subtracts the negative ones, so ``a − c x`` needs the constant ``c``,
    which the graph often has already, where ``−c x + a`` needed ``−c`` too."""
    terms = [arg for part in parts for arg in (part.args if part.is_Add else (part,))]
    if len(terms) == 1:
        return terms[0]
    first = next((i for i, term in enumerate(terms) if not _negative(term)), 0)
    terms.insert(0, terms.pop(first))
    return sp.Add(*terms, evaluate=False)


def factored(program: Program) -> Program:
    """The program with its negations inlined (:func:`negations_inlined`) and
    :func:`factored_expression` applied to every assignment and output.

    Args:
        program: A straight-line program (assignments, then outputs).
    """
    program = negations_inlined(program)
    return dataclasses.replace(
        program,
        assignments=tuple((symbol, factored_expression(expr)) for symbol, expr in program.assignments),
        outputs={name: tuple(factored_expression(sp.sympify(e)) for e in exprs) for name, exprs in program.outputs.items()},
    )


def negations_inlined(program: Program) -> Program:
    """The program without its assignments ``t = −u``: each use of ``t`` reads ``−u``, which
    sympy folds into the expression using it (``a − t`` is ``a + u``, ``u − t`` is ``2 u``,
    ``t t`` is ``u²``): no negation left to compute, the same value (a sign is exact). An
    assignment ``t = −c x`` (or ``−c x − d y``) holds ``c x`` instead and its uses read ``−t`` (the constant
    ``c`` is usually in the graph already, ``−c`` then is not needed).

    Args:
        program: A straight-line program (:class:`~robodyn.equations.program.Program`).
    """
    negated: dict[sp.Symbol, sp.Expr] = {}
    assignments = []
    for symbol, expr in program.assignments:
        expr = expr.xreplace(negated) if negated else expr
        if expr.is_Mul and len(expr.args) == 2 and expr.args[0] == -1 and expr.args[1].is_Symbol:
            negated[symbol] = expr
        elif _negative(expr) or (expr.is_Add and all(map(_negative, expr.args))):  # t = −c x: t holds c x, uses read −t
            negated[symbol] = -symbol
            assignments.append((symbol, -expr))
        else:
            assignments.append((symbol, expr))
    if not negated:
        return program
    outputs = {name: tuple(sp.sympify(e).xreplace(negated) for e in exprs) for name, exprs in program.outputs.items()}
    return dataclasses.replace(program, assignments=tuple(assignments), outputs=outputs)
