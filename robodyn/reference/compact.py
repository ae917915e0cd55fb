"""Compact closed-form dynamics for real arms: the Lagrangian in intermediate variables.

Fully expanded closed forms explode beyond three or four joints (ur5's ``M(q)`` alone
grows past a million operations). This module derives the same Lagrangian equations
as a short program of named assignments, the way SYMORO prints customised models:

- per-joint exact transforms: rotation entries within ``snap`` of 0, ±1, ±½, ±√2/2,
  ±√3/2 are exact, and an axis along ±x, ±y, ±z gives a rotation with only ``c``, ``s``;
- every body's rotation ``R_b``, joint axis ``z_b``, joint origin ``o_b``, centre of mass
  ``p_b``, angular velocity ``ω_b`` and velocity-product accelerations are one variable
  each, built recursively from the parent's (a variable is made only for a non-trivial
  expression; zeros and ones stay exact);
- the Lagrangian per body gives (``J`` the body's Jacobians, ``J̇ q̇`` its
  velocity-product accelerations)

      M = Σ_b m_b J_vᵀ J_v + J_ωᵀ I_b J_ω
      C q̇ = Σ_b J_vᵀ m_b (J̇_v q̇) + J_ωᵀ (I_b (J̇_ω q̇) + ω_b × I_b ω_b)
      G = −Σ_b J_vᵀ m_b g

  (``d/dt ∂T/∂q̇ − ∂T/∂q`` of ``T = Σ ½ m_b |J_v q̇|² + ½ ω_bᵀ I_b ω_b``, summed body by
  body), with ``I_b`` the world-frame inertia about the centre of mass. The sums over
  bodies are grouped by subtree (a joint's Jacobian column is the same for every body
  beyond it), so each joint needs only its subtree's composite mass, first moment and
  inertia about the world origin, and its rate of change of momentum;
- ``sympy.cse`` then shares what is still repeated.

No Pinocchio here.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import sympy as sp

from robodyn.reference.numeric import ReferenceRobot
from robodyn.reference.symbolic import _exact, joint_symbols


@dataclass
class CompactDynamics:
    """``tau = M q̈ + C q̇ + G`` as assignments followed by output expressions.

    Attributes:
        q, qd, qdd: Joint symbols (order of the reference's ``joint_names``).
        assignments: ``(symbol, expression)`` pairs, in evaluation order.
        M: Mass matrix entries in terms of the assigned symbols.
        Cv: ``C(q, q̇) q̇`` entries.
        G: Gravity entries.
    """

    q: list[sp.Symbol]
    qd: list[sp.Symbol]
    qdd: list[sp.Symbol]
    assignments: list[tuple[sp.Symbol, sp.Expr]] = field(default_factory=list)
    M: sp.Matrix | None = None
    Cv: sp.Matrix | None = None
    G: sp.Matrix | None = None

    def operation_count(self) -> int:
        """``sympy.count_ops`` over every assignment and output entry."""
        return int(sum(sp.count_ops(e) for _, e in self.assignments) + sum(sp.count_ops(e) for e in (*self.M, *self.Cv, *self.G)))


class _Program:
    """Collects assignments; a variable is made only for a non-trivial expression."""

    def __init__(self) -> None:
        self.assignments: list[tuple[sp.Symbol, sp.Expr]] = []
        self._counter = 0

    def let(self, expr: sp.Expr, prefix: str = "x") -> sp.Expr:
        expr = sp.expand(expr)
        if (
            expr.is_Number
            or expr.is_Symbol
            or (expr.is_Mul and len(expr.args) == 2 and expr.args[0].is_Number and expr.args[1].is_Symbol)
        ):
            return expr
        self._counter += 1
        symbol = sp.Symbol(f"{prefix}{self._counter}", real=True)
        self.assignments.append((symbol, expr))
        return symbol

    def vector(self, values, prefix: str) -> sp.Matrix:
        return sp.Matrix([self.let(v, prefix) for v in values])

    def matrix(self, matrix: sp.Matrix, prefix: str) -> sp.Matrix:
        return sp.Matrix(matrix.rows, matrix.cols, lambda i, j: self.let(matrix[i, j], prefix))


def _exact_matrix(values: np.ndarray, snap: float) -> sp.Matrix:
    values = np.atleast_2d(values)
    return sp.Matrix(values.shape[0], values.shape[1], lambda i, j: _exact(float(values[i, j]), snap))


def _constant(values: np.ndarray) -> sp.Matrix:
    values = np.atleast_2d(values)
    return sp.Matrix(values.shape[0], values.shape[1], lambda i, j: _exact(float(values[i, j]), 0.0))


def _rotation(axis: sp.Matrix, c: sp.Expr, s: sp.Expr) -> sp.Matrix:
    x, y, z = axis
    skew = sp.Matrix([[0, -z, y], [z, 0, -x], [-y, x, 0]])
    return sp.eye(3) + s * skew + (1 - c) * skew * skew


def derive_compact(
    robot: ReferenceRobot, *, snap: float = 1e-8, cse: bool = True, progress: Callable[[str, int, int], None] | None = None
) -> CompactDynamics:
    """Derive the compact (intermediate-variable) equations of a reference robot.

    Args:
        robot: From :func:`robodyn.reference.load` (mimic joints are not supported here).
        snap: Tolerance for exact rotation and axis entries.
        cse: Share repeated subexpressions with ``sympy.cse`` at the end.
        progress: Called as ``progress(stage, done, total)``.
    """
    tree = robot.tree
    if not np.array_equal(tree.selection, np.eye(len(tree.bodies))):
        raise NotImplementedError("compact equations do not support mimic joints; lock them (--lock)")
    q, qd, qdd = joint_symbols(robot.joint_names)
    program = _Program()
    gravity = _constant(robot.gravity_vector[:, None])
    bodies = tree.bodies
    count = len(bodies)
    R, z, o, p, com, w, dw, acc_p, acc_com, inertia = ([None] * count for _ in range(10))
    zero = sp.zeros(3, 1)
    for b, body in enumerate(bodies):
        if progress:
            progress("kinematics", b, count)
        parent = body.parent
        R_par = sp.eye(3) if parent < 0 else R[parent]
        p_par = zero if parent < 0 else p[parent]
        w_par = zero if parent < 0 else w[parent]
        dw_par = zero if parent < 0 else dw[parent]
        a_par = zero if parent < 0 else acc_p[parent]
        R_joint = program.matrix(R_par * _exact_matrix(body.origin[:3, :3], snap), f"R{b + 1}_")
        o[b] = program.vector(p_par + R_par * _constant(body.origin[:3, 3:]), f"o{b + 1}_")
        axis = _exact_matrix(body.axis[:, None], snap)
        z[b] = program.vector(R_joint * axis, f"z{b + 1}_")
        if body.revolute:
            c = program.let(sp.cos(q[b]), f"c{b + 1}_")
            s = program.let(sp.sin(q[b]), f"s{b + 1}_")
            R[b] = program.matrix(R_joint * _rotation(axis, c, s), f"R{b + 1}_")
            p[b] = o[b]
            w[b] = program.vector(w_par + z[b] * qd[b], f"w{b + 1}_")
            dw[b] = program.vector(dw_par + w_par.cross(z[b] * qd[b]), f"dw{b + 1}_")
        else:
            R[b] = R_joint
            p[b] = program.vector(o[b] + z[b] * q[b], f"p{b + 1}_")
            w[b], dw[b] = w_par, dw_par
        # Velocity-product acceleration of the body frame's origin, then of the centre of mass.
        r = p[b] - p_par
        bias = a_par + dw_par.cross(r) + w_par.cross(w_par.cross(r))
        if not body.revolute:
            bias += 2 * w_par.cross(z[b] * qd[b])
        acc_p[b] = program.vector(bias, f"ap{b + 1}_")
        com[b] = program.vector(p[b] + R[b] * _constant(body.com[:, None]), f"pc{b + 1}_")
        rc = com[b] - p[b]
        acc_com[b] = program.vector(acc_p[b] + dw[b].cross(rc) + w[b].cross(w[b].cross(rc)), f"ac{b + 1}_")
        inertia[b] = program.matrix(R[b] * _constant(body.inertia) * R[b].T, f"I{b + 1}_")

    # Composite bodies, about the world origin: mass, first moment, rotational inertia,
    # and the rate of change of momentum (force, moment about the origin) of each subtree.
    composite_mass = [sp.Integer(0)] * count
    first_moment = [zero] * count
    composite_inertia = [sp.zeros(3, 3)] * count
    force = [zero] * count
    moment = [zero] * count
    for b in reversed(range(count)):
        body = bodies[b]
        if progress:
            progress("Lagrangian", count - b, count)
        if body.mass != 0 or body.inertia.any():
            mass = _exact(body.mass, 0.0)
            c = com[b]
            offset = (c.T * c)[0] * sp.eye(3) - c * c.T
            composite_mass[b] = composite_mass[b] + mass
            first_moment[b] = first_moment[b] + program.vector(mass * c, f"h{b + 1}_")
            composite_inertia[b] = composite_inertia[b] + program.matrix(inertia[b] + mass * offset, f"IO{b + 1}_")
            f_b = program.vector(mass * acc_com[b], f"f{b + 1}_")
            n_b = inertia[b] * dw[b] + w[b].cross(inertia[b] * w[b])
            force[b] = force[b] + f_b
            moment[b] = moment[b] + program.vector(n_b + c.cross(f_b), f"n{b + 1}_")
        first_moment[b] = program.vector(first_moment[b], f"hc{b + 1}_")
        composite_inertia[b] = program.matrix(composite_inertia[b], f"IC{b + 1}_")
        force[b] = program.vector(force[b], f"fc{b + 1}_")
        moment[b] = program.vector(moment[b], f"nc{b + 1}_")
        if body.parent >= 0:
            parent = body.parent
            composite_mass[parent] = composite_mass[parent] + composite_mass[b]
            first_moment[parent] = first_moment[parent] + first_moment[b]
            composite_inertia[parent] = composite_inertia[parent] + composite_inertia[b]
            force[parent] = force[parent] + force[b]
            moment[parent] = moment[parent] + moment[b]

    # Joint axes as spatial motions at the world origin: (angular, linear) velocity.
    axes_angular = [z[i] if bodies[i].revolute else zero for i in range(count)]
    axes_linear = [program.vector(o[i].cross(z[i]), f"v{i + 1}_") if bodies[i].revolute else z[i] for i in range(count)]
    M = sp.zeros(count, count)
    Cv = sp.zeros(count, 1)
    G = sp.zeros(count, 1)
    for i in range(count):
        omega, velocity = axes_angular[i], axes_linear[i]
        # M's column i: the spatial force of composite body i moving along joint i's axis.
        n_i = program.vector(composite_inertia[i] * omega + first_moment[i].cross(velocity), f"Mn{i + 1}_")
        f_i = program.vector(composite_mass[i] * velocity - first_moment[i].cross(omega), f"Mf{i + 1}_")
        for j in range(count):
            if tree.ancestors[i, j]:
                M[i, j] = M[j, i] = (axes_angular[j].T * n_i)[0] + (axes_linear[j].T * f_i)[0]
        Cv[i] = (omega.T * moment[i])[0] + (velocity.T * force[i])[0]
        weight_moment = first_moment[i].cross(gravity)
        G[i] = -((omega.T * weight_moment)[0] + (velocity.T * (composite_mass[i] * gravity))[0])
    equations = CompactDynamics(
        q, qd, qdd, program.assignments, M.applyfunc(sp.expand), Cv.applyfunc(sp.expand), G.applyfunc(sp.expand)
    )
    if cse:
        if progress:
            progress("common subexpressions", 0, 1)
        equations = _shared(equations)
    return equations


def _shared(equations: CompactDynamics) -> CompactDynamics:
    """Share repeated subexpressions (``sympy.cse``) and keep only what the outputs need,
    in dependency order."""
    names = [name for name, _ in equations.assignments]
    outputs = [*equations.M, *equations.Cv, *equations.G]
    extra, reduced = sp.cse(
        [expr for _, expr in equations.assignments] + outputs, symbols=sp.numbered_symbols("t", real=True), order="none"
    )
    definitions = dict(extra)
    definitions.update(zip(names, reduced[: len(names)], strict=True))
    outputs = reduced[len(names) :]
    n = len(equations.q)
    M = sp.Matrix(n, n, outputs[: n * n])
    Cv = sp.Matrix(outputs[n * n : n * n + n])
    G = sp.Matrix(outputs[n * n + n :])
    return CompactDynamics(equations.q, equations.qd, equations.qdd, _in_order(definitions, outputs), M, Cv, G)


def _in_order(definitions: dict[sp.Symbol, sp.Expr], outputs: list[sp.Expr]) -> list[tuple[sp.Symbol, sp.Expr]]:
    """The definitions the outputs depend on, each after everything it uses."""
    ordered: list[tuple[sp.Symbol, sp.Expr]] = []
    state: dict[sp.Symbol, int] = {}  # 1: in progress, 2: done
    roots = sorted({s for e in outputs for s in e.free_symbols if s in definitions}, key=str)
    for root in roots:
        stack = [(root, False)]
        while stack:
            symbol, expanded = stack.pop()
            if state.get(symbol) == 2:
                continue
            if expanded:
                state[symbol] = 2
                ordered.append((symbol, definitions[symbol]))
                continue
            state[symbol] = 1
            stack.append((symbol, True))
            for dependency in definitions[symbol].free_symbols:
                if dependency in definitions and state.get(dependency) != 2:
                    stack.append((dependency, False))
    return ordered
