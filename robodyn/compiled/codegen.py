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

plus ``RD_NV`` and ``rd_parent`` (the tree's parent of each coordinate, for the LDLᵀ
factorisation). ``runtime.c`` supplies everything else.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import sympy as sp

from robodyn.equations.c_printer import CPrinter, c_combination, c_number
from robodyn.equations.compact import CompactDynamics
from robodyn.equations.program import Program, needed

#: Bumped whenever the generated code changes meaning (part of every cache key).
CODEGEN_VERSION = "2"

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
        # Local names: assignments t0, t1, ... (r0, r1, ... in tau); body coordinates th0, thd0, thdd0.
        self._compact = CPrinter(self._names(equations.assignments, "t", (equations.q, equations.qd)))
        if newton_euler is not None:
            inputs = newton_euler.inputs
            self._tau = CPrinter(self._names(newton_euler.assignments, "r", (inputs["q"], inputs["qd"], inputs["qdd"])))

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
                terms = [(self.selection[b, j], f"{array}[{j}]") for j in range(self.nv) if self.selection[b, j] != 0]
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
            lines.append(f"    {out}[{j}] = {c_combination(terms)};")
        return lines

    def _project_matrix(self, local: str, out: str) -> list[str]:
        """``out = Sᵀ local S`` (symmetric: the lower triangle, mirrored)."""
        n, nb, S = self.nv, self.bodies, self.selection
        lines = []
        for j in range(n):
            for k in range(j + 1):
                terms = [
                    (S[b, j] * S[c, k], f"{local}[{b * nb + c}]")
                    for b in range(nb)
                    for c in range(nb)
                    if S[b, j] != 0 and S[c, k] != 0
                ]
                lines.append(f"    {out}[{j * n + k}] = {c_combination(terms)};")
                if j != k:
                    lines.append(f"    {out}[{k * n + j}] = {out}[{j * n + k}];")
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
        return lines + self._project_matrix("mb", "M")

    def _tau_kernel(self) -> list[str]:
        n = self.nv
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
        lines = [head, *self._program(self._tau, ne.assignments, tau, coordinates)]
        return [*lines, *self._vector_lines(self._tau, "tb", "tau", tau), "}", ""]

    def source(self) -> str:
        """The kernels' C source (no includes; ``runtime.c`` is appended after it)."""
        e, nb, n = self.equations, self.bodies, self.nv
        mass_entries = [e.M[b, c] for b in range(nb) for c in range(b + 1)]
        nle = [e.Cv[b] + e.G[b] for b in range(nb)]
        out = [
            "/* Generated by robodyn.compiled (codegen version " + CODEGEN_VERSION + "). */",
            f"#define RD_NV {n}",
            f"static const int rd_parent[RD_NV] = {{{', '.join(str(p) for p in self.parents)}}};",
            "",
            "static void rd_gravity(const double *q, double *g) {",
            *self._body(list(e.G), velocity=False),
            *self._vector_lines(self._compact, "gb", "g", list(e.G)),
            "}",
            "",
            "static void rd_nle(const double *q, const double *v, double *nle) {",
            *self._body(nle, velocity=True),
            *self._vector_lines(self._compact, "hb", "nle", nle),
            "}",
            "",
            "static void rd_mass(const double *q, double *M) {",
            *self._body(mass_entries, velocity=False),
            *self._mass_lines(),
            "}",
            "",
            "static void rd_mass_nle(const double *q, const double *v, double *M, double *nle) {",
            *self._body(mass_entries + nle, velocity=True),
            *self._mass_lines(),
            *self._vector_lines(self._compact, "hb", "nle", nle),
            "}",
            "",
        ]
        return "\n".join(out + self._tau_kernel())
