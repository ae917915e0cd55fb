"""C kernels of one robot's dynamics, generated from the equations layer's programs.

The compact program (:func:`robodyn.equations.compact.derive_compact`) gives ``M``, ``C v``
and ``G`` of the reference's bodies (mimic joints as bodies of their own), the Newton–Euler
program (:func:`robodyn.equations.newton_euler.derive_newton_euler`) gives ``tau`` in O(n),
both as sympy assignments. This module writes them as C99 functions of plain arrays (through
the one C printer, :mod:`robodyn.equations.c_printer`), in the order of
:attr:`robodyn.Robot.joint_names`:

- the body coordinates are the robot's linear map ``theta = Q q + offset``, ``thetȧ = S v``
  (``S`` a permutation when there are no mimic joints), and the outputs are projected
  back: ``tau = Sᵀ tau_bodies``, ``M = Sᵀ M_bodies S``;
- each kernel keeps only the assignments its outputs need (a ``G`` kernel computes no
  velocities), so no work depends on the C compiler's dead-code elimination;
- inputs and outputs are array entries (``q[3]``, ``M[12]``): no name from the URDF
  appears in the generated code, not even in comments.

The kernels, each for one state (arrays of doubles, ``M`` row-major)::

    static void rd_tau(const double *q, const double *v, const double *a, double *tau);
    static void rd_mass(const double *q, double *M);
    static void rd_nle(const double *q, const double *v, double *nle);   /* C v + G */
    static void rd_gravity(const double *q, double *g);
    static void rd_mass_nle(const double *q, const double *v, double *M, double *nle);

plus ``RD_NV``, ``RD_NQ`` and ``rd_parent`` (the tree's parent of each coordinate, for the
LDLᵀ factorisation). ``runtime.c`` supplies everything else.

``sin`` and ``cos`` in the kernels are robodyn's own (``trig.c``: branch-free arithmetic
written once as the macro ``RD_TRIG_DEFINE``, within 1 ulp; libm's beyond
``|x| > 2^20``), placed before the kernels as ``rd_sin``/``rd_cos`` on doubles; the SIMD
batches (:mod:`robodyn.compiled.simd`) instantiate the same macro on vectors of states, so
a batch row is bit for bit a single call, and no batch calls libm lane by lane.

A floating base (the compact program's ``base``, Pinocchio's free flyer) takes ``q[0:7]``
(position, quaternion x, y, z, w), ``v[0:6]`` and ``a[0:6]`` (linear then angular, base
frame) before the joints: its rows of ``tau``, ``M``, ``C v`` and ``G`` come first, the joints'
follow (``RD_NQ = RD_NV + 1``); the position never enters the dynamics.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import sympy as sp

from robodyn.dynamics.handle import QUATERNION_TOLERANCE
from robodyn.equations.c_printer import CPrinter, c_combination, c_number
from robodyn.equations.compact import CompactDynamics
from robodyn.equations.program import Program, needed

#: Above this many assignments ``rd_mass_nle`` calls ``rd_mass`` and ``rd_nle`` instead of
#: repeating both programs: the C compiler's register allocation grows faster than linearly
#: with a function's length (fixed-base talos: compiler CPU 6.8 -> 3.7 s; a 30-joint chain
#: 68 -> 34 s). ur5 (270) and the panda arm (425) stay below it.
SPLIT_ASSIGNMENTS = 1000

#: The generic sin and cos (C, the macro ``RD_TRIG_DEFINE``); its source is part of every cache key, as all of the generator's (:mod:`robodyn.compiled.cache`).
TRIG = Path(__file__).with_name("trig.c")
#: Its instantiation on doubles (``rd_sin``, ``rd_cos``, ``rd_sincos``) with the helpers it needs.
_SCALAR_TRIG = """typedef unsigned long long rd_u64;
static inline __attribute__((always_inline)) rd_u64 rd_bits(double x) { union { double d; rd_u64 u; } b = {x}; return b.u; }
static inline __attribute__((always_inline)) double rd_double(rd_u64 u) { union { rd_u64 u; double d; } b = {u}; return b.d; }
static inline __attribute__((always_inline)) rd_u64 rd_mask(int c) { return -(rd_u64)c; }
static inline __attribute__((always_inline)) void rd_libm(double x, rd_u64 m, double *s, double *c) {
    if (m) { *s = sin(x); *c = cos(x); }
}
RD_TRIG_DEFINE(rd_, double, rd_u64, )
"""


def trig_source(generic: str | None = None) -> str:
    """The generic sin and cos (``generic``, default :data:`TRIG`'s text) and their
    instantiation on doubles: C, before the kernels.

    Args:
        generic: The generic sin and cos as C source; ``None``: :data:`TRIG`'s file.
    """
    return (TRIG.read_text(encoding="utf-8") if generic is None else generic) + _SCALAR_TRIG


#: The body coordinates' C names, and the robot's arrays they are made of.
_COORDINATES = (("th", "q", True), ("thd", "v", False), ("thdd", "a", False))


class KernelWriter:
    """Writes the C kernels of a compact program for a robot's coordinates.

    Args:
        equations: The compact program over the bodies' coordinates (one per body).
        selection: ``S``, shape (n_bodies, nv): body coordinate ``b`` is
            ``selection[b] @ q + offset[b]``.
        offset: Shape (n_bodies,).
        parents: For each of the robot's coordinates, the coordinate of its parent joint
            (-1 for a root), shape (nv,); a parent precedes its children.
        newton_euler: ``tau`` as a Newton–Euler program over the same bodies (O(n), inputs
            ``q``, ``qd``, ``qdd``, output ``tau``); without it ``tau = M a + C v + G``.
    """

    def __init__(
        self,
        equations: CompactDynamics,
        selection: np.ndarray,
        offset: np.ndarray,
        parents: list[int],
        newton_euler: Program | None = None,
    ):
        self.equations = equations
        self.newton_euler = newton_euler
        self.selection = np.asarray(selection, float)
        self.offset = np.asarray(offset, float)
        self.parents = list(parents)
        self.bodies, self.nv = self.selection.shape
        self.base = equations.base
        self._v0 = 0 if self.base is None else 6  # the joints' first entry in v (and q - 1)
        self._q0 = 0 if self.base is None else 7
        self.size = self.nv + self._v0  # RD_NV
        # Local names: assignments t0, t1, ... (r0, r1, ... in tau); body coordinates th0, thd0, thdd0.
        self._compact = CPrinter(
            self._names(equations.assignments, "t", (equations.q, equations.qd)) | self._base_names(), trig="rd_"
        )
        if newton_euler is not None:
            inputs = newton_euler.inputs
            names = self._names(newton_euler.assignments, "r", (inputs["q"], inputs["qd"], inputs["qdd"]))
            if "base_q" in inputs:
                entries = (("base_q", "q", 3), ("base_v", "v", 0), ("base_a", "a", 0))
                names |= {
                    symbol: f"{array}[{start + i}]" for key, array, start in entries for i, symbol in enumerate(inputs[key])
                }
            self._tau = CPrinter(names, trig="rd_")

    def _base_names(self) -> dict[sp.Symbol, str]:
        """The free base's inputs as array entries (``q[3]``.. the quaternion, ``v[0]``..)."""
        if self.base is None:
            return {}
        names = {symbol: f"q[{3 + i}]" for i, symbol in enumerate(self.base.quaternion)}
        return names | {symbol: f"v[{i}]" for i, symbol in enumerate(self.base.velocity)}

    @staticmethod
    def _names(
        assignments: Sequence[tuple[sp.Symbol, sp.Expr]], prefix: str, coordinates: Sequence[Sequence[sp.Symbol]]
    ) -> dict[sp.Symbol, str]:
        names = {symbol: f"{prefix}{index}" for index, (symbol, _) in enumerate(assignments)}
        for symbols, (local, _, _) in zip(coordinates, _COORDINATES, strict=False):
            names.update({symbol: f"{local}{b}" for b, symbol in enumerate(symbols)})
        return names

    def _coordinates(self, used: set[sp.Basic], coordinates: Sequence[Sequence[sp.Symbol]]) -> list[str]:
        """``th``/``thd``/``thdd`` declarations for the body coordinates the code uses."""
        lines = []
        for b in range(self.bodies):
            for symbols, (local, array, shifted) in zip(coordinates, _COORDINATES, strict=False):
                if symbols[b] not in used:
                    continue
                first = self._q0 if array == "q" else self._v0
                terms = [(self.selection[b, j], f"{array}[{first + j}]") for j in range(self.nv) if self.selection[b, j] != 0]
                value = c_combination(terms)
                if shifted and self.offset[b] != 0:
                    value += f" + {c_number(self.offset[b])}"
                lines.append(f"    const double {local}{b} = {value};")
        return lines

    def _program(
        self, printer: CPrinter, assignments, outputs: list[sp.Expr], coordinates: Sequence[Sequence[sp.Symbol]]
    ) -> list[str]:
        """Coordinates and the assignments ``outputs`` need, as C declarations."""
        program = needed(assignments, outputs)
        used = set().union(*(sp.sympify(e).free_symbols for e in outputs), *(e.free_symbols for _, e in program))
        return self._coordinates(used, coordinates) + printer.statements(program)

    def _body(self, outputs: list[sp.Expr], velocity: bool) -> list[str]:
        e = self.equations
        return self._program(self._compact, e.assignments, outputs, (e.q, e.qd) if velocity else (e.q,))

    def _project_vector(self, local: str, out: str) -> list[str]:
        """``out = Sᵀ local`` (``local`` a C array of body entries)."""
        lines = []
        for j in range(self.nv):
            terms = [(self.selection[b, j], f"{local}[{b}]") for b in range(self.bodies) if self.selection[b, j] != 0]
            lines.append(f"    {out}[{self._v0 + j}] = {c_combination(terms)};")
        return lines

    def _project_matrix(self, local: str, out: str) -> list[str]:
        """``out = Sᵀ local S`` (symmetric: the lower triangle, mirrored)."""
        n, nb, S, size, v0 = self.nv, self.bodies, self.selection, self.size, self._v0
        lines = []
        for j in range(n):
            for k in range(j + 1):
                terms = [
                    (S[b, j] * S[c, k], f"{local}[{b * nb + c}]")
                    for b in range(nb)
                    for c in range(nb)
                    if S[b, j] != 0 and S[c, k] != 0
                ]
                lines.append(f"    {out}[{(v0 + j) * size + v0 + k}] = {c_combination(terms)};")
                if j != k:
                    lines.append(f"    {out}[{(v0 + k) * size + v0 + j}] = {out}[{(v0 + j) * size + v0 + k}];")
        return lines

    def _base_vector(self, printer: CPrinter, out: str, entries: Sequence[sp.Expr]) -> list[str]:
        """The base's six rows of a vector: ``out[0..5]``."""
        return [f"    {out}[{i}] = {printer.expression(entry)};" for i, entry in enumerate(entries)]

    def _base_mass_lines(self) -> list[str]:
        """The base's rows and columns of ``M``: its 6×6 block, and ``M_base,bodies S``."""
        rows, size, nb, S = self.equations.base_rows["M"], self.size, self.bodies, self.selection
        lines = [f"    double mbb[{6 * nb}];"]
        lines += [f"    mbb[{r * nb + b}] = {self._compact.expression(rows[r, 6 + b])};" for r in range(6) for b in range(nb)]
        for r in range(6):
            for c in range(r + 1):
                lines.append(f"    M[{r * size + c}] = M[{c * size + r}] = {self._compact.expression(rows[r, c])};")
            for j in range(self.nv):
                value = c_combination([(S[b, j], f"mbb[{r * nb + b}]") for b in range(nb) if S[b, j] != 0])
                lines.append(f"    M[{r * size + 6 + j}] = M[{(6 + j) * size + r}] = {value};")
        return lines

    def _vector_lines(self, printer: CPrinter, local: str, out: str, entries: list[sp.Expr]) -> list[str]:
        """``local[b] = entry`` for every body, then ``out = Sᵀ local``."""
        lines = [f"    double {local}[{self.bodies}];"]
        lines += [f"    {local}[{b}] = {printer.expression(entry)};" for b, entry in enumerate(entries)]
        return lines + self._project_vector(local, out)

    def _mass_lines(self) -> list[str]:
        nb, M = self.bodies, self.equations.M
        lines = [f"    double mb[{nb * nb}];"]
        for b in range(nb):
            for c in range(b + 1):
                lines.append(f"    mb[{b * nb + c}] = mb[{c * nb + b}] = {self._compact.expression(M[b, c])};")
        lines += self._project_matrix("mb", "M")
        return lines if self.base is None else lines + self._base_mass_lines()

    def _base_entries(self, name: str) -> list[sp.Expr]:
        """The base's rows of ``name`` (``"M"``: every entry; none for a fixed base)."""
        return [] if self.base is None else list(self.equations.base_rows[name])

    def _with_base(self, printer: CPrinter, out: str, name: str) -> list[str]:
        """The base's six rows of ``Cv + G`` (``name="nle"``) or ``G`` into ``out``."""
        if self.base is None:
            return []
        rows = self.equations.base_rows
        entries = [rows["Cv"][i] + rows["G"][i] for i in range(6)] if name == "nle" else list(rows["G"])
        return self._base_vector(printer, out, entries)

    def _tau_kernel(self) -> list[str]:
        n = self.size
        head = "static void rd_tau(const double *q, const double *v, const double *a, double *tau) {"
        if self.newton_euler is None:
            return [
                head,
                f"    double M[{n * n}];",
                "    rd_mass_nle(q, v, M, tau);",
                f"    for (int i = 0; i < {n}; ++i)",
                f"        for (int j = 0; j < {n}; ++j) tau[i] += M[i * {n} + j] * a[j];",
                "}",
                "",
            ]
        ne = self.newton_euler
        tau = list(ne.outputs["tau"])
        coordinates = (ne.inputs["q"], ne.inputs["qd"], ne.inputs["qdd"])
        base = list(ne.outputs.get("base", ()))
        lines = [head, *self._program(self._tau, ne.assignments, tau + base, coordinates)]
        lines += self._base_vector(self._tau, "tau", base)
        return [*lines, *self._vector_lines(self._tau, "tb", "tau", tau), "}", ""]

    def _mass_nle_lines(self, mass_entries: list[sp.Expr], nle: list[sp.Expr], base_nle: list[sp.Expr]) -> list[str]:
        """``M`` and ``C v + G`` in one pass (their shared kinematics once), or, for a program
        above :data:`SPLIT_ASSIGNMENTS`, a call of each kernel: the same numbers, bit for bit."""
        if len(self.equations.assignments) > SPLIT_ASSIGNMENTS:
            return ["    rd_mass(q, M);", "    rd_nle(q, v, nle);"]
        return [
            *self._body(mass_entries + nle + base_nle, velocity=True),
            *self._mass_lines(),
            *self._with_base(self._compact, "nle", "nle"),
            *self._vector_lines(self._compact, "hb", "nle", nle),
        ]

    def _tree_tables(self) -> list[str]:
        """``rd_depth`` and ``rd_ancestor``: each coordinate's ancestors, nearest first (the
        tree LDLᵀ's walk, ``core.c``)."""
        ancestors = []
        for i in range(self.size):
            chain, j = [], self.parents[i]
            while j >= 0:
                chain.append(j)
                j = self.parents[j]
            ancestors.append(chain)
        rows = ", ".join("{" + ", ".join(str(j) for j in chain or [0]) + "}" for chain in ancestors)
        return [
            f"static const int rd_depth[RD_NV] = {{{', '.join(str(len(chain)) for chain in ancestors)}}};",
            f"static const int rd_ancestor[RD_NV][RD_NV] = {{{rows}}};",
        ]

    def source(self) -> str:
        """The kernels' C source (no includes; ``runtime.c`` is appended after it)."""
        e, nb, n = self.equations, self.bodies, self.size
        mass_entries = [e.M[b, c] for b in range(nb) for c in range(b + 1)] + self._base_entries("M")
        nle = [e.Cv[b] + e.G[b] for b in range(nb)]
        base_nle = self._base_entries("Cv") + self._base_entries("G")
        out = [
            "/* Generated by robodyn.compiled. */",
            f"#define RD_NV {n}",
            f"#define RD_NQ {n + (self.base is not None)}",
            f"#define RD_QUATERNION_TOLERANCE {c_number(QUATERNION_TOLERANCE)}",
            f"static const int rd_parent[RD_NV] = {{{', '.join(str(p) for p in self.parents)}}};",
            *self._tree_tables(),
            trig_source(),
            "static void rd_gravity(const double *q, double *g) {",
            *self._body(list(e.G) + self._base_entries("G"), velocity=False),
            *self._with_base(self._compact, "g", "G"),
            *self._vector_lines(self._compact, "gb", "g", list(e.G)),
            "}",
            "",
            "static void rd_nle(const double *q, const double *v, double *nle) {",
            *self._body(nle + base_nle, velocity=True),
            *self._with_base(self._compact, "nle", "nle"),
            *self._vector_lines(self._compact, "hb", "nle", nle),
            "}",
            "",
            "static void rd_mass(const double *q, double *M) {",
            *self._body(mass_entries, velocity=False),
            *self._mass_lines(),
            "}",
            "",
            "static void rd_mass_nle(const double *q, const double *v, double *M, double *nle) {",
            *self._mass_nle_lines(mass_entries, nle, base_nle),
            "}",
            "",
        ]
        return "\n".join(out + self._tau_kernel())
