"""Closed-form entries simplified the way a person would write them.

Each entry of ``M``, ``C q̇`` and ``G`` is exact (rationals, no round-off). It is split by
velocity products (``q̇_i q̇_j``); the coefficient of each is a function of ``q`` tried in
several forms — expanded, ``trigsimp`` (which merges ``sin·cos`` pairs and uses
``s² + c² = 1``), collected on its trigonometric monomials with each factor in Horner
form, factored — and the shortest kept; then the entry as a whole is tried factored, so
``C q̇`` groups velocity products sharing a coefficient. "Shortest" is
:func:`robodyn.equations.model.operation_count`'s measure (numbers as floats).

Round-off: a URDF's rotations enter as exact rationals that are orthonormal only to
about 1e-16, so ``s² + c² = 1`` can leave ``3.8e-18 cos(q)²``. :func:`chop` drops every term
whose numeric coefficient is below ``floor`` (:data:`RELATIVE_ROUND_OFF` of the largest
coefficient of the matrix, see :func:`largest_coefficient`), at the start, after every
``s² + c² = 1`` reduction, and no form that still carries such a term is chosen.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterable

import sympy as sp
from sympy.simplify.fu import TR10i

#: A term smaller than this, relative to the largest of its entry, is round-off.
RELATIVE_ROUND_OFF = 1e-12


def size(expr: sp.Expr) -> int:
    """Operations of ``expr`` as printed (fractions as one float each; a fast stand-in for
    :func:`robodyn.equations.model.operation_count`'s measure).

    Args:
        expr: A sympy expression.
    """
    fractions = {a: sp.Float(a) for a in expr.atoms(sp.Rational) if not a.is_Integer}
    return int(sp.count_ops(expr.xreplace(fractions) if fractions else expr))


def _weights(expr: sp.Expr) -> list[float]:
    """The magnitude of each term's numeric coefficient (``expr`` expanded)."""
    return [abs(float(t.as_coeff_Mul()[0])) for t in sp.Add.make_args(expr) if t != 0]


def largest_coefficient(exprs: Iterable[sp.Expr]) -> float:
    """The largest magnitude of a numeric coefficient of the expanded ``exprs`` (0 if none).

    Args:
        exprs: Sympy expressions.
    """
    return max((w for e in exprs for w in _weights(sp.expand(e))), default=0.0)


def chop(expr: sp.Expr, floor: float | None = None) -> sp.Expr:
    """``expr`` (expanded) without terms whose numeric coefficient is below ``floor``
    (default: :data:`RELATIVE_ROUND_OFF` of its own largest).

    Args:
        expr: A sympy expression.
        floor: Terms whose numeric coefficient is below it are dropped; ``None``: relative.
    """
    expr = sp.expand(expr)
    if not expr.is_Add:
        return expr if floor is None or expr == 0 or _weights(expr)[0] >= floor else sp.Integer(0)
    weights = _weights(expr)
    floor = RELATIVE_ROUND_OFF * max(weights) if floor is None else floor
    return sp.Add(*(t for t, w in zip(expr.args, weights, strict=True) if w >= floor))


def clean(expr: sp.Expr, floor: float) -> bool:
    """No term of ``expr`` (expanded) has a numeric coefficient below ``floor``.

    Args:
        expr: A sympy expression.
        floor: The smallest coefficient accepted.
    """
    return all(w >= floor for w in _weights(sp.expand(expr)))


def _horner(expr: sp.Expr, variables: Iterable[sp.Symbol]) -> sp.Expr:
    present = [v for v in variables if expr.has(v)]
    if not present:
        return expr
    try:
        return sp.horner(expr, *present)
    except sp.PolynomialError:
        return expr


def _collected(expr: sp.Expr, q: list[sp.Symbol]) -> sp.Expr:
    """Collected on the trigonometric monomials, each coefficient in Horner form in ``q``."""
    trig = sorted(expr.atoms(sp.sin, sp.cos), key=sp.default_sort_key)
    if not trig:
        return _horner(expr, q)
    parts = sp.collect(sp.expand(expr), trig, evaluate=False)
    return sp.Add(*(_horner(coefficient, q) * monomial for monomial, coefficient in parts.items()))


def absorb(expr: sp.Expr) -> sp.Expr:
    """A numeric factor in front of a product moved into one of its sums:
    ``(2*q + 1.4)*x`` rather than ``2*(q + 0.7)*x`` or ``3.3e-16*(1e13*s + ...)``.

    Args:
        expr: A sympy expression.
    """
    if expr.is_Add:
        return sp.Add(*(absorb(term) for term in expr.args))
    if not expr.is_Mul:
        return expr
    number, rest = expr.as_coeff_Mul()
    factors = [absorb(f) for f in sp.Mul.make_args(rest)]
    for i, f in enumerate(factors):  # -(a + b) x rather than (-a - b) x
        if f.is_Add and f.could_extract_minus_sign():
            factors[i], number = sp.expand(-f), -number
    sums = [i for i, f in enumerate(factors) if f.is_Add]
    if number in (1, -1) or not sums:
        return sp.Mul(number, *factors)
    options = []
    for i in sums:
        moved = list(factors)
        moved[i] = sp.expand(abs(number) * factors[i])
        options.append(sp.Mul(sp.sign(number), *moved))
    return min(options, key=lambda e: len(str(e.evalf(6))))


def _best(candidates: list[sp.Expr], floor: float) -> sp.Expr:
    """The shortest candidate without round-off (the first one is known to have none)."""
    kept = [candidates[0]] + [c for c in candidates[1:] if floor <= 0 or clean(c, floor)]
    return min((absorb(c) for c in kept), key=lambda e: (size(e), len(str(e))))


def pythagoras(expr: sp.Expr, floor: float = 0.0) -> sp.Expr:
    """``expr`` expanded, reduced with ``sin² + cos² = 1`` of each angle (towards
    whichever of ``sin²`` or ``cos²`` gives the shorter result), terms below ``floor``
    dropped.

    Args:
        expr: A sympy expression.
        floor: Terms whose numeric coefficient is below it are dropped.
    """
    expr = chop(expr, floor)
    angles = {f.args[0] for f in expr.atoms(sp.sin)} & {f.args[0] for f in expr.atoms(sp.cos)}
    for angle in sorted(angles, key=sp.default_sort_key):
        s, c = sp.sin(angle), sp.cos(angle)
        options = [expr]
        for square, other in ((s, c), (c, s)):
            reduced = sp.expand(
                expr.replace(
                    lambda e, sq=square: e.is_Pow and e.base == sq and e.exp >= 2,
                    lambda e, sq=square, ot=other: sq ** (e.exp - 2) * (1 - ot**2),
                )
            )
            options.append(chop(reduced, floor))
        expr = min(options, key=size)
    return expr


def completed_square(expr: sp.Expr, q: list[sp.Symbol]) -> sp.Expr:
    """``a q² + b q + c`` as ``a (q + b/2a)² + c − b²/4a`` for the first coordinate it is
    quadratic in (a prismatic joint's ``r = q + offset``), else ``expr``.

    Args:
        expr: A sympy expression.
        q: The joint position symbols.
    """
    for variable in q:
        if not expr.has(variable):
            continue
        try:
            poly = sp.Poly(expr, variable)
        except sp.PolynomialError:
            continue
        if poly.degree() != 2:
            continue
        a, b, c = poly.all_coeffs()
        shift = sp.cancel(b / (2 * a))
        rest = sp.expand(c - sp.cancel(b**2 / (4 * a)))
        return a * (variable + shift) ** 2 + _collected(rest, q)
    return expr


def coefficient(expr: sp.Expr, q: list[sp.Symbol], floor: float = 0.0) -> sp.Expr:
    """The shortest of several equivalent forms of a function of ``q`` (terms below
    ``floor`` dropped).

    Args:
        expr: A sympy expression.
        q: The joint position symbols.
        floor: Terms whose numeric coefficient is below it are dropped.
    """
    reduced = pythagoras(expr, floor)
    if reduced.is_number:
        return reduced
    merged = pythagoras(TR10i(reduced), floor)  # cos a cos b - sin a sin b = cos(a + b), ...
    candidates = [reduced, _collected(reduced, q), merged, sp.factor_terms(merged), _collected(merged, q)]
    candidates += [completed_square(reduced, q), completed_square(merged, q)]
    if sp.count_ops(reduced) < 200:
        with contextlib.suppress(sp.PolynomialError):
            candidates.append(sp.factor(reduced))
    return _best(candidates, floor)


def entry(expr: sp.Expr, q: list[sp.Symbol], qd: list[sp.Symbol], *, floor: float | None = None) -> sp.Expr:
    """One entry of ``M``, ``C q̇`` or ``G``, chopped and simplified (see the module).

    Args:
        expr: The exact entry.
        q: The joint position symbols.
        qd: The joint velocity symbols.
        floor: Terms whose numeric coefficient is below it are dropped (default
            :data:`RELATIVE_ROUND_OFF` of the entry's largest).
    """
    expr = chop(expr, floor)
    floor = RELATIVE_ROUND_OFF * largest_coefficient([expr]) if floor is None else floor
    speeds = [v for v in qd if expr.has(v)]
    if not speeds:
        return coefficient(expr, q, floor)
    terms = sp.Poly(expr, *speeds).terms()
    by_product = sp.Add(
        *(coefficient(c, q, floor) * sp.Mul(*(v**k for v, k in zip(speeds, powers, strict=True))) for powers, c in terms)
    )
    candidates = [by_product, sp.factor_terms(by_product)]
    with contextlib.suppress(sp.PolynomialError):
        candidates.append(sp.factor(by_product))
    return _best(candidates, floor)
