"""A whole-body controller on contacts: each call one small QP over ``v̇``, ``τ`` and the contact forces.

:class:`Stand` holds a floating robot (a quadruped, a humanoid's legs) on its feet. At a
state ``(q, v)`` it solves, for ``x = (v̇, τ, f)`` (``f``: 3 per contact, world axes)::

    minimise   Σ_k w_k |A_k v̇ − b_k|²  +  ε (|τ|² + |f|²)
    subject to M v̇ + h + b∘v = Sᵀ τ + Jcᵀ f    (the equations of motion)
               Jc v̇ + J̇c v = 0                 (the feet do not move)
               ‖f_t‖ ≤ μ_c n·f, one cone a foot (second-order cones: the exact cone,
                                                 not a linearised pyramid)
               |τ| ≤ τ_max                      (the joints' effort limits)

and returns ``τ``. ``b ∘ v`` is the joints' viscous damping (the model's
:attr:`~robodyn.Robot.joint_damping`; never the Coulomb term) when ``compensate_damping``
is on (what a run that applies the damping sets, :func:`robodyn.sim.twin.compensate`),
else 0: the QP's accelerations are those of the plant that applies it, or of the rigid
plant. The tasks (``A_k v̇ = b_k``, each a PD law of its error):

- centre of mass: ``J_c v̇ + J̇_c v = Kp (c_d − c) − Kd ċ`` (``J_c = A_G[:3] / m``, the
  centroidal momentum matrix's linear rows, :mod:`robodyn.dynamics.centroidal`);
- base orientation: ``R ω̇_b = Kp log(R_d Rᵀ) − Kd ω`` (world axes; ``d(R ω_b)/dt = R ω̇_b``);
- posture: ``q̈_j = Kp (q_j,d − q_j) − Kd q̇_j`` on the actuated joints, a small weight
  (1e-6: what the first two leave free; where it disagrees with them it moves their
  steady state by about that weight times its error).

``μ_c = margin · μ`` (default :data:`CONE_MARGIN`) keeps the forces strictly inside each
contact's friction cone. The solver is **Clarabel** (an interior-point conic solver:
second-order cones natively, equalities kept to its tolerance, maintained, and already
installed with cvxpy, robodyn's ``[ident]`` extra); it is called directly, not through
cvxpy, whose problem compilation would cost more than the solve at every step.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import KW_ONLY, dataclass, field

import numpy as np
import pinocchio as pin

from robodyn.common.extras import require
from robodyn.constraints import PointContact
from robodyn.dynamics import constrained
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError
from robodyn.sim.force_control import scalar, vector
from robodyn.sim.twin import viscous_compensation

#: The controller's cone is this fraction of each contact's friction coefficient.
CONE_MARGIN = 0.9
#: Regularisation of the torques and forces in the cost (makes the QP strictly convex).
REGULARISATION = 1e-11
#: Clarabel's tolerances (gap and feasibility).
TOLERANCE = 1e-10


def _tangents(normal: np.ndarray) -> np.ndarray:
    """Two unit vectors spanning the plane normal to ``normal``, (2, 3)."""
    seed = np.eye(3)[int(np.argmin(np.abs(normal)))]
    first = np.cross(normal, seed)
    first /= np.linalg.norm(first)
    return np.stack([first, np.cross(normal, first)])


def friction_cone_margin(contacts: Sequence[PointContact], forces: np.ndarray) -> np.ndarray:
    """``μ n·f − ‖f_t‖`` of each contact force (≥ 0 inside its cone), in [N].

    Args:
        contacts: Sticking contacts (``friction > 0``).
        forces: Their forces, world axes, shape (3 k,) or (N, 3 k), in [N].

    Returns:
        Shape (k,) or (N, k).
    """
    stacked = np.asarray(forces, float).reshape(*np.shape(forces)[:-1], len(contacts), 3)
    normals = np.array([contact.normal for contact in contacts])
    mu = np.array([contact.friction for contact in contacts])
    normal = np.einsum("...ki,ki->...k", stacked, normals)
    tangential = np.linalg.norm(stacked - normal[..., None] * normals, axis=-1)
    return mu * normal - tangential


def _cross2(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The z component of ``a × b`` for 2-D vectors (last axis)."""
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _hull(points: np.ndarray) -> np.ndarray:
    """Convex hull of 2-D points, counter-clockwise (Andrew's monotone chain), (k, 2)."""
    ordered = sorted(map(tuple, np.round(points, 15)))

    def half(sequence: list) -> list:
        chain: list = []
        for point in sequence:
            while len(chain) >= 2 and _cross2(np.subtract(chain[-1], chain[-2]), np.subtract(point, chain[-2])) <= 0:
                chain.pop()
            chain.append(point)
        return chain[:-1]

    return np.array(half(ordered) + half(ordered[::-1]))


def _ground_axes(robot: Robot) -> np.ndarray:
    """Two unit vectors spanning the plane normal to gravity, right-handed about the upward
    direction: the world's x and y for gravity along −z, (2, 3)."""
    up = -robot.gravity_vector / np.linalg.norm(robot.gravity_vector)
    seed = np.eye(3)[0] if abs(up[0]) < 0.9 else np.eye(3)[1]
    first = seed - (seed @ up) * up
    first /= np.linalg.norm(first)
    return np.stack([first, np.cross(up, first)])


def support_polygon(robot: Robot, q: np.ndarray, contacts: Sequence[PointContact]) -> np.ndarray:
    """The support polygon: the convex hull of the contact points seen along gravity.

    Args:
        robot: The robot.
        q: Its configuration, shape (nq,) (a floating base: position in [m], then its unit
            quaternion).
        contacts: The contacts (their points on their links).

    Returns:
        Its vertices counter-clockwise seen from above, shape (k, 2), in [m], in two axes
        normal to gravity (for gravity along −z: world x, y), the axes
        :func:`support_margin` uses.
    """
    pin.framesForwardKinematics(robot.model, robot.data, q)
    world = [robot.data.oMf[robot.frame_id(c.frame)].act(np.asarray(c.point, float)) for c in contacts]
    return _hull(np.array(world) @ _ground_axes(robot).T)


def support_margin(robot: Robot, q: np.ndarray, contacts: Sequence[PointContact], point: np.ndarray) -> float:
    """How far ``point`` (3,) seen along gravity lies inside the support polygon, in [m]
    (negative: outside; −inf for fewer than three contact points not on one line).

    Args:
        robot: The robot.
        q: Its configuration, shape (nq,) (a floating base: position in [m], then its unit
            quaternion).
        contacts: The contacts (their points on their links).
        point: A world point in [m], shape (3,) (e.g. the centre of mass).
    """
    polygon = support_polygon(robot, q, contacts)
    if len(polygon) < 3:
        return -np.inf
    flat = np.asarray(point, float) @ _ground_axes(robot).T
    edges = np.roll(polygon, -1, axis=0) - polygon
    lengths = np.linalg.norm(edges, axis=1)
    return float(np.min(_cross2(edges, flat - polygon) / lengths))


def _rotation(value: object) -> np.ndarray:
    """A rotation matrix (3, 3), or an :class:`InputError` naming ``orientation``."""
    try:
        rotation = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError("orientation", "a rotation matrix (3, 3)", repr(value)[:80]) from None
    if not (
        rotation.shape == (3, 3)
        and np.isfinite(rotation).all()
        and np.allclose(rotation @ rotation.T, np.eye(3), atol=1e-9)
        and np.linalg.det(rotation) > 0
    ):
        raise InputError("orientation", "a rotation matrix (3, 3)", f"an array of shape {rotation.shape}, not a rotation")
    return rotation


@dataclass
class Stand:
    """Hold a floating robot on sticking contacts at a centre of mass and base attitude.

    Attributes:
        model: The controller's model of the robot (floating base, no mimic joints).
        contacts: The feet: sticking :class:`~robodyn.constraints.PointContact` (friction > 0).
        com: The target centre of mass in [m], world axes (3,).
        orientation: The target base attitude, a rotation matrix (3, 3) (world axes).
        posture: The target configuration (nq,) whose joints the posture task holds.
        kp: Centre of mass and attitude stiffness [1/s²]. kd: damping [1/s].
        posture_kp, posture_kd: The posture's, [1/s²] and [1/s].
        weights: Of the centre of mass, attitude and posture tasks.
        torque_limit: ``τ_max`` of each actuated joint (nv − 6,), default the model's effort limits
            (a joint without one, or a limit of 0 as URDF and MJCF write none: no limit).
        margin: ``μ_c / μ`` (:data:`CONE_MARGIN`); ``None`` drops the cone (a negative control).
        compensate_damping: Add ``b ∘ v`` (the model's joint damping) to the equations of
            motion, so that the QP plans for the plant that applies it (never the Coulomb term).
        last_forces: The QP's contact forces at the last call, (3 k,) in [N], world axes.

    Raises:
        InputError: A fixed-base or mimic robot, contacts that do not stick, bad targets.
    """

    model: Robot
    contacts: Sequence[PointContact]
    com: np.ndarray
    orientation: np.ndarray
    posture: np.ndarray
    _: KW_ONLY
    kp: float = 100.0
    kd: float = 20.0
    posture_kp: float = 100.0
    posture_kd: float = 20.0
    weights: tuple[float, float, float] = (1.0, 1.0, 1e-6)
    torque_limit: np.ndarray | None = None
    margin: float | None = CONE_MARGIN
    compensate_damping: bool = False
    last_forces: np.ndarray = field(init=False, repr=False)
    _actuated: np.ndarray = field(init=False, repr=False)
    _tangent_rows: list[np.ndarray] = field(init=False, repr=False)
    _bounds: tuple = field(init=False, repr=False)

    def __post_init__(self) -> None:
        model = self.model
        if not model.floating_base or model.mimic is not None:
            raise InputError("model", "a floating robot without mimic joints", repr(model.name))
        self.contacts = tuple(self.contacts)
        if not self.contacts or not all(isinstance(c, PointContact) and c.friction > 0 for c in self.contacts):
            raise InputError("contacts", "sticking PointContacts (friction > 0)", repr(self.contacts)[:80])
        self.com = vector(self.com, "com")
        self.orientation = _rotation(self.orientation)
        for name in ("kp", "kd", "posture_kp", "posture_kd"):
            setattr(self, name, scalar(getattr(self, name), name, "a finite gain >= 0"))
        weights = vector(self.weights, "weights", 3, "[1]")
        if (weights < 0).any():
            raise InputError("weights", "3 finite weights >= 0", repr(self.weights)[:80])
        self.weights = (float(weights[0]), float(weights[1]), float(weights[2]))
        if self.margin is not None and not 0 < scalar(self.margin, "margin", "a fraction in (0, 1] or None") <= 1:
            raise InputError("margin", "a fraction in (0, 1] or None", repr(self.margin))
        (self.posture,), batch = model.validate(q=self.posture)
        if batch:
            raise InputError("posture", f"one configuration ({model.nq} values)", f"shape {self.posture.shape}")
        self._actuated = np.array([dof.index for dof in model.dofs if dof.actuated])
        efforts = np.array([dof.effort_limit for dof in model.dofs if dof.actuated], dtype=float)
        limits = np.where(efforts > 0, efforts, np.inf) if self.torque_limit is None else self.torque_limit  # 0: none
        try:
            self.torque_limit = np.broadcast_to(np.asarray(limits, float), (len(self._actuated),)).copy()
        except (TypeError, ValueError):
            raise InputError(
                "torque_limit", f"a limit or {len(self._actuated)} limits in [N m] or [N]", repr(limits)[:80]
            ) from None
        if not (self.torque_limit > 0).all():
            raise InputError("torque_limit", "limits > 0 in [N m] or [N]", repr(self.torque_limit)[:80])
        self._tangent_rows = [_tangents(np.asarray(contact.normal)) for contact in self.contacts]
        self.last_forces = np.zeros(3 * len(self.contacts))
        self._bounds = constrained.bound(model, self.contacts)
        margin = support_margin(model, self.posture, self.contacts, self.com)
        if not margin > 0:
            raise InputError(
                "com",
                "a centre of mass over the support polygon of the contacts (at the posture)",
                f"{-margin:.3g} m outside it"
                if np.isfinite(margin)
                else "contacts with no polygon (fewer than three points off one line)",
            )

    def _tasks(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The stacked weighted task rows ``(A, b)`` over ``v̇``."""
        model, nv = self.model, self.model.nv
        data = model.data
        pin.centerOfMass(model.model, data, q, v, np.zeros(nv))
        com, com_velocity, com_drift = data.com[0].copy(), data.vcom[0].copy(), data.acom[0].copy()
        com_jacobian = model.centroidal_momentum_matrix(q)[:3] / model.total_mass
        rotation = pin.Quaternion(q[6], q[3], q[4], q[5]).toRotationMatrix()
        attitude = np.zeros((3, nv))
        attitude[:, 3:6] = rotation
        omega = rotation @ v[3:6]
        joints = np.zeros((nv - 6, nv))
        joints[:, 6:] = np.eye(nv - 6)
        joint_error = pin.difference(model.model, q, self.posture)[6:]
        rows = (
            (com_jacobian, self.kp * (self.com - com) - self.kd * com_velocity - com_drift),
            (attitude, self.kp * pin.log3(self.orientation @ rotation.T) - self.kd * omega),
            (joints, self.posture_kp * joint_error - self.posture_kd * v[6:]),
        )
        weights = np.sqrt(np.asarray(self.weights, float))
        return np.vstack([w * a for w, (a, _) in zip(weights, rows, strict=True)]), np.concatenate(
            [w * b for w, (_, b) in zip(weights, rows, strict=True)]
        )

    def _constraints(self, q: np.ndarray, v: np.ndarray, sizes: tuple[int, int, int]) -> tuple[np.ndarray, np.ndarray, list]:
        """``A x + s = b``, ``s`` in the cones: equalities, torque limits, friction cones."""
        clarabel = require("clarabel", extra="ident", purpose="the whole-body controller's QP")
        model = self.model
        nv, nt, nf = sizes
        mass, bias = model.mass_matrix(q), model.nonlinear_effects(q, v)
        _, jacobian, drift = constrained.state_rows(model, self._bounds, q, v)
        selection = np.zeros((nt, nv))
        selection[np.arange(nt), self._actuated] = 1.0
        dynamics = np.hstack([mass, -selection.T, -jacobian.T])
        fixed = np.hstack([jacobian, np.zeros((len(jacobian), nt + nf))])
        bound = np.asarray(self.torque_limit, dtype=float)  # set by __post_init__
        limited = np.flatnonzero(np.isfinite(bound))  # an unlimited joint has no row
        limits = np.zeros((2 * limited.size, nv + nt + nf))
        limits[np.arange(limited.size), nv + limited] = 1.0
        limits[limited.size + np.arange(limited.size), nv + limited] = -1.0
        rows = [dynamics, fixed, limits]
        damping = viscous_compensation(model, self.compensate_damping, v)
        right = [-bias - damping, -drift, np.tile(bound[limited], 2)]
        cones = [clarabel.ZeroConeT(nv + len(jacobian)), clarabel.NonnegativeConeT(2 * limited.size)]
        if self.margin is not None:
            for index, (contact, tangents) in enumerate(zip(self.contacts, self._tangent_rows, strict=True)):
                cone = np.zeros((3, nv + nt + nf))
                columns = slice(nv + nt + 3 * index, nv + nt + 3 * index + 3)
                cone[0, columns] = -self.margin * contact.friction * np.asarray(contact.normal)
                cone[1:, columns] = -tangents
                rows.append(cone)
                right.append(np.zeros(3))
                cones.append(clarabel.SecondOrderConeT(3))
        return np.vstack(rows), np.concatenate(right), cones

    def solve(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The QP's ``(v̇, τ, f)`` at a state: (nv,), (actuated,), (3 k,) in SI units, world axes for ``f``.

        Args:
            q: Configuration, shape (nq,) (a floating base: position in [m], then its unit
                quaternion).
            v: Velocity, shape (nv,), in [rad/s] / [m/s] (a floating base's first six in its
                own axes, Pinocchio's convention).

        Raises:
            InputError: If the QP has no solution at this state (naming ``q``).
        """
        clarabel = require("clarabel", extra="ident", purpose="the whole-body controller's QP")
        sparse = require("scipy.sparse", extra="ident", purpose="the whole-body controller's QP")
        nv, nt, nf = self.model.nv, len(self._actuated), 3 * len(self.contacts)
        tasks, targets = self._tasks(q, v)
        hessian = np.zeros((nv + nt + nf,) * 2)
        hessian[:nv, :nv] = tasks.T @ tasks
        hessian[nv:, nv:] = REGULARISATION * np.eye(nt + nf)
        linear = np.concatenate([-tasks.T @ targets, np.zeros(nt + nf)])
        matrix, right, cones = self._constraints(q, v, (nv, nt, nf))
        settings = clarabel.DefaultSettings()
        settings.verbose = False
        settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = TOLERANCE
        solver = clarabel.DefaultSolver(
            sparse.csc_matrix(np.triu(hessian)), linear, sparse.csc_matrix(matrix), right, cones, settings
        )
        solution = solver.solve()
        if str(solution.status) not in ("Solved", "AlmostSolved"):
            raise InputError(
                "q",
                "a state from which the contacts can carry the robot within their cones and torque limits",
                f"a QP {solution.status} (a leg stretched, a push beyond friction)",
            )
        x = np.asarray(solution.x)
        return x[:nv], x[nv : nv + nt], x[nv + nt :]

    def __call__(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        _, torques, forces = self.solve(q, v)
        self.last_forces = forces
        tau = np.zeros(self.model.nv)
        tau[self._actuated] = torques
        return tau


__all__ = ["CONE_MARGIN", "Stand", "friction_cone_margin", "support_margin", "support_polygon"]
