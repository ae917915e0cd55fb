"""The reference in symbols: the Lagrangian derivation in closed form, with sympy.

:func:`lagrangian_dynamics` is the lecture's method applied to any kinetic energy ``T``
and potential energy ``U`` given as expressions in ``q`` and ``q̇``:

    M = ∂²T/∂q̇²,    G = ∂U/∂q,    C_ij = Σ_k Γ_ijk q̇_k,
    Γ_ijk = ½ (∂M_ij/∂q_k + ∂M_ik/∂q_j − ∂M_jk/∂q_i),

so that ``d/dt ∂L/∂q̇ − ∂L/∂q = M q̈ + C q̇ + G`` with ``L = T − U``.

:func:`derive` builds ``T`` and ``U`` of a URDF robot from the reference's kinematic tree
(every body's centre of mass and rotation as functions of ``q``) and hands them to
:func:`lagrangian_dynamics`. Rotation-matrix and axis entries within ``snap`` of 0, ±1,
±½, ±√2/2 or ±√3/2 (such as ``cos(1.5707963)``) are made exact, so that right-angle frames
print as the textbook would print them; lengths, masses and inertias are kept as given.

Meant for small chains (up to three or four joints fully simplified). No Pinocchio here.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
import sympy as sp

from robodyn.reference.numeric import ReferenceRobot

#: Exact values URDF constants are snapped to when within ``snap`` of one.
_EXACT = [sp.Integer(0), sp.Integer(1), sp.Rational(1, 2), sp.sqrt(2) / 2, sp.sqrt(3) / 2]


@dataclass(frozen=True)
class SymbolicDynamics:
    """Closed-form equations of motion ``tau = M(q) q̈ + C(q, q̇) q̇ + G(q)``.

    Attributes:
        q: Joint position symbols, in the order of the equations.
        qd: Joint velocity symbols.
        qdd: Joint acceleration symbols.
        T: Kinetic energy.
        U: Potential energy.
        M: Mass matrix (n × n).
        C: Coriolis matrix from the Christoffel symbols of ``M`` (n × n).
        G: Gravity vector (n × 1).
        parameters: Symbols kept for physical parameters, with their values.
    """

    q: list[sp.Symbol]
    qd: list[sp.Symbol]
    qdd: list[sp.Symbol]
    T: sp.Expr
    U: sp.Expr
    M: sp.Matrix
    C: sp.Matrix
    G: sp.Matrix
    parameters: dict = field(default_factory=dict)

    @property
    def tau(self) -> sp.Matrix:
        """``M q̈ + C q̇ + G``."""
        return self.M * sp.Matrix(self.qdd) + self.C * sp.Matrix(self.qd) + self.G

    def euler_lagrange(self) -> sp.Matrix:
        """``d/dt ∂L/∂q̇ − ∂L/∂q`` computed directly from ``L = T − U`` (a cross-check)."""
        lagrangian = self.T - self.U
        t = sp.Symbol("t")
        path = {q: sp.Function(f"path_{q}")(t) for q in self.q}
        speeds = {qd: sp.diff(path[q], t) for q, qd in zip(self.q, self.qd, strict=True)}
        back = {sp.diff(path[q], t, 2): qdd for q, qdd in zip(self.q, self.qdd, strict=True)}
        back.update({sp.diff(path[q], t): qd for q, qd in zip(self.q, self.qd, strict=True)})
        back.update({path[q]: q for q in self.q})
        rows = []
        for q, qd in zip(self.q, self.qd, strict=True):
            momentum = sp.diff(lagrangian, qd).subs(speeds).subs(path)
            rows.append(sp.diff(momentum, t).subs(back) - sp.diff(lagrangian, q))
        return sp.Matrix(rows)


def lagrangian_dynamics(
    T: sp.Expr, U: sp.Expr, q: list[sp.Symbol], qd: list[sp.Symbol], qdd: list[sp.Symbol], *, simplify: bool = True
) -> SymbolicDynamics:
    """Equations of motion from the energies (see the module docstring).

    Args:
        T: Kinetic energy, quadratic in ``qd``.
        U: Potential energy, a function of ``q``.
        q, qd, qdd: Position, velocity and acceleration symbols.
        simplify: Trigonometric simplification of every entry (small systems only).
    """
    tidy = (lambda e: sp.trigsimp(sp.expand(e))) if simplify else (lambda e: e)
    n = len(q)
    M = sp.Matrix(n, n, lambda i, j: tidy(sp.diff(T, qd[i], qd[j])))
    G = sp.Matrix(n, 1, lambda i, _: tidy(sp.diff(U, q[i])))

    def christoffel(i: int, j: int, k: int) -> sp.Expr:
        return (sp.diff(M[i, j], q[k]) + sp.diff(M[i, k], q[j]) - sp.diff(M[j, k], q[i])) / 2

    C = sp.Matrix(n, n, lambda i, j: tidy(sum(christoffel(i, j, k) * qd[k] for k in range(n))))
    return SymbolicDynamics(list(q), list(qd), list(qdd), T, U, M, C, G)


def _exact(value: float, snap: float) -> sp.Expr:
    for exact in _EXACT:
        for signed in (exact, -exact):
            if abs(value - float(signed)) <= snap:
                return signed
    return sp.Float(value, 17)


def exact_matrix(values: np.ndarray, snap: float) -> sp.Matrix:
    """A sympy matrix of numbers, each snapped to an exact value within ``snap``."""
    values = np.atleast_2d(values)
    return sp.Matrix(values.shape[0], values.shape[1], lambda i, j: _exact(float(values[i, j]), snap))


def joint_symbols(names: list[str]) -> tuple[list[sp.Symbol], list[sp.Symbol], list[sp.Symbol]]:
    """Position, velocity and acceleration symbols named after the joints.

    A joint ``joint1`` gives ``q_joint1``, ``qd_joint1`` and ``qdd_joint1``.
    """
    clean = [name.replace(" ", "_").replace("-", "_").replace(".", "_") for name in names]
    return (
        [sp.Symbol(f"q_{name}", real=True) for name in clean],
        [sp.Symbol(f"qd_{name}", real=True) for name in clean],
        [sp.Symbol(f"qdd_{name}", real=True) for name in clean],
    )


def _parameter(values: np.ndarray, names: list[str], keep: dict | None) -> sp.Matrix:
    """Exact constants, or (when ``keep`` is a dict) symbols for the non-zero ones."""
    flat = np.ravel(values)
    entries = []
    for value, name in zip(flat, names, strict=True):
        if keep is None or value == 0:
            entries.append(_exact(float(value), 0.0))
        else:
            symbol = sp.Symbol(name, real=True)
            keep[symbol] = float(value)
            entries.append(symbol)
    return sp.Matrix(np.shape(values)[0], 1 if np.ndim(values) == 1 else np.shape(values)[1], entries)


def derive(robot: ReferenceRobot, *, simplify: bool = True, snap: float = 1e-8, keep_params: bool = False) -> SymbolicDynamics:
    """Closed-form dynamics of a reference robot, by the Lagrangian of its bodies.

    Args:
        robot: From :func:`robodyn.reference.load`.
        simplify: Trigonometric simplification (small chains only).
        snap: Tolerance for making URDF constants exact (0 to keep every float as is).
        keep_params: Keep masses (``m_<link>``), centres of mass (``c_<link>_x``...),
            inertias (``I_<link>_xx``...), joint offsets (``d_<joint>_x``...) and gravity
            ``g`` as symbols; their values are in ``SymbolicDynamics.parameters``.

    Returns:
        The equations, in the order of ``robot.joint_names``.
    """
    tree = robot.tree
    keep: dict | None = {} if keep_params else None
    q, qd, qdd = joint_symbols(robot.joint_names)
    selection = exact_matrix(tree.selection, 0.0)
    theta = selection * sp.Matrix(q) + exact_matrix(tree.offset[:, None], 0.0)
    theta_dot = selection * sp.Matrix(qd)
    gravity = exact_matrix(robot.gravity_vector[:, None], 0.0)
    if keep is not None:
        magnitude = float(np.linalg.norm(robot.gravity_vector))
        g = sp.Symbol("g", positive=True)
        keep[g] = magnitude
        gravity = exact_matrix(robot.gravity_vector[:, None] / magnitude, snap) * g if magnitude > 0 else gravity
    rotations: list[sp.Matrix] = []
    positions: list[sp.Matrix] = []
    axes: list[sp.Matrix] = []
    origins: list[sp.Matrix] = []
    T = sp.Integer(0)
    U = sp.Integer(0)
    for index, body in enumerate(tree.bodies):
        parent_rotation = sp.eye(3) if body.parent < 0 else rotations[body.parent]
        parent_position = sp.zeros(3, 1) if body.parent < 0 else positions[body.parent]
        joint_rotation = parent_rotation * exact_matrix(body.origin[:3, :3], snap)
        offset = _parameter(body.origin[:3, 3], [f"d_{body.joint}_{a}" for a in "xyz"], keep)
        origin = parent_position + parent_rotation * offset
        axis = exact_matrix(body.axis[:, None], snap)
        world_axis = joint_rotation * axis
        angle = theta[index]
        if body.revolute:
            skew = sp.Matrix([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
            rotation = joint_rotation * (sp.eye(3) + sp.sin(angle) * skew + (1 - sp.cos(angle)) * skew * skew)
            position = origin
        else:
            rotation = joint_rotation
            position = origin + world_axis * angle
        rotations.append(rotation)
        positions.append(position)
        axes.append(world_axis)
        origins.append(origin)
        if body.mass == 0 and not body.inertia.any():
            continue
        com = position + rotation * _parameter(body.com, [f"c_{body.link}_{a}" for a in "xyz"], keep)
        velocity = com.jacobian(q) * sp.Matrix(qd)
        omega = sp.zeros(3, 1)
        for ancestor in range(index + 1):
            if tree.ancestors[index, ancestor] and tree.bodies[ancestor].revolute:
                omega += axes[ancestor] * theta_dot[ancestor]
        names = [f"I_{body.link}_{a}{b}" for a in "xyz" for b in "xyz"]
        names = [name if name[-2] <= name[-1] else name[:-2] + name[-1] + name[-2] for name in names]  # I_yx -> I_xy
        inertia = rotation * _parameter(body.inertia, names, keep).reshape(3, 3) * rotation.T
        mass = _parameter(np.array([body.mass]), [f"m_{body.link}"], keep)[0]
        T += mass * (velocity.T * velocity)[0] / 2 + (omega.T * inertia * omega)[0] / 2
        U += -mass * (gravity.T * com)[0]
    dynamics = lagrangian_dynamics(T, U, q, qd, qdd, simplify=simplify)
    return replace(dynamics, parameters=keep or {})
