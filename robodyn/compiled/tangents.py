"""The Newton–Euler program differentiated in reverse, its outputs in SIMD lanes.

:class:`TangentWriter` writes ``rdd_tau_derivatives`` (``∂τ/∂q``, ``∂τ/∂v`` of one state) and
its batch forms (and ``rdd_fd_derivatives``: ``−M⁻¹ ∂τ`` and ``M⁻¹`` of one state) for
:mod:`robodyn.compiled.derivatives`. For ``x = e(y1, y2, …)`` the partials
``∂e/∂y`` are differentiated symbolically (sympy, on the program's small expressions;
``∂cos θ/∂θ`` is the program's own ``−sin θ``) and printed once as scalars, in the
program's order (a value whose sum is ``c A + s B`` in a rotation's cos and sin is then
printed from its partials ``A`` and ``B``). Then the reverse sweep: the adjoint ``x̄`` of a
quantity is a vector over the outputs (lane ``j``: ``∂τ_j/∂x``, in chunks of the
instruction set's width ``W``: 2 SSE2, 4 AVX2, 8 AVX-512), and ``ȳ ← ȳ + ∂e/∂y · x̄`` is one
vector statement a chunk for each dependency ``y`` of each ``x``, last statement first; a
chunk no lane of which can be non-zero is not computed, an adjoint that is a constant
times another is not a statement. One sweep gives both ``∂τ/∂q`` and ``∂τ/∂v`` (forward
mode ran one group of directions for each: a quarter more vector work on a 7-joint arm);
only the quantities that depend on ``q`` or ``v`` are swept. The outputs are seeded through
the bodies' linear map (``θ = S q + offset``, ``θ̇ = S v``, ``τ = Sᵀ τ_bodies``: mimic joints
included) and the body coordinates' adjoints projected back (``∂τ/∂q = (Sᵀ θ̄)ᵀ``).

The single call runs these vector statements (GCC/Clang vector extension; compiled once
plainly and once per instruction set of the build's SIMD variants, the widest the CPU runs
chosen at the first call: :mod:`robodyn.compiled.tangent_single`), its columns turned into
rows at the end. A batch runs states in lanes instead (``rdd_tau_derivatives2``,
``rdd<L>_tau_derivatives``: :mod:`robodyn.compiled.derivatives`), from the same statements
written lane by lane: each output's entry is the vector statement's lane, the same IEEE
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
        # The quantities that depend on q or v (the inputs seeded: rows of S not zero), each
        # with its partials ``[(dependency, ∂x/∂dependency)]``, in the program's order.
        self.active: set[sp.Basic] = set()
        for b in range(self.bodies):
            if self.selection[b].any():
                self.active |= {program.inputs["q"][b], program.inputs["qd"][b]}
        self.uses: list[tuple[sp.Symbol, list[tuple[sp.Symbol, Term]]]] = []
        # Each quantity's adjoint (lane j: ∂τ_j/∂x), and how many sums made it so far.
        self.adjoints: dict[sp.Basic, Tangent] = {}
        self._sums: dict[sp.Basic, int] = {}
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

    def _record(self, symbol: sp.Symbol, expr: sp.Expr) -> dict[sp.Symbol, Term]:
        """The partials of ``symbol = expr`` by the quantities that depend on q or v (printed
        where not simple); ``symbol`` depends on them if one is not zero."""
        partials = []
        for dependency in sorted(expr.free_symbols & self.active, key=str):
            partial = self._partial(expr, dependency)
            if partial is not None:
                partials.append((dependency, partial))
        if partials:
            self.active.add(symbol)
            self.uses.append((symbol, partials))
        return dict(partials)

    def _value(self, symbol: sp.Symbol, expr: sp.Expr, partials: dict[sp.Symbol, Term]) -> list[str]:
        """``symbol = expr`` printed, its sum regrouped by its partials where that is shorter:
        ``Σ y ∂e/∂y + rest`` over variables ``y`` of degree 1 in every product of the sum
        that has them, no two in one product (a rotation's cos and sin: ``c A + s B``)."""
        plain = self.printer.statements([(symbol, expr)])
        if not expr.is_Add:
            return plain
        powers = [product.as_powers_dict() for product in expr.args]
        candidates = []
        for y, (_, factor) in partials.items():
            if factor is not None and all(power.get(y, 0) in (0, 1) for power in powers):
                products = {i for i, power in enumerate(powers) if power.get(y, 0) == 1}
                candidates.append((-len(products), str(y), y, products))
        taken: set[int] = set()
        chosen = []
        for count, _, y, products in sorted(candidates, key=lambda c: c[:2]):
            if count <= -2 and not products & taken:
                taken |= products
                chosen.append(y)
        if not chosen:
            return plain
        parts = [_product(partials[y][0], [self.names[y], partials[y][1]]) for y in chosen]
        rest = sp.Add(*(product for i, product in enumerate(expr.args) if i not in taken))
        if rest != 0:
            parts.append(self.printer.expression(rest))
        return [f"    const double {self.names[symbol]} = {' + '.join(parts)};"]

    def _accumulate(self, symbol: sp.Symbol, partials: list[tuple[sp.Symbol, Term]]) -> None:
        """A step of the reverse sweep: ``ȳ ← ȳ + ∂x/∂y · x̄`` for each dependency ``y`` of
        ``x = symbol`` (``x̄`` complete: every later use of ``x`` is done)."""
        adjoint = self.adjoints.get(symbol)
        if adjoint is None:
            return
        for dependency, (coefficient, factor) in partials:
            terms: list[tuple[float, str | None, Tangent]] = [(coefficient, factor, adjoint)]
            if dependency in self.adjoints:
                terms.insert(0, (1.0, None, self.adjoints[dependency]))
            count = self._sums[dependency] = self._sums.get(dependency, 0) + 1
            self.adjoints[dependency] = self._statement(f"a{count}_{self.names[dependency]}", terms)

    def source(self) -> str:
        """The single call ``rdd_tau_derivatives`` and the batches' ``rdd_tau_derivatives2``
        (``RDD_PAIRS``) and ``rdd<L>_tau_derivatives`` (``RDD_BLOCKS``)."""
        tau = list(self.program.outputs["tau"])
        values = self._with_partners(needed(self.program.assignments, tau))
        used = set().union(*(sp.sympify(e).free_symbols for e in tau), *(e.free_symbols for _, e in values))
        inputs = {s for symbols in self.program.inputs.values() for s in symbols}
        early = {s for s, e in values if isinstance(e, (sp.sin, sp.cos)) and e.free_symbols <= inputs}
        for line in self._trig([(s, e) for s, e in values if s in early]):
            self._both(line)  # sin and cos first: a partial of one is the other
        for symbol, expr in values:  # each value's partials, then the value (from them where shorter)
            partials = self._record(symbol, expr)
            if symbol not in early:
                for line in self._value(symbol, expr, partials):
                    self._both(line)
        for b, expr in enumerate(tau):  # τ_j = Σ_b S[b, j] τ_body_b: the seeds
            output = sp.Dummy(f"tau_body{b}")
            self.names[output] = f"tb{b}"
            self._record(output, sp.sympify(expr))
            seeds: dict[int, float | None] = {j: float(s) for j, s in enumerate(self.selection[b]) if s != 0}
            if seeds:
                self.adjoints[output] = (1.0, None, seeds)
        for symbol, partials in reversed(self.uses):
            self._accumulate(symbol, partials)
        results, stores = self._outputs()
        single = single_functions(self, used, stores)
        return "\n".join(single + pair_function(self, used, results) + block_functions(self, used, results))

    def _with_partners(self, values: list[tuple[sp.Symbol, sp.Expr]]) -> list[tuple[sp.Symbol, sp.Expr]]:
        """``values`` with the program's cosine of each sine printed (and the sine of each
        cosine): a partial of one is the other (``_partial`` names the program's), which ``τ``
        alone may not need (a pendulum's ``τ`` reads ``cos θ`` only)."""
        present = {symbol for symbol, _ in values}
        completed = []
        for symbol, expr in values:
            if isinstance(expr, (sp.sin, sp.cos)):
                partner = (sp.cos if isinstance(expr, sp.sin) else sp.sin)(expr.args[0])
                known = self._known.get(partner)
                if known is not None and known not in present:
                    completed.append((known, partner))
                    present.add(known)
            completed.append((symbol, expr))
        return completed

    def _trig(self, values: list[tuple[sp.Symbol, sp.Expr]]) -> list[str]:
        """The sines and cosines of the coordinates: of one argument together as one
        ``rd_sincos`` (the kernels' own: ``rd_sin`` and ``rd_cos`` each compute both)."""
        by_argument: dict[sp.Expr, dict[type, sp.Symbol]] = {}
        for symbol, expr in values:
            by_argument.setdefault(expr.args[0], {})[expr.func] = symbol
        lines = []
        for argument, pair in by_argument.items():
            if len(pair) == 2:
                sine, cosine = self.names[pair[sp.sin]], self.names[pair[sp.cos]]
                call = f"rd_sincos({self.printer.expression(argument)}, &{sine}, &{cosine});"
                lines.append(f"    double {sine}, {cosine}; {call}")
            else:
                ((function, symbol),) = pair.items()
                lines += self.printer.statements([(symbol, function(argument))])
        return lines

    def _outputs(self) -> tuple[list[tuple[str, int, str]], list[Statement]]:
        """``(array, index, C value)`` of every entry of ``dq`` and ``dv`` lane by lane, and
        the single call's stores: column ``k`` of each (``c<group>[k]``, lane ``j``:
        ``∂τ_j/∂x_k``), ``Sᵀ`` times the body coordinates' adjoints."""
        n, S = self.nv, self.selection
        results: list[tuple[str, int, str]] = []
        stores: list[Statement] = []
        for group, array in zip(GROUPS, ("dq", "dv"), strict=True):
            symbols = self.program.inputs["q" if group == "q" else "qd"]
            for k in range(n):
                terms: list[tuple[float, str | None, Tangent]] = [
                    (float(S[b, k]), None, self.adjoints[symbols[b]])
                    for b in range(self.bodies)
                    if S[b, k] != 0 and symbols[b] in self.adjoints
                ]
                for j in range(n):
                    parts = [self._lane_term(c, f, t, j) for c, f, t in terms if j in t[2]]
                    lane = self._lane_sum(parts) if parts else 0.0
                    results.append((array, j * n + k, c_number(lane) if isinstance(lane, float) else lane))
                stores.append((f"c{group}[{k}]", terms))
        return results, stores
