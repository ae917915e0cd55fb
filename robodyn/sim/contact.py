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
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import pinocchio as pin

from robodyn.dynamics.robot import Robot
from robodyn.exceptions import SingularMassMatrixError
from robodyn.sim.contact_solver import ContactSettings, solve_impulses
from robodyn.sim.ground import ContactPoint, Ground

#: A contact is active when its normal force exceeds this, in [N].
ACTIVE_FORCE = 1e-9


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
    """A point's linear Jacobian (3, nv) in the contact axes (rows ``t₁, t₂, n``)."""
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
    settings = settings or ContactSettings()
    mass, bias = robot.mass_matrix(q), robot.nonlinear_effects(q, v)
    gaps, jacobian = contact_kinematics(robot, q, ground, points)
    try:
        solved = np.linalg.solve(mass, np.column_stack([tau - bias, jacobian.T]))
    except np.linalg.LinAlgError:
        raise SingularMassMatrixError(robot.name, []) from None
    free = v + dt * solved[:, 0]
    response = solved[:, 1:]
    velocity = jacobian @ free
    velocity[2::3] += np.where(gaps >= 0.0, gaps, settings.baumgarte * gaps) / dt
    impulses, iterations, converged = solve_impulses(jacobian @ response, velocity, ground.friction, settings, guess)
    v_next = free + response @ impulses
    local = impulses.reshape(-1, 3)
    after = (jacobian @ v_next).reshape(-1, 3)
    return ContactStep(
        integrate(robot, q, dt * v_next),
        v_next,
        local,
        local @ ground.frame() / dt,
        gaps,
        np.linalg.norm(after[:, :2], axis=1),
        iterations,
        converged,
    )


__all__ = ["ACTIVE_FORCE", "ContactSettings", "ContactStep", "contact_kinematics", "contact_step", "integrate"]
