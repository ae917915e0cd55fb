"""The Newton–Euler program differentiated forward, its directions in SIMD lanes.

:class:`TangentWriter` writes ``rdd_tau_derivatives`` (``∂τ/∂q``, ``∂τ/∂v`` of one state) and
its batch forms (and ``rdd_fd_derivatives``: ``−M⁻¹ ∂τ`` and ``M⁻¹`` of one state) for
:mod:`robodyn.compiled.derivatives`. For ``x = e(y1, y2, …)`` the partials
``∂e/∂y`` are differentiated symbolically (sympy, on the program's small expressions;
``∂cos θ/∂θ`` is the program's own ``−sin θ``) and printed once as scalars; the tangents are
vectors over the directions, one group for ``q_0 … q_{n−1}`` and one for ``v_0 … v_{n−1}``
(a lane a direction, in chunks of the instruction set's width ``W``: 2 SSE2, 4 AVX2, 8
AVX-512): ``dx = Σ ∂e/∂y · dy`` is one vector statement a chunk however many directions
reach ``x``, and a chunk no lane of which can be non-zero is not computed. The
directions are seeded through the bodies' linear map (``θ = S q + offset``, ``θ̇ = S v``:
mimic joints included) and projected back (``∂τ/∂x = Sᵀ ∂τ_bodies/∂x``); a tangent that is
a constant times another is not a statement.

The single call runs these vector statements (GCC/Clang vector extension; compiled once
plainly and once per instruction set of the build's SIMD variants, the widest the CPU runs
chosen at the first call: :mod:`robodyn.compiled.tangent_single`). A batch runs states in
lanes instead (``rdd_tau_derivatives2``, ``rdd<L>_tau_derivatives``:
:mod:`robodyn.compiled.derivatives`), from the same statements
written lane by lane: each direction's entry is the vector statement's lane, the same IEEE
operations in the same order, the terms a lane cannot have left out (they add an exact
zero in the vector: at most the sign of a zero differs), so a batch row equals its single
call (no FMA: contraction is off).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import cast

import numpy as np
import sympy as sp

from robodyn.compiled.tangent_batches import block_functions, pair_function
from robodyn.compiled.tangent_single import single_functions
from robodyn.equations.c_printer import CPrinter, c_number
from robodyn.equations.program import Program, needed

#: A value in the generated code: ``coefficient * name`` (``name`` None: the constant).
Term = tuple[float, str | None]
#: A tangent: ``(coefficient, vector name, lanes)``: ``coefficient * name`` with the lanes
#: that can be non-zero (a lane's value: None for the lane's own variable ``name_k``, else
#: the constant it is); a constant vector when the name is None (``lanes``: its non-zero
#: entries).
Tangent = tuple[float, str | None, dict[int, float | None]]
#: A vector statement of the single call: ``(name, [(coefficient, factor, tangent), ...])``.
Statement = tuple[str, list[tuple[float, str | None, Tangent]]]
#: The two groups of directions: ``q`` (lane ``j``: ``q_j``) and ``v`` (lane ``j``: ``v_j``).
GROUPS = ("q", "v")


def _diff(expr: sp.Expr, symbol: sp.Symbol) -> sp.Expr:
    """``∂expr/∂symbol``: by hand for the program's sums of products of symbols and whole
    powers (fast), by ``sympy.diff`` for anything else."""
    if expr == symbol:
        return sp.Integer(1)
    if expr.is_Add:
        return sp.Add(*(_diff(term, symbol) for term in expr.args if symbol in term.free_symbols))
    if expr.is_Mul:
        inside = [i for i, factor in enumerate(expr.args) if symbol in factor.free_symbols]
        if len(inside) == 1:
            i = inside[0]
            rest = expr.args[:i] + expr.args[i + 1 :]
            return sp.Mul(*rest, _diff(expr.args[i], symbol))
    if expr.is_Pow and expr.base == symbol and expr.exp.is_Integer:
        return expr.exp * symbol ** (expr.exp - 1)
    return sp.diff(expr, symbol)


def _term(expr: sp.Expr, names: dict[sp.Symbol, str]) -> Term | None:
    """``expr`` as ``coefficient * name`` if it is that simple (a number, a symbol, or
    number × symbol), else None."""
    if expr.is_Number:
        return float(expr), None
    if expr.is_Symbol:
        return 1.0, names[expr]
    if expr.is_Mul and len(expr.args) == 2 and expr.args[0].is_Number and expr.args[1].is_Symbol:
        return float(expr.args[0]), names[expr.args[1]]
    return None


def _product(coefficient: float, factors: Sequence[str | None]) -> str:
    """``c*f1*f2`` (evaluated left to right: ``(c*f1)*f2``), unit coefficients left out."""
    names = [f for f in factors if f]
    if not names:
        return c_number(coefficient)
    return "*".join(names) if coefficient == 1.0 else f"{c_number(coefficient)}*" + "*".join(names)


class TangentWriter:
    """Writes ``rdd_tau_derivatives`` for a Newton–Euler program over bodies (see the module).

    Args:
        program: ``tau`` of the bodies (inputs ``q``, ``qd``, ``qdd``, one per body).
        selection: ``S``, shape (n_bodies, nv).
        offset: Shape (n_bodies,).
        variants: The build's SIMD variants ``(name, lanes, GCC target)``.
    """

    def __init__(
        self, program: Program, selection: np.ndarray, offset: np.ndarray, variants: Sequence[tuple[str, int, str]] = ()
    ):
        self.program = program
        self.variants = tuple(variants)
        self.selection = np.asarray(selection, float)
        self.offset = np.asarray(offset, float)
        self.bodies, self.nv = self.selection.shape
        self.names: dict[sp.Symbol, str] = {symbol: f"r{i}" for i, (symbol, _) in enumerate(program.assignments)}
        inputs = (program.inputs["q"], program.inputs["qd"], program.inputs["qdd"])
        for symbols, local in zip(inputs, ("th", "thd", "thdd"), strict=True):
            self.names.update({symbol: f"{local}{b}" for b, symbol in enumerate(symbols)})
        self.printer = CPrinter(self.names, trig="rd_")  # the kernels' own sin and cos (trig.c)
        # Each quantity's tangents by group.
        self.tangents: dict[sp.Symbol, dict[str, Tangent]] = {}
        for b in range(self.bodies):
            seeds = {j: float(s) for j, s in enumerate(self.selection[b]) if s != 0}
            if seeds:
                lanes: dict[int, float | None] = dict(seeds)
                self.tangents[program.inputs["q"][b]] = {"q": (1.0, None, lanes)}
                self.tangents[program.inputs["qd"][b]] = {"v": (1.0, None, dict(lanes))}
        trig = (sp.sin, sp.cos)
        self._known = {expr: symbol for symbol, expr in program.assignments if isinstance(expr, trig)}
        self._partials: dict[sp.Expr, str] = {}
        self.lines: list[str] = []  # lane by lane (the batches' statements)
        # The single call's: scalar lines, and vector statements (name, terms) printed for a
        # width of vectors by robodyn.compiled.tangent_single.
        self.vector_lines: list[str | Statement] = []

    def _both(self, line: str) -> None:
        self.lines.append(line)
        self.vector_lines.append(line)

    def _coordinates(self, used: set[sp.Basic], suffix: str = "") -> list[str]:
        """``th``/``thd``/``thdd`` values of the body coordinates the program uses, as
        ``const double name = C expression in q{suffix}, v{suffix}, a{suffix};``."""
        values = []
        inputs = (self.program.inputs["q"], self.program.inputs["qd"], self.program.inputs["qdd"])
        for b in range(self.bodies):
            for symbols, (local, array) in zip(inputs, (("th", "q"), ("thd", "v"), ("thdd", "a")), strict=True):
                if symbols[b] not in used:
                    continue
                terms = [(self.selection[b, j], f"{array}{suffix}[{j}]") for j in range(self.nv) if self.selection[b, j] != 0]
                value = " + ".join(_product(c, [name]) for c, name in terms) or "0.0"
                if local == "th" and self.offset[b] != 0:
                    value += f" + {c_number(self.offset[b])}"
                values.append(f"    const double {local}{b} = {value};")
        return values

    def _partial(self, expr: sp.Expr, symbol: sp.Symbol) -> Term | None:
        """``∂expr/∂symbol`` as a term (named by a new statement when not simple), None if 0."""
        partial = _diff(expr, symbol).xreplace(self._known)
        if partial == 0:
            return None
        if not partial.free_symbols:  # a constant such as √2/2: folded like a number
            return float(partial), None
        simple = _term(partial, self.names)
        if simple is not None:
            return simple
        name = self._partials.get(partial)
        if name is None:
            name = self._partials[partial] = f"p{len(self._partials)}"
            self._both(f"    const double {name} = {self.printer.expression(partial)};")
        return 1.0, name

    def _vector_term(self, coefficient: float, factor: str | None, tangent: Tangent, lanes: range, vector: str) -> str:
        """A term of a vector statement on the chunk of directions ``lanes`` (type ``vector``)."""
        scale, name, values = tangent
        if name is not None:
            return _product(coefficient * scale, [factor, f"{name}_c{lanes.start // len(lanes)}"])
        constant = ", ".join(c_number(coefficient * scale * (values.get(k) or 0.0)) for k in lanes)
        literal = f"({vector}){{{constant}}}"
        return f"{factor}*{literal}" if factor else literal

    @staticmethod
    def _lane_term(coefficient: float, factor: str | None, tangent: Tangent, lane: int) -> str | float:
        """Lane ``lane`` of :meth:`_vector_term`: its C, or a float when it is a constant
        (the same IEEE product the vector's lane makes)."""
        scale, name, lanes = tangent
        value = lanes[lane]
        if name is None:  # a constant vector: its lane folded, times the factor
            constant = coefficient * scale * cast(float, value)
            return _product(constant, [factor]) if factor else constant
        if value is None:
            return _product(coefficient * scale, [factor, f"{name}_{lane}"])
        if factor is None:
            return coefficient * scale * value
        return _product(coefficient * scale, [factor, c_number(value)])

    @staticmethod
    def _lane_sum(parts: list[str | float]) -> str | float:
        """``parts`` summed in order: a float when they all are (Python's IEEE sums, as C's)."""
        if all(isinstance(part, float) for part in parts):
            total = cast(float, parts[0])
            for part in parts[1:]:
                total += cast(float, part)
            return total
        return " + ".join(part if isinstance(part, str) else c_number(part) for part in parts)

    def _statement(self, target: str, terms: list[tuple[float, str | None, Tangent]]) -> Tangent:
        """``Σ coefficient * factor * tangent`` as a tangent: an alias when it is one tangent
        times a constant, else a vector statement and its lanes' statements (a lane that is
        a constant is not a statement)."""
        if len(terms) == 1 and terms[0][1] is None:
            coefficient, _, (scale, name, lanes) = terms[0]
            if name is not None:
                return coefficient * scale, name, lanes
            return 1.0, None, {k: coefficient * scale * cast(float, value) for k, value in lanes.items()}
        self.vector_lines.append((target, terms))
        result: dict[int, float | None] = {}
        for k in sorted({k for _, _, tangent in terms for k in tangent[2]}):
            lane = self._lane_sum([self._lane_term(c, factor, tangent, k) for c, factor, tangent in terms if k in tangent[2]])
            if isinstance(lane, float):
                result[k] = lane
            else:
                result[k] = None
                self.lines.append(f"    const double {target}_{k} = {lane};")
        return 1.0, target, result

    def differentiate(self, symbol: sp.Symbol, expr: sp.Expr, name: str) -> None:
        """The tangents of ``symbol = expr`` in both groups of directions that reach it.

        Args:
            symbol: The assigned symbol.
            expr: Its value, an expression of earlier symbols and the inputs.
            name: The symbol's C name; its tangents are named ``d<group>_<name>``.
        """
        partials = []
        for dependency in sorted(expr.free_symbols & self.tangents.keys(), key=str):
            partial = self._partial(expr, dependency)
            if partial is not None:
                partials.append((partial, self.tangents[dependency]))
        for group in GROUPS:
            terms = [(c, factor, tangents[group]) for (c, factor), tangents in partials if group in tangents]
            if terms:
                self.tangents.setdefault(symbol, {})[group] = self._statement(f"d{group}_{name}", terms)

    def source(self) -> str:
        """The single call ``rdd_tau_derivatives`` and the batches' ``rdd_tau_derivatives2``
        (``RDD_PAIRS``) and ``rdd<L>_tau_derivatives`` (``RDD_BLOCKS``)."""
        tau = list(self.program.outputs["tau"])
        values = needed(self.program.assignments, tau)
        used = set().union(*(sp.sympify(e).free_symbols for e in tau), *(e.free_symbols for _, e in values))
        inputs = {s for symbols in self.program.inputs.values() for s in symbols}
        early = {s for s, e in values if isinstance(e, (sp.sin, sp.cos)) and e.free_symbols <= inputs}
        for line in self.printer.statements([(s, e) for s, e in values if s in early]):
            self._both(line)  # sin and cos first: a partial of one is the other
        for symbol, expr in values:  # each value, then its derivatives (short live ranges)
            if symbol not in early:
                for line in self.printer.statements([(symbol, expr)]):
                    self._both(line)
            self.differentiate(symbol, expr, self.names[symbol])
        outputs = [sp.Dummy(f"tau_body{b}") for b in range(self.bodies)]
        for b, (symbol, expr) in enumerate(zip(outputs, tau, strict=True)):
            self.names[symbol] = f"tb{b}"
            self.differentiate(symbol, sp.sympify(expr), f"tb{b}")
        results, stores = self._outputs(outputs)
        single = single_functions(self, used, stores)
        return "\n".join(single + pair_function(self, used, results) + block_functions(self, used, results))

    def _outputs(self, outputs: Sequence[sp.Symbol]) -> tuple[list[tuple[str, int, str]], list[Statement]]:
        """``(array, index, C value)`` of every entry of ``dq`` and ``dv`` lane by lane, and
        the single call's stores (``Sᵀ`` times the bodies' tangents)."""
        n, S = self.nv, self.selection
        results: list[tuple[str, int, str]] = []
        stores: list[Statement] = []
        for j in range(n):
            for group, array in zip(GROUPS, ("dq", "dv"), strict=True):
                terms: list[tuple[float, str | None, Tangent]] = [
                    (float(S[b, j]), None, self.tangents[outputs[b]][group])
                    for b in range(self.bodies)
                    if S[b, j] != 0 and group in self.tangents.get(outputs[b], {})
                ]
                for k in range(n):
                    parts = [self._lane_term(c, f, t, k) for c, f, t in terms if k in t[2]]
                    lane = self._lane_sum(parts) if parts else 0.0
                    results.append((array, j * n + k, c_number(lane) if isinstance(lane, float) else lane))
                stores.append((f"b{group}[{j}]", terms))
        return results, stores
