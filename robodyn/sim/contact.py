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
the previous step's impulses. The contact force reported is ``p / dt`` [N].

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
tolerance (tests/sim/test_contact_stepper.py).
"""

from __future__ import annotations

import math
import threading
from typing import NamedTuple

import numpy as np
import pinocchio as pin

from robodyn.compiled.contact import kept_step
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import SingularMassMatrixError
from robodyn.sim.contact_solver import ContactSettings, solve_impulses
from robodyn.sim.ground import ContactPoint, Ground

#: A contact is active when its normal force exceeds this, in [N].
ACTIVE_FORCE = 1e-9

_DEFAULT = ContactSettings()
_LOCAL = threading.local()  # this thread's ContactStepper of the run it steps


class ContactStep(NamedTuple):
    """One step's outcome.

    Attributes:
        q, v: The state at the end of the step, shapes (nq,), (nv,).
        impulses: ``p`` per contact in its axes ``(t₁, t₂, n)``, shape (k, 3), [N s].
        forces: ``p / dt`` in world axes, shape (k, 3), [N].
        gaps: Each point's signed distance above the plane at the start, shape (k,), [m].
        slip: Each point's tangential speed after the step, shape (k,), [m/s].
        iterations: ADMM's iterations; ``converged`` whether it met its tolerance.
    """

    q: np.ndarray
    v: np.ndarray
    impulses: np.ndarray
    forces: np.ndarray
    gaps: np.ndarray
    slip: np.ndarray
    iterations: int
    converged: bool


def contact_kinematics(
    robot: Robot, q: np.ndarray, ground: Ground, points: tuple[ContactPoint, ...]
) -> tuple[np.ndarray, np.ndarray]:
    """The points' gaps (k,) [m] and their Jacobian (3k, nv) in the contact axes ``(t₁, t₂, n)``.

    A sphere's point is its centre minus ``radius · n`` (the point nearest the plane).
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


def integrate(robot: Robot, q: np.ndarray, dq: np.ndarray) -> np.ndarray:
    """``q ⊕ dq`` with a floating base on ``R³ × SO(3)``: its origin moves along the world
    velocity ``R v`` in a straight line, its rotation by ``exp(ω dt)`` (MuJoCo's rule).

    Pinocchio's ``integrate`` moves the base along the screw of ``SE(3)``'s exponential: a
    rolling ball's body twist is a rotation about its contact point, so its centre would
    dip by ``r (1 − cos ω dt)`` into the plane every step.
    """
    moved = pin.integrate(robot.model, q, dq)
    if robot.floating_base:
        rotation = pin.Quaternion(q[3:7]).toRotationMatrix()
        moved[:3] = q[:3] + rotation @ dq[:3]
    return moved


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
) -> ContactStep:
    """One step of the contact scheme (module docstring) from checked 1-D ``q``, ``v``, ``tau``.

    A run's steps (the same ``robot``, ``ground`` and ``points`` objects, ``guess`` set)
    reuse one :class:`ContactStepper` of this thread, made again at each first step
    (``guess=None``); a robot with mimic joints (its ``M`` is not CRBA's) goes through
    :func:`generic_step`.

    Args:
        robot: The robot.
        q, v, tau: State and joint torques at the start, shapes (nq,), (nv,), (nv,).
        dt: Step in [s].
        ground: The plane.
        points: The contact points.
        settings: Solver settings (default :class:`ContactSettings`).
        guess: Warm start: the previous step's impulses (k, 3), or ``None``.

    Returns:
        The state after the step with the contact impulses and forces.
    """
    settings = settings or _DEFAULT
    if robot.handle.mimic is not None:
        return generic_step(robot, q, v, tau, dt, ground, points, settings, guess)
    stepper = getattr(_LOCAL, "stepper", None)
    if guess is None or stepper is None or not stepper.serves(robot, ground, points):
        stepper = _LOCAL.stepper = ContactStepper(robot, ground, points)
    return stepper.step(q, v, tau, dt, settings, guess)


class ContactStepper:
    """The contact step of one robot (no mimic joints), ground and point set, its
    workspace kept from step to step: one Pinocchio ``Data``, the points' anchors in their
    joints' frames and the rows of ``J`` each point sees.

    A step is one pass of Pinocchio per quantity (``M⁻¹`` by its ABA-like recursion,
    ``C v + G``, the joints' world Jacobians) and a few stacked products: each point's
    Jacobian is ``axes (J_v − [p]× J_ω)`` of its joint's world Jacobian (``v_p = v₀ + ω × p``
    at the world origin, the joint's supporting columns), every point at once.
    """

    def __init__(self, robot: Robot, ground: Ground, points: tuple[ContactPoint, ...]):
        model, nv, count = robot.model, robot.nv, len(points)
        self.robot, self.ground, self.points = robot, ground, points
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

    def serves(self, robot: Robot, ground: Ground, points: tuple[ContactPoint, ...]) -> bool:
        """Whether this stepper is the one of these very objects."""
        return robot is self.robot and ground is self.ground and points is self.points

    def kinematics(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The points' gaps (k,) [m] and Jacobian (3k, nv) (:func:`contact_kinematics`)."""
        world, gaps = self.locate(q)
        return gaps, self.jacobian(world)

    def locate(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The points in world axes (k, 3) [m] and their gaps (k,) [m]; the joints' world
        Jacobians are then in ``data.J``."""
        world = self.centres(q) - self.offsets
        return world, world @ self.normal - self.level

    def centres(self, q: np.ndarray) -> np.ndarray:
        """The points' anchors (a sphere's centre) in world axes (k, 3) [m], and the joints'
        world Jacobians in ``data.J``."""
        pin.computeJointJacobians(self.model, self.data, q)
        placements = self.data.oMi
        return np.array([placements[joint].act(anchor) for joint, anchor in self.anchors]).reshape(-1, 3)

    def jacobian(self, world: np.ndarray) -> np.ndarray:
        """The points' Jacobian (3k, nv) in their contact axes, after :meth:`locate`."""
        count = len(self.anchors)
        columns = self.data.J * self.mask  # (k, 6, nv): each point's joint's world Jacobian
        linear = columns[:, :3] - (world @ self.skew).reshape(count, 3, 3) @ columns[:, 3:]
        return _local_jacobian(self.axes, linear).reshape(3 * count, self.model.nv)

    def step(
        self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, dt: float, settings: ContactSettings, guess: np.ndarray | None
    ) -> ContactStep:
        """:func:`contact_step` of this robot, ground and points."""
        model, data = self.model, self.data
        inverse = pin.computeMinverse(model, data, q)  # M⁻¹'s upper triangle (armature included)
        bias = pin.nonLinearEffects(model, data, q, v)
        centres = self.centres(q)
        if self.kept is not None and guess is not None and settings.polish and self.anchors:
            if self.scalars[0] != (dt, settings):
                self.scalars = ((dt, settings), np.array([dt, settings.baumgarte, self.ground.friction, self.level]))
            base = q if self.floating else None
            done = self.kept(
                inverse, data.J, centres, self.offsets, self.mask, v, tau, bias, guess, self.axes, self.scalars[1], base
            )
            if done is not None:  # the previous modes hold: solved in C, with integrate's base origin
                v_next, impulses, forces, slip, gaps, dq, origin = done
                moved = pin.integrate(model, q, dq)
                if origin is not None:
                    moved[:3] = origin
                return ContactStep(moved, v_next, impulses, forces, gaps, slip, 0, True)
        world = centres - self.offsets
        gaps = world @ self.normal - self.level
        jacobian = self.jacobian(world)
        np.copyto(inverse, inverse.T, where=self.lower)
        response = inverse @ jacobian.T
        free = v + dt * (inverse @ (tau - bias))
        if not math.isfinite(free @ free) and not np.isfinite(inverse).all():  # (a huge free: not finite squared)
            raise SingularMassMatrixError(self.robot.name, [])
        return _finish(self.robot, q, dt, self.ground, settings, guess, (gaps, jacobian, free, response))


def generic_step(
    robot: Robot, q: np.ndarray, v: np.ndarray, tau: np.ndarray, dt: float, ground: Ground,
    points: tuple[ContactPoint, ...], settings: ContactSettings, guess: np.ndarray | None,
) -> ContactStep:  # fmt: skip
    """:func:`contact_step` through ``Robot``'s own ``M`` and ``C v + G`` (any robot: mimic joints too)."""
    mass, bias = robot.mass_matrix(q), robot.nonlinear_effects(q, v)
    gaps, jacobian = contact_kinematics(robot, q, ground, points)
    try:
        solved = np.linalg.solve(mass, np.column_stack([tau - bias, jacobian.T]))
    except np.linalg.LinAlgError:
        raise SingularMassMatrixError(robot.name, []) from None
    free = v + dt * solved[:, 0]
    return _finish(robot, q, dt, ground, settings, guess, (gaps, jacobian, free, solved[:, 1:]))


def _finish(
    robot: Robot, q: np.ndarray, dt: float, ground: Ground, settings: ContactSettings, guess: np.ndarray | None,
    terms: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
) -> ContactStep:  # fmt: skip
    """The step from its ``gaps``, ``J``, the free velocity and ``M⁻¹ Jᵀ``: the impulses, ``v⁺``, ``q⁺``."""
    gaps, jacobian, free, response = terms
    velocity = jacobian @ free
    beta = settings.baumgarte
    velocity[2::3] += [gap / dt if gap >= 0.0 else beta * gap / dt for gap in gaps.tolist()]
    delassus = jacobian @ response
    impulses, iterations, converged = solve_impulses(delassus, velocity, ground.friction, settings, guess, dofs=jacobian.shape[1])
    v_next = free + response @ impulses
    local = impulses.reshape(-1, 3)
    after = (jacobian @ v_next).reshape(-1, 3)
    return ContactStep(
        integrate(robot, q, dt * v_next),
        v_next,
        local,
        local @ ground.frame() / dt,
        gaps,
        np.hypot(after[:, 0], after[:, 1]),
        iterations,
        converged,
    )


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
