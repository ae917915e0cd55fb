"""The end of one contact step (:mod:`robodyn.sim.contact`): the impulses of its rows, ``v⁺``, ``q⁺``.

From the rows' gaps, their Jacobian ``J``, the free velocity ``v + dt M⁻¹ (τ − h)`` and
``M⁻¹ Jᵀ`` (the points' rows, then the joint-limit rows in reach), :func:`finish_step`
biases the normal rows (speculative contact, Baumgarte), solves the impulses
(:func:`robodyn.sim.contact_solver.solve_impulses`) and moves the state
(:func:`integrate`: a floating base on ``R³ × SO(3)``), into a :class:`ContactStep`.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import pinocchio as pin

from robodyn.dynamics.robot import Robot
from robodyn.sim.contact_limits import LimitRows
from robodyn.sim.contact_solver import ContactSettings, solve_impulses
from robodyn.sim.ground import Ground


class ContactStep(NamedTuple):
    """One step's outcome.

    Attributes:
        q, v: The state at the end of the step, shapes (nq,), (nv,).
        impulses: ``p`` per contact in its axes ``(t₁, t₂, n)``, shape (k, 3), [N s].
        forces: ``p / dt`` in world axes, shape (k, 3), [N].
        gaps: Each point's signed distance above the plane at the start, shape (k,), [m].
        slip: Each point's tangential speed after the step, shape (k,), [m/s].
        iterations: ADMM's iterations; ``converged`` whether it met its tolerance.
        limits: With limit rows (:mod:`robodyn.sim.contact_limits`), each row's impulse,
            shape (r,), in [N m s] or [N s] (0 for a row out of reach); else ``None``.
    """

    q: np.ndarray
    v: np.ndarray
    impulses: np.ndarray
    forces: np.ndarray
    gaps: np.ndarray
    slip: np.ndarray
    iterations: int
    converged: bool
    limits: np.ndarray | None = None


def integrate(robot: Robot, q: np.ndarray, dq: np.ndarray) -> np.ndarray:
    """``q ⊕ dq`` with a floating base on ``R³ × SO(3)``: its origin moves along the world
    velocity ``R v`` in a straight line, its rotation by ``exp(ω dt)`` (MuJoCo's rule).

    Pinocchio's ``integrate`` moves the base along the screw of ``SE(3)``'s exponential: a
    rolling ball's body twist is a rotation about its contact point, so its centre would
    dip by ``r (1 − cos ω dt)`` into the plane every step.

    Args:
        robot: The robot.
        q: The configuration, shape (nq,).
        dq: The displacement ``dt v``, shape (nv,), in [rad] / [m]; a floating base's first
            six: its origin's displacement in [m] then its rotation vector in [rad], both in
            the base's own axes (Pinocchio's free-flyer velocity convention).

    Returns:
        The moved configuration, shape (nq,).
    """
    moved = pin.integrate(robot.model, q, dq)
    if robot.floating_base:
        rotation = pin.Quaternion(q[3:7]).toRotationMatrix()
        moved[:3] = q[:3] + rotation @ dq[:3]
    return moved


def finish_step(
    robot: Robot, q: np.ndarray, dt: float, ground: Ground, settings: ContactSettings, guess: np.ndarray | None,
    terms: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
    limits: tuple[LimitRows | None, np.ndarray | None, np.ndarray | None],
) -> ContactStep:  # fmt: skip
    """The step from its ``gaps``, ``J``, the free velocity and ``M⁻¹ Jᵀ`` (the points' rows,
    then the limit rows ``near`` in reach, :mod:`robodyn.sim.contact_limits`): the impulses, ``v⁺``, ``q⁺``.

    Args:
        robot: The robot.
        q: The configuration at the start, shape (nq,).
        dt: Step in [s].
        ground: The plane (its friction and contact axes).
        settings: Solver settings.
        guess: The previous step's impulses (k, 3), or ``None``.
        terms: ``(gaps, J, free, M⁻¹ Jᵀ)``: the rows' gaps (k + r,) in [m], their Jacobian
            (3(k + r), nv), the velocity without contact ``v + dt M⁻¹ (τ − h)`` (nv,) and
            ``M⁻¹ Jᵀ`` (nv, 3(k + r)).
        limits: ``(rows, near, held)``: the limit rows (or ``None``), the indices of those in
            reach (or ``None``) and their previous impulses (r,) (or ``None``).
    """
    gaps, jacobian, free, response = terms
    rows, near, held = limits
    velocity = jacobian @ free
    beta = settings.baumgarte
    velocity[2::3] += [gap / dt if gap >= 0.0 else beta * gap / dt for gap in gaps.tolist()]
    delassus = jacobian @ response
    extra = 0 if near is None else len(near)
    count = len(gaps) - extra
    if extra:  # each limit row's tangent rows decoupled, of the normal row's diagonal
        first = 3 * count + 3 * np.arange(extra)
        delassus[first, first] = delassus[first + 1, first + 1] = delassus[first + 2, first + 2]
        if guess is not None:
            start = np.zeros((count + extra, 3))
            start[:count] = guess.reshape(count, 3)
            start[count:, 2] = 0.0 if held is None else held[near]
            guess = start
    dofs = jacobian.shape[1] + 2 * extra  # (each limit's decoupled tangent rows add two to A's rank)
    impulses, iterations, converged = solve_impulses(delassus, velocity, ground.friction, settings, guess, dofs=dofs)
    v_next = free + response @ impulses
    local = impulses.reshape(-1, 3)
    after = (jacobian[: 3 * count] @ v_next).reshape(-1, 3)
    limit_impulses = None if rows is None else np.zeros(len(rows.bound))
    if limit_impulses is not None and extra:
        limit_impulses[near] = local[count:, 2]
    return ContactStep(
        integrate(robot, q, dt * v_next), v_next, local[:count], local[:count] @ ground.frame() / dt, gaps[:count],
        np.hypot(after[:, 0], after[:, 1]), iterations, converged, limit_impulses,
    )  # fmt: skip
