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
        labels: ``(kind, owner, component)`` of every kept parameter (see :class:`Parameters`).
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
    labels: dict = field(default_factory=dict)

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
    tidy = (lambda e: sp.trigsimp(sp.expand(e))) if simplify else sp.expand
    n = len(q)
    quadratic = sp.expand(T)
    M = sp.Matrix(n, n, lambda i, j: tidy(sp.diff(quadratic, qd[i], qd[j])))
    G = sp.Matrix(n, 1, lambda i, _: tidy(sp.diff(U, q[i])))

    def christoffel(i: int, j: int, k: int) -> sp.Expr:
        return (sp.diff(M[i, j], q[k]) + sp.diff(M[i, k], q[j]) - sp.diff(M[j, k], q[i])) / 2

    C = sp.Matrix(n, n, lambda i, j: tidy(sum(christoffel(i, j, k) * qd[k] for k in range(n))))
    return SymbolicDynamics(list(q), list(qd), list(qdd), T, U, M, C, G)


#: Magnitudes below this (in SI units) are round-off of the URDF's preprocessing, made 0.
ROUND_OFF = 1e-15


def exact_number(value: float) -> sp.Rational:
    """A URDF number as the exact rational it was written as: ``0.41`` is ``41/100``.

    The float's shortest decimal of up to 15 significant digits (within 1e-15 of it,
    relative) is taken, so ``0.30000000000000004`` is ``3/10``; magnitudes below
    :data:`ROUND_OFF` are 0.

    Args:
        value: A finite float.
    """
    if not np.isfinite(value):
        raise ValueError(f"not a finite number: {value!r}")
    if abs(value) < ROUND_OFF:
        return sp.Integer(0)
    return sp.Rational(f"{value:.15g}")


def exact_angle(value: float) -> sp.Expr:
    """An angle in [rad], recognised as a fraction of π (``1.5707963267948966`` is ``π/2``)
    when within 1e-12 of one with a denominator up to 12, else :func:`exact_number`.

    Args:
        value: The angle in [rad].
    """
    for denominator in range(1, 13):
        numerator = round(value * denominator / np.pi)
        if numerator and abs(value - numerator * np.pi / denominator) <= 1e-12:
            return sp.pi * sp.Rational(numerator, denominator)
    return exact_number(value)


def _exact(value: float, snap: float) -> sp.Expr:
    for exact in _EXACT:
        for signed in (exact, -exact):
            if abs(value - float(signed)) <= snap:
                return signed
    return exact_number(value)


def exact_matrix(values: np.ndarray, snap: float) -> sp.Matrix:
    """A sympy matrix of numbers, each snapped to an exact value within ``snap``.

    Args:
        values: The numbers, 1-D (one row) or 2-D.
        snap: Entries within it of 0, ±½, ±√2/2, ±√3/2 or ±1 become that value (else the
            rational they were written as).
    """
    values = np.atleast_2d(values)
    return sp.Matrix(values.shape[0], values.shape[1], lambda i, j: _exact(float(values[i, j]), snap))


def joint_symbols(names: list[str]) -> tuple[list[sp.Symbol], list[sp.Symbol], list[sp.Symbol]]:
    """Position, velocity and acceleration symbols named after the joints.

    A joint ``joint1`` gives ``q_joint1``, ``qd_joint1`` and ``qdd_joint1``.

    Args:
        names: The joints' names (spaces, ``-`` and ``.`` become ``_``).
    """
    clean = [name.replace(" ", "_").replace("-", "_").replace(".", "_") for name in names]
    return (
        [sp.Symbol(f"q_{name}", real=True) for name in clean],
        [sp.Symbol(f"qd_{name}", real=True) for name in clean],
        [sp.Symbol(f"qdd_{name}", real=True) for name in clean],
    )


class Parameters:
    """Physical constants of a robot as exact numbers, or (``keep=True``) as symbols.

    A kept constant is a real symbol named ``<kind>_<owner>[_<component>]`` (``m_link1``,
    ``c_link1_x``, ``I_link1_xy``, ``d_joint2_x``, ``g``); :attr:`values` maps it to its
    number and :attr:`labels` to ``(kind, owner, component)`` for printing. Zeros stay 0.
    """

    def __init__(self, keep: bool) -> None:
        self.keep = keep
        self.values: dict[sp.Symbol, float] = {}
        self.labels: dict[sp.Symbol, tuple[str, str, str]] = {}

    def symbol(self, value: float, kind: str, owner: str = "", component: str = "") -> sp.Expr:
        """One constant (exact), or its symbol.

        Args:
            value: The constant.
            kind: What it is, the symbol's first part (e.g. ``"m"``, ``"I"``, ``"g"``).
            owner: The link or joint it belongs to.
            component: Its component (e.g. ``"x"``, ``"xy"``).
        """
        if not self.keep or value == 0:
            return exact_number(float(value))
        name = "_".join(part for part in (kind, owner, component) if part)
        symbol = sp.Symbol(name, real=True)
        self.values[symbol] = float(value)
        self.labels[symbol] = (kind, owner, component)
        return symbol

    def vector(self, values: np.ndarray, kind: str, owner: str) -> sp.Matrix:
        """A 3-vector (components ``x``, ``y``, ``z``).

        Args:
            values: Its three numbers.
            kind: What it is (see :meth:`symbol`).
            owner: The link or joint it belongs to.
        """
        return sp.Matrix([self.symbol(v, kind, owner, a) for v, a in zip(np.ravel(values), "xyz", strict=True)])

    def inertia(self, values: np.ndarray, owner: str) -> sp.Matrix:
        """A symmetric 3×3 inertia (components ``xx``, ``xy``, ...: one symbol a pair).

        Args:
            values: The 3×3 inertia in [kg m²].
            owner: The link it belongs to.
        """
        entries = {}
        for i in range(3):
            for j in range(i, 3):
                entries[i, j] = entries[j, i] = self.symbol(values[i, j], "I", owner, "xyz"[i] + "xyz"[j])
        return sp.Matrix(3, 3, lambda i, j: entries[i, j])

    def gravity(self, vector: np.ndarray) -> sp.Matrix:
        """The gravity vector: with ``keep``, ``g`` times an axis when along one, else
        one symbol ``g_x``, ``g_y``, ``g_z`` a non-zero component.

        Args:
            vector: World gravity in [m/s²], shape (3,).
        """
        nonzero = np.flatnonzero(vector)
        if self.keep and len(nonzero) == 1:
            axis = sp.zeros(3, 1)
            axis[nonzero[0]] = sp.sign(vector[nonzero[0]])
            return axis * self.symbol(abs(float(vector[nonzero[0]])), "g")
        return self.vector(vector, "g", "")


def derive(
    robot: ReferenceRobot,
    *,
    simplify: bool = True,
    snap: float = 1e-8,
    keep_params: bool = False,
    symbols: tuple[list[sp.Symbol], list[sp.Symbol], list[sp.Symbol]] | None = None,
) -> SymbolicDynamics:
    """Closed-form dynamics of a reference robot, by the Lagrangian of its bodies.

    Numbers from the URDF enter as exact rationals (:func:`exact_number`), rotation
    entries near 0, ±1, ±½, ±√2/2, ±√3/2 as those values, mimic offsets near a fraction
    of π as that fraction, so no round-off term can appear.

    Args:
        robot: From :func:`robodyn.reference.load`.
        simplify: Trigonometric simplification (small chains only).
        snap: Tolerance for exact rotation and axis entries (0 to snap only exact values).
        keep_params: Keep masses (``m_<link>``), centres of mass (``c_<link>_x``...),
            inertias (``I_<link>_xx``...), joint offsets (``d_<joint>_x``...) and gravity
            (``g``, or ``g_x``... off the axes) as symbols; their values are in
            ``SymbolicDynamics.parameters``.
        symbols: ``(q, qd, qdd)`` to use instead of :func:`joint_symbols`.

    Returns:
        The equations, in the order of ``robot.joint_names``.
    """
    tree = robot.tree
    params = Parameters(keep_params)
    q, qd, qdd = symbols or joint_symbols(robot.joint_names)
    theta, theta_dot = body_coordinates(robot, q, qd)
    gravity = params.gravity(robot.gravity_vector)
    rotations, positions, axes = body_poses(robot, theta, params, snap=snap)
    T = sp.Integer(0)
    U = sp.Integer(0)
    for index, body in enumerate(tree.bodies):
        rotation, position = rotations[index], positions[index]
        if body.mass == 0 and not body.inertia.any():
            continue
        com = position + rotation * params.vector(body.com, "c", body.link)
        velocity = com.jacobian(q) * sp.Matrix(qd)
        omega = sp.zeros(3, 1)
        for ancestor in range(index + 1):
            if tree.ancestors[index, ancestor] and tree.bodies[ancestor].revolute:
                omega += axes[ancestor] * theta_dot[ancestor]
        inertia = rotation * params.inertia(body.inertia, body.link) * rotation.T
        mass = params.symbol(body.mass, "m", body.link)
        T += mass * (velocity.T * velocity)[0] / 2 + (omega.T * inertia * omega)[0] / 2
        U += -mass * (gravity.T * com)[0]
    dynamics = lagrangian_dynamics(T, U, q, qd, qdd, simplify=simplify)
    return replace(dynamics, parameters=params.values, labels=params.labels)


def body_poses(
    robot: ReferenceRobot, theta: sp.Matrix, params: Parameters | None = None, *, snap: float = 1e-8
) -> tuple[list[sp.Matrix], list[sp.Matrix], list[sp.Matrix]]:
    """World rotation, origin and joint axis of every body frame as functions of the bodies'
    coordinates ``theta`` (forward kinematics in closed form, exact constants).

    Args:
        robot: The reference robot.
        theta: Every body's joint coordinate (:func:`body_coordinates`).
        params: Which constants stay symbols (default: none).
        snap: Rotation and axis entries within it of 0, ±½, ±√2/2, ±√3/2 or ±1 become that value.
    """
    params = params or Parameters(False)
    rotations: list[sp.Matrix] = []
    positions: list[sp.Matrix] = []
    axes: list[sp.Matrix] = []
    for index, body in enumerate(robot.tree.bodies):
        parent_rotation = sp.eye(3) if body.parent < 0 else rotations[body.parent]
        parent_position = sp.zeros(3, 1) if body.parent < 0 else positions[body.parent]
        joint_rotation = parent_rotation * exact_matrix(body.origin[:3, :3], snap)
        origin = parent_position + parent_rotation * params.vector(body.origin[:3, 3], "d", body.joint)
        axis = exact_matrix(body.axis[:, None], snap)
        world_axis = joint_rotation * axis
        if body.revolute:
            rotations.append(joint_rotation * axis_rotation(axis, sp.cos(theta[index]), sp.sin(theta[index])))
            positions.append(origin)
        else:
            rotations.append(joint_rotation)
            positions.append(origin + world_axis * theta[index])
        axes.append(world_axis)
    return rotations, positions, axes


def axis_rotation(axis: sp.Matrix, c: sp.Expr, s: sp.Expr) -> sp.Matrix:
    """Rodrigues' rotation about a unit ``axis`` by the angle whose cosine is ``c`` and sine ``s``.

    Args:
        axis: Unit axis, 3×1.
        c: Cosine of the angle.
        s: Sine of the angle.
    """
    x, y, z = axis
    skew = sp.Matrix([[0, -z, y], [z, 0, -x], [-y, x, 0]])
    return sp.eye(3) + s * skew + (1 - c) * skew * skew


def body_coordinates(robot: ReferenceRobot, q: list[sp.Symbol], qd: list[sp.Symbol]) -> tuple[sp.Matrix, sp.Matrix]:
    """Every body's joint coordinate and speed: ``theta = S q + offset``, ``theta_dot = S q̇``
    (mimic joints through their exact multiplier and offset).

    Args:
        robot: The reference robot.
        q: Joint position symbols.
        qd: Joint velocity symbols.
    """
    tree = robot.tree
    selection = exact_matrix(tree.selection, 0.0)
    offset = [
        exact_angle(float(o)) if body.revolute else exact_number(float(o))
        for o, body in zip(tree.offset, tree.bodies, strict=True)
    ]
    return selection * sp.Matrix(q) + sp.Matrix(offset), selection * sp.Matrix(qd)
