"""Derivatives of the compiled dynamics: ``∂τ/∂q``, ``∂τ/∂v`` and ``∂q̈/∂q``, ``∂q̈/∂v`` in C.

``∂τ/∂q`` and ``∂τ/∂v`` are the Newton–Euler program (the one the ``tau`` kernel runs)
differentiated forward, assignment by assignment: for ``x = e(y1, y2, …)`` the partials
``∂e/∂y`` are differentiated symbolically (sympy, on the program's small expressions;
``∂cos θ/∂θ`` is the program's own ``−sin θ``) and printed once, then for each input
direction ``k`` the program gets ``dx_k = Σ ∂e/∂y · dy_k``. The directions are the robot's
``q_0 … q_{n−1}, v_0 … v_{n−1}``, seeded through the bodies' linear map
(``θ = S q + offset``, ``θ̇ = S v``: mimic joints included) and projected back
(``∂τ/∂x = Sᵀ ∂τ_bodies/∂x``). Which directions reach a quantity is tracked, so a link's
rotation carries one derivative and nothing is computed that is zero by structure; a
tangent that is a constant times another is not a statement at all. ``∂τ/∂a = M`` is the
``mass`` kernel.

The forward dynamics' derivatives follow: ``q̈ = FD(q, v, τ)`` (the LDLᵀ of ``M``),
``∂q̈/∂x = −M⁻¹ ∂τ/∂x`` at ``a = q̈`` and ``∂q̈/∂τ = M⁻¹``, the three solved with the one
factorisation (``derivatives.c``).

The kernels make a module of their own, built on the first derivative asked for
(:func:`derivative_module`) and cached like the robot's (:mod:`robodyn.compiled.build`;
about as much CPU as the robot's ``tau`` program, plus the C compiler). The functions::

    static void rdd_tau_derivatives(const double *q, const double *v, const double *a,
                                    double *dq, double *dv);   /* (nv, nv) row-major each */
    static void rdd_tau_derivatives2(...);  /* 2 states, SSE2; rdd8_...: 8 states, AVX-512 */

A batch goes ``L`` rows at a time through the variant of the instruction set the build chose
(:func:`robodyn.compiled.simd.build_variants`, as the dynamics' SIMD blocks: the widest the
CPU runs, or ``$ROBODYN_SIMD``; 2, 4 or 8 lanes, compiled with that ``target`` attribute and
chosen at run time with ``__builtin_cpu_supports``), else two at a time
(``rdd_tau_derivatives2``, plain SSE2), on the runtime's thread pool. Each is a GCC/Clang
vector extension of the same statements: the same IEEE operations in the same order (no
FMA: contraction is off), so each row is bit-identical to a single call; ``cos``/``sin``
are the kernels' own (``trig.c``: ``rd_sin`` in the single call, its vector form in the
blocks, as the dynamics' SIMD blocks; libm's, lane by lane, were 19 % of a block's time).

Why forward mode through the program, not the analytical recursions (Carpentier and Mansard
2018): the program is exact for every robot the compiled engine takes (mimic joints, oblique
axes, prismatic joints), constants folded, structural zeros known: straight-line arithmetic
(its cost: ~10 000 operations a panda-arm state; ``make bench``, ``compiled-derivatives-*``).
"""

from __future__ import annotations

import re
from collections.abc import Callable, Sequence
from pathlib import Path
from types import ModuleType
from typing import cast

import numpy as np
import sympy as sp

from robodyn.compiled import build, simd
from robodyn.compiled.cache import robot_key
from robodyn.compiled.programs import dynamics_programs, robot_bodies
from robodyn.dynamics.robot import Robot
from robodyn.equations.c_printer import CPrinter, c_combination, c_number
from robodyn.equations.program import Program, needed
from robodyn.exceptions import CompileError, NonFiniteResultError, SingularMassMatrixError

_RUNTIME = Path(__file__).with_name("derivatives.c")

#: A scalar call left in a vector statement (the vector forms take none).
_SCALAR_CALL = re.compile(r"(?<!\w)(?:rd_)?(?:cos|sin|pow)\(")
#: A value in the generated code: ``coefficient * name`` (``name`` None: the constant).
Term = tuple[float, str | None]


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


class TangentWriter:
    """Writes ``rdd_tau_derivatives`` for a Newton–Euler program over bodies (see the module).

    Args:
        program: ``tau`` of the bodies (inputs ``q``, ``qd``, ``qdd``, one per body).
        selection: ``S``, shape (n_bodies, nv).
        offset: Shape (n_bodies,).
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
        # Each quantity's derivatives: direction -> coefficient * name (or a constant).
        self.tangents: dict[sp.Symbol, dict[int, Term]] = {}
        for b in range(self.bodies):
            for symbols, shift in ((program.inputs["q"], 0), (program.inputs["qd"], self.nv)):
                seeds: dict[int, Term] = {shift + j: (float(s), None) for j, s in enumerate(self.selection[b]) if s != 0}
                if seeds:
                    self.tangents[symbols[b]] = seeds
        trig = (sp.sin, sp.cos)
        self._known = {expr: symbol for symbol, expr in program.assignments if isinstance(expr, trig)}
        self._partials: dict[sp.Expr, str] = {}
        self.lines: list[str] = []

    def _coordinates(self, used: set[sp.Basic], suffix: str = "") -> list[str]:
        """``th``/``thd``/``thdd`` values of the body coordinates the program uses, as
        ``(name, C expression in q{suffix}, v{suffix}, a{suffix})``."""
        values = []
        inputs = (self.program.inputs["q"], self.program.inputs["qd"], self.program.inputs["qdd"])
        for b in range(self.bodies):
            for symbols, (local, array) in zip(inputs, (("th", "q"), ("thd", "v"), ("thdd", "a")), strict=True):
                if symbols[b] not in used:
                    continue
                terms = [(self.selection[b, j], f"{array}{suffix}[{j}]") for j in range(self.nv) if self.selection[b, j] != 0]
                value = c_combination(terms)
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
            self.lines.append(f"    const double {name} = {self.printer.expression(partial)};")
        return 1.0, name

    def _combine(self, name: str, direction: int, terms: list[tuple[float, list[str]]]) -> Term | None:
        """``Σ coefficient * Π names`` as a term: kept as it is when simple, else a statement."""
        constant = sum(c for c, factors in terms if not factors)
        products: dict[str, float] = {}
        for c, factors in terms:
            if factors:
                key = "*".join(factors)
                products[key] = products.get(key, 0.0) + c
        products = {k: c for k, c in products.items() if c != 0.0}
        if not products:
            return (constant, None) if constant != 0.0 else None
        if constant == 0.0 and len(products) == 1:
            ((key, c),) = products.items()
            if "*" not in key:
                return c, key
        value = c_combination(list((c, k) for k, c in products.items()))
        if constant != 0.0:
            value += f" + {c_number(constant)}"
        target = f"d{name}_{direction}"
        self.lines.append(f"    const double {target} = {value};")
        return 1.0, target

    def differentiate(self, symbol: sp.Symbol, expr: sp.Expr, name: str) -> None:
        """The derivatives of ``symbol = expr`` in every direction that reaches it."""
        partials = []
        for dependency in sorted(expr.free_symbols & self.tangents.keys(), key=str):
            partial = self._partial(expr, dependency)
            if partial is not None:
                partials.append((partial, self.tangents[dependency]))
        directions = sorted({k for _, tangent in partials for k in tangent})
        result: dict[int, Term] = {}
        for k in directions:
            terms = []
            for (pc, pn), tangent in partials:
                if k in tangent:
                    tc, tn = tangent[k]
                    terms.append((pc * tc, [n for n in (pn, tn) if n is not None]))
            combined = self._combine(name, k, terms)
            if combined is not None:
                result[k] = combined
        if result:
            self.tangents[symbol] = result

    def source(self) -> str:
        """The C functions ``rdd_tau_derivatives`` and, where the program allows it, the same
        on two states at once in SIMD lanes (``rdd_tau_derivatives2``, ``RDD_PAIRS`` 1)."""
        tau = list(self.program.outputs["tau"])
        values = needed(self.program.assignments, tau)
        used = set().union(*(sp.sympify(e).free_symbols for e in tau), *(e.free_symbols for _, e in values))
        for symbol, expr in values:  # each value, then its derivatives (short live ranges)
            self.lines += self.printer.statements([(symbol, expr)])
            self.differentiate(symbol, expr, self.names[symbol])
        outputs = [sp.Dummy(f"tau_body{b}") for b in range(self.bodies)]
        for b, (symbol, expr) in enumerate(zip(outputs, tau, strict=True)):
            self.names[symbol] = f"tb{b}"
            self.differentiate(symbol, sp.sympify(expr), f"tb{b}")
        results = self._outputs(outputs)
        scalar = [
            "static void rdd_tau_derivatives(const double *q, const double *v, const double *a, double *dq, double *dv) {",
            *self._coordinates(used),
            *self.lines,
            *(f"    {out}[{index}] = {value};" for out, index, value in results),
            "}",
            "",
        ]
        return "\n".join(scalar + self._pairs(used, results) + self._blocks(used, results))

    def _pairs(self, used: set[sp.Basic], results: list[tuple[str, int, str]]) -> list[str]:
        """``rdd_tau_derivatives2``: the same statements on two states, one a SIMD lane
        (GCC/Clang vector extension; the same IEEE operations, so bit-identical results)."""
        pattern = re.compile(r"= rd_(cos|sin)\((\w+)\);$")
        body = [pattern.sub(r"= rdd_\1_2(\2);", line).replace("const double ", "const rdd_v2 ") for line in self.lines]
        if any(_SCALAR_CALL.search(line) for line in body):
            return ["#define RDD_PAIRS 0", ""]
        lanes = zip(self._coordinates(used, "0"), self._coordinates(used, "1"), strict=True)
        head = [
            f"{one.split(' = ')[0].replace('double', 'rdd_v2')} = {{{one.split(' = ')[1][:-1]}, {two.split(' = ')[1][:-1]}}};"
            for one, two in lanes
        ]
        tail = []
        for out, index, value in results:
            try:  # a constant: the same in both lanes
                tail.append(f"    {out}0[{index}] = {out}1[{index}] = {c_number(float(value))};")
            except ValueError:
                tail.append(f"    {{ const rdd_v2 o = {value}; {out}0[{index}] = o[0]; {out}1[{index}] = o[1]; }}")
        return [
            "#define RDD_PAIRS 1",
            "typedef double rdd_v2 __attribute__((vector_size(16)));",
            "static inline rdd_v2 rdd_cos_2(rdd_v2 x) { const rdd_v2 r = {rd_cos(x[0]), rd_cos(x[1])}; return r; }",
            "static inline rdd_v2 rdd_sin_2(rdd_v2 x) { const rdd_v2 r = {rd_sin(x[0]), rd_sin(x[1])}; return r; }",
            "static void rdd_tau_derivatives2(const double *q0, const double *v0, const double *a0, const double *q1,",
            "                                 const double *v1, const double *a1, double *dq0, double *dv0, double *dq1, double *dv1) {",
            *head,
            *body,
            *tail,
            "}",
            "",
        ]

    def _blocks(self, used: set[sp.Basic], results: list[tuple[str, int, str]]) -> list[str]:
        """``rdd<L>_tau_derivatives``: the same statements on ``L`` states at once, one a lane
        of a vector of the instruction set of each of :attr:`variants` (``(name, L, GCC
        target)``, :data:`robodyn.compiled.simd.VARIANTS`: SSE2, AVX2, AVX-512), compiled
        with its ``target`` attribute; ``cos``/``sin`` the SIMD dynamics' (``rds<L>_sin``: the
        single call's ``rd_sin`` on every lane). ``RDD_BLOCKS`` names the variants for
        ``derivatives.c``'s blocks and dispatch."""
        pattern = re.compile(r"= rd_(cos|sin)\((\w+)\);$")
        out: list[str] = []
        names: list[str] = []
        for name, lanes, target in self.variants:
            vector, attribute = f"rdd{lanes}", f'__attribute__((target("{target}")))'
            body = [pattern.sub(rf"= {vector}_\1(\2);", line).replace("const double ", f"const {vector} ") for line in self.lines]
            if any(_SCALAR_CALL.search(line) for line in body):
                return ["#define RDD_BLOCKS(X)", ""]
            lane_values = [self._coordinates(used, str(lane)) for lane in range(lanes)]
            head = []
            for i, first in enumerate(lane_values[0]):
                values = ", ".join(lane_values[lane][i].split(" = ", 1)[1][:-1] for lane in range(lanes))
                head.append(f"    const {vector} {first.split(' = ')[0].split()[-1]} = {{{values}}};")
            tail = []
            for array, index, value in results:
                try:  # a constant: the same in every lane
                    constant = c_number(float(value))
                    tail.append("    " + " = ".join(f"{array}{lane}[{index}]" for lane in range(lanes)) + f" = {constant};")
                except ValueError:
                    stores = " ".join(f"{array}{lane}[{index}] = o[{lane}];" for lane in range(lanes))
                    tail.append(f"    {{ const {vector} o = {value}; {stores} }}")
            pointers = [
                f"    const double *q{lane} = q[{lane}], *v{lane} = v[{lane}], *a{lane} = a[{lane}];"
                f" double *dq{lane} = dq[{lane}], *dv{lane} = dv[{lane}];"
                for lane in range(lanes)
            ]
            inline = f"static inline __attribute__((always_inline)) {attribute}"
            lane_loop = f"{vector} r; for (int l = 0; l < {lanes}; ++l) r[l] ="
            out += [
                f"typedef double {vector} __attribute__((vector_size({8 * lanes})));",
                "#ifdef RD_SIMD",  # the SIMD dynamics' sin and cos on vectors: rd_sin's operations on every lane
                f"{inline} {vector} {vector}_cos({vector} x) {{ return rds{lanes}_cos(x); }}",
                f"{inline} {vector} {vector}_sin({vector} x) {{ return rds{lanes}_sin(x); }}",
                "#else",
                f"{inline} {vector} {vector}_cos({vector} x) {{ {lane_loop} rd_cos(x[l]); return r; }}",
                f"{inline} {vector} {vector}_sin({vector} x) {{ {lane_loop} rd_sin(x[l]); return r; }}",
                "#endif",
                f"static {attribute} void {vector}_tau_derivatives(const double *const *q, const double *const *v,",
                "        const double *const *a, double *const *dq, double *const *dv) {",
                *pointers,
                *head,
                *body,
                *tail,
                "}",
                "",
            ]
            vzeroupper = "__builtin_ia32_vzeroupper();" if lanes > 2 else ""
            names.append(f'X({vector}, {lanes}, "{name}", "{target}", {attribute}, rds{lanes}, {vzeroupper})')
        if not out:
            return ["#define RDD_BLOCKS(X)", ""]
        guard = "#if defined(__x86_64__) && defined(__GNUC__)"
        return [guard, *out, f"#define RDD_BLOCKS(X) {' '.join(names)}", "#else", "#define RDD_BLOCKS(X)", "#endif", ""]

    def _outputs(self, outputs: Sequence[sp.Symbol]) -> list[tuple[str, int, str]]:
        """``(array, index, C value)`` of every entry of ``dq`` and ``dv``: ``Sᵀ`` times the
        bodies' derivatives."""
        n, S = self.nv, self.selection
        results = []
        for j in range(n):
            for k in range(2 * n):
                terms = []
                for b in range(self.bodies):
                    entry = self.tangents.get(outputs[b], {}).get(k)
                    if S[b, j] != 0 and entry is not None:
                        terms.append((S[b, j] * entry[0], entry[1]))
                constant = sum(c for c, name in terms if name is None)
                named = [(c, name) for c, name in terms if name is not None]
                value = c_combination(named) if named else ""
                if constant != 0.0 or not named:
                    value = f"{value} + {c_number(constant)}" if named else c_number(constant)
                results.append(("dq" if k < n else "dv", j * n + k % n, value))
        return results


def derivative_module(robot: Robot, *, kernels: Callable[[], str]) -> ModuleType:
    """The robot's derivative module: found by the robot's key, else generated, built and cached.

    The Newton–Euler program differentiated is the robot's cached one
    (:func:`robodyn.compiled.programs.dynamics_programs`, the one its ``tau`` kernel prints).

    Args:
        robot: A fixed-base robot the compiled engine took.
        kernels: Gives its kernels' C source (the module calls ``rd_mass``, ``rd_mass_nle``);
            asked for only for a build.

    Raises:
        CompileError: If the build fails or the module does not match the robot.
    """
    variants = simd.build_variants()
    own = "derivatives-" + robot_key(robot) + "-simd=" + " ".join(name for name, _, _ in variants)

    def source() -> str:
        derivative = build.cached_kernels(own)
        if derivative is None:
            bodies = robot_bodies(robot)
            derivative = TangentWriter(dynamics_programs(robot).tau, bodies.selection, bodies.offset, variants).source()
            build.store_kernels(own, derivative)
        runtime = build.runtime_source() + "\n" + _RUNTIME.read_text(encoding="utf-8")
        robot_kernels = kernels()  # and their SIMD variants: the forward dynamics' part of a block
        return robot_kernels + "\n" + simd.vector_source(robot_kernels, variants) + derivative + "\n" + runtime

    module = build.keyed_extension(own, source, init="rdd_module", label=robot.name)
    if module.info()["nv"] != robot.nv:
        raise CompileError(robot.name, "the cached derivative kernels do not match the robot; clear the cache folder")
    return module


def checked(function, robot: Robot, threads: int, kind: str, **named: object) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The checked path of a derivative call: validate, convert, compute again, refuse what
    is not finite (the errors of :class:`robodyn.compiled.CompiledRobot`'s methods).

    Args:
        function: The module's ``tau_derivatives`` or ``fd_derivatives``.
        robot: The robot (its input checks).
        threads: Native threads for a batch.
        kind: ``"tau"`` or ``"fd"``.
        named: The state arguments by name (``q``, ``v``, and ``a`` or ``tau``).
    """
    arrays, _ = robot.validate(**named)
    arrays = [np.ascontiguousarray(array, dtype=np.float64) for array in arrays]
    result = function(*arrays, threads)
    if result.__class__ is tuple:
        return cast(tuple[np.ndarray, np.ndarray, np.ndarray], result)
    if result == 3 or kind == "fd":
        raise SingularMassMatrixError(robot.name, robot.massless_joints)
    if result is None or result == 1:  # cannot happen after validate(): refuse rather than guess
        raise CompileError(robot.name, f"the compiled {kind} derivatives refused checked inputs (status {result})")
    raise NonFiniteResultError(robot.name, "the derivatives of tau")
