"""Unilateral point contacts with Coulomb friction: one time step (a pure function).

**Scheme** (semi-implicit Euler at the velocity level, Stewart–Trinkle / Anitescu, as
MuJoCo, Drake's TAMSI and Pinocchio's simulators do): with ``M``, ``h = C v + G`` at the
start of the step and the contacts' Jacobian ``J`` (3 rows a contact, in its axes
``(t₁, t₂, n)``),

    v⁺ = v + dt M⁻¹ (τ − h) + M⁻¹ Jᵀ p,        q⁺ = q ⊕ dt v⁺

(a floating base's ``⊕`` on ``R³ × SO(3)``, :func:`integrate`),

where the impulses ``p`` [N s] solve the **nonlinear complementarity problem** of the
Coulomb cone (not a pyramid): for each contact ``i``, ``pᵢ ∈ K_μ = {‖p_t‖ ≤ μ p_n}``, its
post-step velocity ``uᵢ = Jᵢ v⁺ + bᵢ`` and the De Saxcé velocity
``ûᵢ = uᵢ + μ ‖u_t‖ n ∈ K_μ*`` (the dual cone), ``pᵢ · ûᵢ = 0``: a contact is open
(``p = 0``), sticking (``u = 0``) or slipping (``u_n = 0``, friction ``μ p_n`` against the
slip). The solver is **Pinocchio's ADMM** (``ADMMConstraintSolver`` with ``solve_ncp``)
over **robodyn's Delassus matrix** ``A = J M⁻¹ Jᵀ`` (``DelassusOperatorDense``): ``M`` is
robodyn's (mimic joints and armature included, which Pinocchio's own constraint
algorithms refuse), the cones are ``PointContactConstraintModel``\\ s, warm-started with
the previous step's impulses. The contact force reported is ``p / dt`` [N] (the solve and
the state after it: :mod:`robodyn.sim.contact_impulses`).

**Stabilisation** (the bias ``b`` on the normal rows, :class:`ContactSettings`): a point
above the plane (gap ``g ≥ 0``) may close the gap in the step but not cross it,
``u_n = n·v⁺ + g / dt ≥ 0`` (a *speculative* contact: a dropped body lands on the plane
without penetrating); a penetrating point (``g < 0``) is pushed out by the fraction
``β`` of its penetration each step (Baumgarte at the velocity level, ``b_n = β g / dt``,
``β = 0.2`` by default). **Impacts are inelastic**: the normal velocity of a point that
lands becomes zero within the step (no restitution). Contacts are rigid (no compliance).

**Speed** (:class:`ContactStepper`): a run's steps reuse one workspace; ``M⁻¹`` comes from
Pinocchio's ``computeMinverse``, every point's Jacobian from one ``computeJointJacobians``;
a step whose previous contacts all stick (a robot standing) is one C call
(:mod:`robodyn.compiled.contact`: the sticking rows' solve and the complementarity check,
no ADMM; numpy's polish without a C compiler, :mod:`robodyn.sim.contact_solver`). Robots
with mimic joints take :func:`generic_step` (``Robot``'s ``M``); the two agree to ADMM's
tolerance (tests/sim/test_contact_stepper.py). Enforced joint limits are rows of the same
step in both (:mod:`robodyn.sim.contact_limits`); the C call declines a step with one in reach.
"""

from __future__ import annotations

import math
import threading

import numpy as np
import pinocchio as pin

from robodyn.compiled.contact import kept_step
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import SingularMassMatrixError
from robodyn.sim.contact_impulses import ContactStep, finish_step, integrate
from robodyn.sim.contact_limits import LimitRows
from robodyn.sim.contact_solver import ContactSettings
from robodyn.sim.ground import ContactPoint, Ground

#: A contact is active when its normal force exceeds this, in [N].
ACTIVE_FORCE = 1e-9

_DEFAULT = ContactSettings()
_LOCAL = threading.local()  # this thread's ContactStepper of the run it steps


def contact_kinematics(
    robot: Robot, q: np.ndarray, ground: Ground, points: tuple[ContactPoint, ...]
) -> tuple[np.ndarray, np.ndarray]:
    """The points' gaps (k,) [m] and their Jacobian (3k, nv) in the contact axes ``(t₁, t₂, n)``.

    A sphere's point is its centre minus ``radius · n`` (the point nearest the plane).

    Args:
        robot: The robot.
        q: The configuration, shape (nq,).
        ground: The plane (its normal ``n`` and contact axes, :meth:`Ground.frame`).
        points: The contact points (k of them).
    """
    model, data, nv = robot.model, robot.handle.data, robot.nv
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    axes, normal = ground.frame(), np.array(ground.normal)
    frames = robot.handle.frames
    gaps, rows = np.empty(len(points)), []
    for index, point in enumerate(points):
        frame = frames[point.link]
        placement = data.oMf[frame]
        lever = placement.rotation @ np.array(point.position) - point.radius * normal
        jacobian = pin.getFrameJacobian(model, data, frame, pin.LOCAL_WORLD_ALIGNED).reshape(6, nv)
        linear = jacobian[:3] - _skew(lever) @ jacobian[3:]
        gaps[index] = ground.gap(placement.translation + lever)
        rows.append(_local_jacobian(axes, linear))
    return gaps, np.vstack(rows) if rows else np.zeros((0, nv))


def _local_jacobian(axes: np.ndarray, linear: np.ndarray) -> np.ndarray:
    """Points' linear Jacobians (…, 3, nv) in the contact axes (rows ``t₁, t₂, n``)."""
    return axes @ linear


def _skew(a: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


def contact_step(
    robot: Robot,
    q: np.ndarray,
    v: np.ndarray,
    tau: np.ndarray,
    dt: float,
    ground: Ground,
    points: tuple[ContactPoint, ...],
    *,
    settings: ContactSettings | None = None,
    guess: np.ndarray | None = None,
    limits: LimitRows | None = None,
    held: np.ndarray | None = None,
) -> ContactStep:
    """One step of the contact scheme (module docstring) from checked 1-D ``q``, ``v``, ``tau``.

    A run's steps (the same ``robot``, ``ground``, ``points`` and ``limits`` objects,
    ``guess`` set) reuse one :class:`ContactStepper` of this thread, made again at each
    first step (``guess=None``); a robot with mimic joints (its ``M`` is not CRBA's) goes
    through :func:`generic_step`.

    Args:
        robot: The robot.
        q, v, tau: State and joint torques at the start, shapes (nq,), (nv,), (nv,).
        dt: Step in [s].
        ground: The plane.
        points: The contact points.
        settings: Solver settings (default :class:`ContactSettings`).
        guess: Warm start: the previous step's impulses (k, 3), or ``None``.
        limits: The joints' position limits as rows of the same problem
            (:mod:`robodyn.sim.contact_limits`), or ``None``: the joints move freely.
        held: Warm start of the limit rows: the previous step's ``limits`` impulses (r,), or ``None``.

    Returns:
        The state after the step with the contact impulses and forces (and the limit rows' impulses).
    """
    settings = settings or _DEFAULT
    if robot.handle.mimic is not None:
        return generic_step(robot, q, v, tau, dt, ground, points, settings, guess, limits=limits, held=held)
    stepper = getattr(_LOCAL, "stepper", None)
    if guess is None or stepper is None or not stepper.serves(robot, ground, points, limits):
        stepper = _LOCAL.stepper = ContactStepper(robot, ground, points, limits)
    return stepper.step(q, v, tau, dt, settings, guess, held)


class ContactStepper:
    """The contact step of one robot (no mimic joints), ground, point set and limit rows,
    its workspace kept from step to step: one Pinocchio ``Data``, the points' anchors in
    their joints' frames and the rows of ``J`` each point sees.

    A step is one pass of Pinocchio per quantity (``M⁻¹`` by its ABA-like recursion,
    ``C v + G``, the joints' world Jacobians) and a few stacked products: each point's
    Jacobian is ``axes (J_v − [p]× J_ω)`` of its joint's world Jacobian (``v_p = v₀ + ω × p``
    at the world origin, the joint's supporting columns), every point at once.

    Args:
        robot, ground, points, limits: As for :func:`contact_step` (a robot without mimic joints).
    """

    def __init__(self, robot: Robot, ground: Ground, points: tuple[ContactPoint, ...], limits: LimitRows | None = None) -> None:
        model, nv, count = robot.model, robot.nv, len(points)
        self.robot, self.ground, self.points, self.limits = robot, ground, points, limits
        self.model, self.data = model, model.createData()
        self.anchors = []
        self.mask = np.zeros((count, 1, nv))
        for index, point in enumerate(points):
            frame = model.frames[robot.handle.frames[point.link]]
            self.anchors.append((frame.parentJoint, frame.placement.act(np.array(point.position))))
            for joint in model.supports[frame.parentJoint]:
                self.mask[index, 0, model.idx_vs[joint] : model.idx_vs[joint] + model.nvs[joint]] = 1.0
        self.axes = ground.frame()
        self.normal, self.level = self.axes[2], float(ground.point @ self.axes[2])
        self.offsets = np.array([point.radius * self.normal for point in points]).reshape(count, 3)
        self.skew = np.array([_skew(unit).ravel() for unit in np.eye(3)])  # p @ skew: [p]× of every point, flat
        self.lower = np.tri(nv, nv, -1, dtype=bool)
        self.floating = robot.floating_base
        self.scalars: tuple[tuple[float, ContactSettings] | None, np.ndarray] = (None, np.zeros(4))  # the C step's
        #: The compiled step of kept modes (robodyn.compiled.contact), or None: Python alone.
        self.kept = kept_step()

    def serves(self, robot: Robot, ground: Ground, points: tuple[ContactPoint, ...], limits: LimitRows | None = None) -> bool:
        """Whether this stepper is the one of these very objects.

        Args:
            robot, ground, points, limits: As for :func:`contact_step`.
        """
        return robot is self.robot and ground is self.ground and points is self.points and limits is self.limits

    def kinematics(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The points' gaps (k,) [m] and Jacobian (3k, nv) (:func:`contact_kinematics`).

        Args:
            q: The configuration, shape (nq,).
        """
        world, gaps = self.locate(q)
        return gaps, self.jacobian(world)

    def locate(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The points in world axes (k, 3) [m] and their gaps (k,) [m]; the joints' world
        Jacobians are then in ``data.J``.

        Args:
            q: The configuration, shape (nq,).
        """
        world = self.centres(q) - self.offsets
        return world, world @ self.normal - self.level

    def centres(self, q: np.ndarray) -> np.ndarray:
        """The points' anchors (a sphere's centre) in world axes (k, 3) [m], and the joints'
        world Jacobians in ``data.J``.

        Args:
            q: The configuration, shape (nq,).
        """
        pin.computeJointJacobians(self.model, self.data, q)
        placements = self.data.oMi
        return np.array([placements[joint].act(anchor) for joint, anchor in self.anchors]).reshape(-1, 3)

    def jacobian(self, world: np.ndarray) -> np.ndarray:
        """The points' Jacobian (3k, nv) in their contact axes, after :meth:`locate`.

        Args:
            world: The points in world axes, shape (k, 3), in [m].
        """
        count, nv = len(self.anchors), self.model.nv
        columns = self.data.J.reshape(6, nv) * self.mask  # (k, 6, nv): each point's joint's world Jacobian
        linear = columns[:, :3] - (world @ self.skew).reshape(count, 3, 3) @ columns[:, 3:]
        return _local_jacobian(self.axes, linear).reshape(3 * count, nv)

    def step(
        self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, dt: float, settings: ContactSettings, guess: np.ndarray | None,
        held: np.ndarray | None = None,
    ) -> ContactStep:  # fmt: skip
        """:func:`contact_step` of this robot, ground, points and limit rows.

        Args:
            q, v, tau: State and joint torques at the start, shapes (nq,), (nv,), (nv,).
            dt: Step in [s].
            settings: Solver settings.
            guess: The previous step's impulses (k, 3), or ``None``.
            held: The previous step's limit impulses (r,), or ``None``.
        """
        model, data, rows = self.model, self.data, self.limits
        inverse = pin.computeMinverse(model, data, q)  # M⁻¹'s upper triangle (armature included)
        bias = pin.nonLinearEffects(model, data, q, v)
        centres = self.centres(q)
        near, free = None, None
        if rows is not None:  # (the C step reads M⁻¹'s upper triangle alone: mirrored only when needed)
            np.copyto(inverse, inverse.T, where=self.lower)
            free = v + dt * (inverse @ (tau - bias))
            near = rows.near(q, v, free, dt)
        if near is None or not len(near):  # no limit row in reach: the compiled step may take it
            done = self._compiled(q, v, tau, dt, settings, guess, (inverse, bias, centres))
            if done is not None:
                return done if rows is None else done._replace(limits=np.zeros(len(rows.bound)))
        if free is None:
            np.copyto(inverse, inverse.T, where=self.lower)
            free = v + dt * (inverse @ (tau - bias))
        if not math.isfinite(free @ free) and not np.isfinite(inverse).all():  # (a huge free: not finite squared)
            raise SingularMassMatrixError(self.robot.name, [])
        world = centres - self.offsets
        gaps, jacobian = world @ self.normal - self.level, self.jacobian(world)
        if rows is not None and near is not None and len(near):
            jacobian = np.vstack([jacobian, rows.jacobian(near, model.nv)])
            gaps = np.concatenate([gaps, rows.gaps(q)[near]])
        terms = (gaps, jacobian, free, inverse @ jacobian.T)
        return finish_step(self.robot, q, dt, self.ground, settings, guess, terms, (rows, near, held))

    def _compiled(
        self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, dt: float, settings: ContactSettings, guess: np.ndarray | None,
        terms: tuple[np.ndarray, np.ndarray, np.ndarray],
    ) -> ContactStep | None:  # fmt: skip
        """The step by the compiled path when the previous modes hold (every closed contact
        sticking), else ``None``; ``terms``: ``M⁻¹``, ``C v + G`` and the points' anchors."""
        if self.kept is None or guess is None or not settings.polish or not self.anchors:
            return None
        if self.scalars[0] != (dt, settings):
            self.scalars = ((dt, settings), np.array([dt, settings.baumgarte, self.ground.friction, self.level]))
        inverse, bias, centres = terms
        joints = self.data.J.reshape(6, self.model.nv)
        base = q if self.floating else None
        done = self.kept(inverse, joints, centres, self.offsets, self.mask, v, tau, bias, guess, self.axes, self.scalars[1], base)
        if done is None:
            return None
        v_next, impulses, forces, slip, gaps, dq, origin = done  # solved in C, with integrate's base origin
        moved = pin.integrate(self.model, q, dq)
        if origin is not None:
            moved[:3] = origin
        return ContactStep(moved, v_next, impulses, forces, gaps, slip, 0, True)


def generic_step(
    robot: Robot, q: np.ndarray, v: np.ndarray, tau: np.ndarray, dt: float, ground: Ground,
    points: tuple[ContactPoint, ...], settings: ContactSettings, guess: np.ndarray | None, *,
    limits: LimitRows | None = None, held: np.ndarray | None = None,
) -> ContactStep:  # fmt: skip
    """:func:`contact_step` through ``Robot``'s own ``M`` and ``C v + G`` (any robot: mimic joints too).

    Args:
        robot, q, v, tau, dt, ground, points, settings, guess, limits, held: As for :func:`contact_step`.
    """
    mass, bias = robot.mass_matrix(q), robot.nonlinear_effects(q, v)
    gaps, jacobian = contact_kinematics(robot, q, ground, points)
    try:
        inverse = np.linalg.solve(mass, np.column_stack([tau - bias, np.eye(robot.nv)]))
    except np.linalg.LinAlgError:
        raise SingularMassMatrixError(robot.name, []) from None
    free = v + dt * inverse[:, 0]
    near = None if limits is None else limits.near(q, v, free, dt)
    if limits is not None and near is not None and len(near):
        jacobian = np.vstack([jacobian, limits.jacobian(near, robot.nv)])
        gaps = np.concatenate([gaps, limits.gaps(q)[near]])
    terms = (gaps, jacobian, free, inverse[:, 1:] @ jacobian.T)
    return finish_step(robot, q, dt, ground, settings, guess, terms, (limits, near, held))


__all__ = [
    "ACTIVE_FORCE",
    "ContactSettings",
    "ContactStep",
    "ContactStepper",
    "contact_kinematics",
    "contact_step",
    "generic_step",
    "integrate",
]
