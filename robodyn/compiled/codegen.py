"""C kernels of one robot's dynamics, generated from the compact (intermediate-variable) equations.

The compact program (:func:`robodyn.equations.compact.derive_compact`) gives ``M``, ``C v``
and ``G`` of the reference's bodies (mimic joints as bodies of their own) as sympy
assignments. This module writes them as C99 functions of plain arrays, in the order of
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

from collections.abc import Iterable

import numpy as np
import sympy as sp

from robodyn.compiled.rnea import NewtonEuler
from robodyn.equations.compact import CompactDynamics

#: Bumped whenever the generated code changes meaning (part of every cache key).
CODEGEN_VERSION = "2"


def _number(value: float) -> str:
    """A double literal that reads back to exactly ``value``."""
    return repr(float(value))


def _needed(assignments: list[tuple[sp.Symbol, sp.Expr]], outputs: Iterable[sp.Expr]) -> list[tuple[sp.Symbol, sp.Expr]]:
    """The assignments the outputs depend on, in their original order."""
    wanted = set().union(*(expr.free_symbols for expr in outputs))
    kept = []
    for symbol, expr in reversed(assignments):
        if symbol in wanted:
            kept.append((symbol, expr))
            wanted |= expr.free_symbols
    return kept[::-1]


class KernelWriter:
    """Writes the C kernels of a compact program for a robot's coordinates.

    Args:
        equations: The compact program over the bodies' coordinates (one per body).
        selection: ``S``, shape (n_bodies, nv): body coordinate ``b`` is
            ``selection[b] @ q + offset[b]``.
        offset: Shape (n_bodies,).
        parents: For each of the robot's coordinates, the coordinate of its parent joint
            (-1 for a root), shape (nv,); a parent precedes its children.
        newton_euler: ``tau`` as a Newton–Euler program over the same bodies (O(n));
            without it ``tau = M a + C v + G``.
    """

    def __init__(
        self,
        equations: CompactDynamics,
        selection: np.ndarray,
        offset: np.ndarray,
        parents: list[int],
        newton_euler: NewtonEuler | None = None,
    ):
        self.equations = equations
        self.newton_euler = newton_euler
        self.selection = np.asarray(selection, float)
        self.offset = np.asarray(offset, float)
        self.parents = list(parents)
        self.bodies, self.nv = self.selection.shape
        # Local names: assignments t0, t1, ...; body coordinates th0, thd0, ... .
        self._names: dict[sp.Symbol, sp.Symbol] = {}
        self._printed: dict[sp.Symbol, str] = {}
        for index, (symbol, _) in enumerate(equations.assignments):
            self._names[symbol] = sp.Symbol(f"t{index}", real=True)
        for b in range(self.bodies):
            self._names[equations.q[b]] = sp.Symbol(f"th{b}", real=True)
            self._names[equations.qd[b]] = sp.Symbol(f"thd{b}", real=True)
        if newton_euler is not None:
            for b in range(self.bodies):
                self._names[newton_euler.q[b]] = sp.Symbol(f"th{b}", real=True)
                self._names[newton_euler.qd[b]] = sp.Symbol(f"thd{b}", real=True)
                self._names[newton_euler.qdd[b]] = sp.Symbol(f"thdd{b}", real=True)

    def _c(self, expr: sp.Expr) -> str:
        """C for an expression of the program (a small printer: ``sympy.ccode`` is the
        slowest step of a compile; anything unusual still goes to it)."""
        expr = sp.sympify(expr)
        if expr.is_Symbol:
            return str(self._names.get(expr, expr))
        if expr.is_Integer or expr.is_Float:
            return _number(float(expr))
        if expr.is_Rational:
            return f"({_number(expr.p)}/{_number(expr.q)})"
        if expr.is_Add:
            return "(" + " + ".join(self._c(arg) for arg in expr.args) + ")"
        if expr.is_Mul:
            return "(" + "*".join(self._c(arg) for arg in expr.args) + ")"
        if expr.is_Pow and expr.exp == 2:
            base = self._c(expr.base)
            return f"({base}*{base})"
        if expr.is_Pow and expr.exp == -1:
            return f"(1.0/{self._c(expr.base)})"
        if expr.is_Pow and expr.exp.is_Integer:
            return f"pow({self._c(expr.base)}, {int(expr.exp)})"
        if isinstance(expr, sp.cos | sp.sin) and len(expr.args) == 1:
            return f"{type(expr).__name__}({self._c(expr.args[0])})"
        return sp.ccode(expr.xreplace(self._names), standard="C99")

    def _combination(self, terms: list[tuple[float, str]]) -> str:
        """``c0*x0 + c1*x1 + ...`` with unit coefficients written as they are."""
        parts = [name if coefficient == 1.0 else f"{_number(coefficient)}*{name}" for coefficient, name in terms]
        return " + ".join(parts) if parts else "0.0"

    def _coordinates(self, symbols: set[sp.Symbol], velocity: bool) -> list[str]:
        """``th``/``thd`` declarations for the body coordinates the code uses."""
        lines = []
        for b in range(self.bodies):
            uses_q = self.equations.q[b] in symbols
            if uses_q:
                terms = [(self.selection[b, j], f"q[{j}]") for j in range(self.nv) if self.selection[b, j] != 0]
                value = self._combination(terms)
                if self.offset[b] != 0:
                    value += f" + {_number(self.offset[b])}"
                lines.append(f"    const double th{b} = {value};")
            if velocity and self.equations.qd[b] in symbols:
                terms = [(self.selection[b, j], f"v[{j}]") for j in range(self.nv) if self.selection[b, j] != 0]
                lines.append(f"    const double thd{b} = {self._combination(terms)};")
        return lines

    def _body(self, outputs: list[sp.Expr], velocity: bool) -> list[str]:
        """Coordinates and the assignments ``outputs`` need, as C declarations."""
        program = _needed(self.equations.assignments, outputs)
        used = set().union(*(expr.free_symbols for expr in outputs), *(expr.free_symbols for _, expr in program))
        lines = self._coordinates(used, velocity)
        lines += [f"    const double {self._names[symbol]} = {self._assignment(symbol, expr)};" for symbol, expr in program]
        return lines

    def _assignment(self, symbol: sp.Symbol, expr: sp.Expr) -> str:
        """An assignment's C expression (printed once, used by several kernels)."""
        if symbol not in self._printed:
            self._printed[symbol] = self._c(expr)
        return self._printed[symbol]

    def _project_vector(self, local: str, out: str) -> list[str]:
        """``out = Sᵀ local`` (``local`` a C array of body entries)."""
        lines = []
        for j in range(self.nv):
            terms = [(self.selection[b, j], f"{local}[{b}]") for b in range(self.bodies) if self.selection[b, j] != 0]
            lines.append(f"    {out}[{j}] = {self._combination(terms)};")
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
                lines.append(f"    {out}[{j * n + k}] = {self._combination(terms)};")
                if j != k:
                    lines.append(f"    {out}[{k * n + j}] = {out}[{j * n + k}];")
        return lines

    def _mass_lines(self) -> list[str]:
        nb, M = self.bodies, self.equations.M
        lines = [f"    double mb[{nb * nb}];"]
        for b in range(nb):
            for c in range(b + 1):
                lines.append(f"    mb[{b * nb + c}] = mb[{c * nb + b}] = {self._c(M[b, c])};")
        return lines

    def _tau_kernel(self) -> list[str]:
        n, nb = self.nv, self.bodies
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
        program = _needed(ne.assignments, ne.tau)
        used = set().union(*(expr.free_symbols for expr in ne.tau), *(expr.free_symbols for _, expr in program))
        lines = [head]
        for b in range(nb):
            for symbols, array, prefix, offset in (
                (ne.q, "q", "th", True),
                (ne.qd, "v", "thd", False),
                (ne.qdd, "a", "thdd", False),
            ):
                if symbols[b] not in used:
                    continue
                terms = [(self.selection[b, j], f"{array}[{j}]") for j in range(n) if self.selection[b, j] != 0]
                value = self._combination(terms)
                if offset and self.offset[b] != 0:
                    value += f" + {_number(self.offset[b])}"
                lines.append(f"    const double {prefix}{b} = {value};")
        lines += [f"    const double {symbol} = {self._c(expr)};" for symbol, expr in program]
        lines += [f"    double tb[{nb}];", *[f"    tb[{b}] = {self._c(ne.tau[b])};" for b in range(nb)]]
        return [*lines, *self._project_vector("tb", "tau"), "}", ""]

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
            f"    double gb[{nb}];",
            *[f"    gb[{b}] = {self._c(e.G[b])};" for b in range(nb)],
            *self._project_vector("gb", "g"),
            "}",
            "",
            "static void rd_nle(const double *q, const double *v, double *nle) {",
            *self._body(nle, velocity=True),
            f"    double hb[{nb}];",
            *[f"    hb[{b}] = {self._c(nle[b])};" for b in range(nb)],
            *self._project_vector("hb", "nle"),
            "}",
            "",
            "static void rd_mass(const double *q, double *M) {",
            *self._body(mass_entries, velocity=False),
            *self._mass_lines(),
            *self._project_matrix("mb", "M"),
            "}",
            "",
            "static void rd_mass_nle(const double *q, const double *v, double *M, double *nle) {",
            *self._body(mass_entries + nle, velocity=True),
            *self._mass_lines(),
            *self._project_matrix("mb", "M"),
            f"    double hb[{nb}];",
            *[f"    hb[{b}] = {self._c(nle[b])};" for b in range(nb)],
            *self._project_vector("hb", "nle"),
            "}",
            "",
        ]
        out += self._tau_kernel()
        return "\n".join(out)
