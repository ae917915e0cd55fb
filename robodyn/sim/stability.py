"""The step against the fastest mode: warn at the start of a run that will likely diverge.

An explicit integrator is stable only while ``|λ| dt`` stays inside its stability region, for
every eigenvalue ``λ`` of the closed loop: about 2.78 for RK4 (2.785 on the real axis, 2.83 on
the imaginary one), 2 for semi-implicit Euler. :func:`step_warning` linearizes the plant at
the run's start (:func:`robodyn.sim.linearize.linearize`, the joints' damping included when it
acts) and, for the library's controllers (those that own a compiled twin: pure functions of
``(t, q, v)``), their feedback by central differences; a user's function is not called
(it may count its calls), so only the plant's own modes are checked for it. When ``dt``
exceeds the largest stable step it returns one sentence: the step it should be, the fastest
mode's rate, the joint that mode moves most, and its likely cause (the controller's gains or
the joints' damping). It never changes the run.

Most runs are far inside the region, and every :func:`robodyn.simulate` call asks, so a
screen goes first (:func:`clearly_stable`): one call of the plant's analytical derivatives
and an upper bound on the spectral radius of ``A`` (the infinity norm of ``A`` under a
diagonal similarity, no eigenvalues, no second linearisation). When that bound, with a
margin, already fits the step, no warning can follow and the check stops there (tens of
microseconds instead of hundreds); otherwise the eigenvalues decide, as before.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import NamedTuple

import numpy as np
import pinocchio as pin

from robodyn.compiled.controllers import HasTwin
from robodyn.exceptions import RobodynError
from robodyn.sim.linearize import linearize
from robodyn.sim.operational_space import OperationalSpace
from robodyn.sim.plan import RunPlan

#: ``|λ| dt`` at the edge of each integrator's stability region (RK4: the real-axis limit).
STABLE_RATE = {"rk4": 2.78, "semi-implicit-euler": 2.0}
#: Relative step of the central differences of a controller.
_DIFFERENCE = 1e-6
#: The screen passes a step only when the bound times this margin fits (room for the
#: eigenvalues' own rounding, which the bound does not see).
SCREEN_MARGIN = 1.25
#: The similarity scales :func:`spectral_bound` tries, relative to ``√max by_q``.
_SCALES = 2.0 ** np.arange(-4.0, 5.0)


#: A controller's torque as a function of the state alone, ``tau(q, v)`` at t = 0, in [N m] / [N].
Torque = Callable[[np.ndarray, np.ndarray], np.ndarray]
#: What the check catches at the start: it then says nothing (the run reports its own error).
_FAILURES = (RobodynError, np.linalg.LinAlgError, FloatingPointError, ValueError)


class _Start(NamedTuple):
    """The closed loop at the plan's start: the library controller (``None``: the plant
    alone), its torque there and its feedback ``[∂τ/∂q, ∂τ/∂v]`` (nv, 2 nv), computed once."""

    controller: HasTwin | None
    tau: np.ndarray
    feedback: np.ndarray | None


def largest_stable_step(plan: RunPlan) -> tuple[float, str, str] | None:
    """The largest stable step in [s] at the plan's start, the joint its fastest mode moves
    most and that mode's likely cause; ``None`` when the start cannot be linearized (a
    singular mass matrix: the run reports its own error).

    Args:
        plan: The checked simulation request (robot, controller, options).
    """
    try:
        return _largest(plan, _start(plan))
    except _FAILURES:
        return None


def step_warning(plan: RunPlan, law: Torque | None = None) -> str | None:
    """One sentence when ``plan.dt`` exceeds the largest stable step at the start, else ``None``
    (at once when :func:`clearly_stable` says the step fits).

    Args:
        plan: The run.
        law: The plan's library controller as ``tau(q, v)`` at t = 0 evaluated elsewhere (its
            compiled twin: microseconds a call), for the screen's feedback only; a step it does
            not clear is judged on the controller itself, as without it.
    """
    try:
        if law is not None and clearly_stable(plan, _start(plan, law)):
            return None
        start = _start(plan)
        found = None if law is None and clearly_stable(plan, start) else _largest(plan, start)
    except _FAILURES:
        return None
    if found is None or plan.dt <= found[0]:
        return None
    limit, joint, cause = found
    fastest = STABLE_RATE[plan.integrator] / limit
    return (
        f"{plan.robot.name}: dt = {plan.dt:.3g} s is above the largest stable step of its fastest mode at the start, "
        f"about {limit:.2g} s ({fastest:.3g} 1/s, mostly joint {joint!r}, set by {cause}): the run will likely "
        f"diverge; use dt <= {limit:.2g} s (e.g. {round_step(limit):g} s)"
    )


def round_step(limit: float) -> float:
    """The largest step of the 1-2-5 series (…, 1e-5, 2e-5, 5e-5, 1e-4, …) at most ``limit``:
    a step to type that divides the usual durations (1.2e-5 s would leave 0.1 s a fraction
    of a step, which a run refuses).

    Args:
        limit: The largest stable step, in [s] (> 0).
    """
    decade = 10.0 ** math.floor(math.log10(limit))
    return max(factor * decade for factor in (1.0, 2.0, 5.0) if factor * decade <= limit * (1 + 1e-12))


def clearly_stable(plan: RunPlan, start: _Start | None = None) -> bool:
    """Whether an upper bound on the fastest rate at the plan's start already fits its step:
    :func:`spectral_bound` of the closed loop ``A + B K`` (``K`` the library controller's
    feedback; the plant alone for a user's controller, which the check never calls), from one
    call of the plant's analytical derivatives.

    Args:
        plan: The run.
        start: Its closed loop at the start, when already computed (``None``: computed here).

    Raises:
        RobodynError: If the derivatives fail there (a singular mass matrix).
    """
    start = _start(plan) if start is None else start
    robot, q, v, nv = plan.robot, plan.q0, plan.v0, plan.robot.nv
    damping = robot.joint_damping if plan.friction and not plan.coulomb else np.zeros(nv)
    by_q, by_v, inverse = robot.forward_dynamics_derivatives(q, v, start.tau - damping * v)
    by_v = by_v - inverse * damping
    if start.feedback is not None:
        by_q, by_v = by_q + inverse @ start.feedback[:, :nv], by_v + inverse @ start.feedback[:, nv:]
    top = float(np.abs(pin.Motion(v[:6]).action).sum(axis=1).max()) if robot.floating_base else 0.0
    bound = spectral_bound(top, np.abs(by_q).sum(axis=1), np.abs(by_v).sum(axis=1))
    return bool(plan.dt * bound * SCREEN_MARGIN <= STABLE_RATE[plan.integrator])


def spectral_bound(top: float, by_q: np.ndarray, by_v: np.ndarray) -> float:
    """An upper bound on the spectral radius of ``A = [[T, I], [Q, V]]`` (each block nv × nv).

    For any ``s > 0``, ``diag(s I, I) A diag(s I, I)⁻¹ = [[T, s I], [Q / s, V]]`` has A's
    eigenvalues, and its infinity norm (largest absolute row sum) bounds them:
    ``max(top + s, maxᵢ(by_qᵢ / s + by_vᵢ))``. The least of a few ``s`` around ``√max by_q``.

    Args:
        top: Largest absolute row sum of ``T`` (0 for a fixed base).
        by_q, by_v: Absolute row sums of ``Q`` and ``V``, shape (nv,).

    Returns:
        The bound in [1/s] (``inf`` for non-finite rows).
    """
    scales = np.sqrt(max(float(by_q.max(initial=0.0)), 1e-300)) * _SCALES
    bounds = np.maximum(top + scales, (by_q / scales[:, None] + by_v).max(axis=1, initial=0.0))
    best = float(bounds.min())
    return best if np.isfinite(best) else float("inf")


def _start(plan: RunPlan, law: Torque | None = None) -> _Start:
    """The controller, torque and feedback at the plan's start (a user's controller: none),
    the controller evaluated by ``law`` when given (its twin), else called at t = 0."""
    given = plan.controller
    controller = given if given is not None and isinstance(given, HasTwin) else None
    if controller is None:
        return _Start(None, np.zeros(plan.robot.nv), None)
    torque: Torque = law if law is not None else (lambda q, v: controller(0.0, q, v))
    tau = np.asarray(torque(plan.q0, plan.v0), dtype=float)
    return _Start(controller, tau, _feedback(plan, torque))


def _largest(plan: RunPlan, start: _Start) -> tuple[float, str, str]:
    """:func:`largest_stable_step` from the start's closed loop, by its eigenvalues."""
    fastest, joint, cause = _rates(plan, start)
    return (STABLE_RATE[plan.integrator] / fastest if fastest > 0 else float("inf")), joint, cause


def _rates(plan: RunPlan, start: _Start) -> tuple[float, str, str]:
    """The fastest closed-loop rate in [1/s], the joint its mode moves most, and its cause."""
    robot, q, v = plan.robot, plan.q0, plan.v0
    controller, tau = start.controller, start.tau
    damped = plan.friction and not plan.coulomb
    A, B = linearize(robot, q, v, tau, joint_friction=damped)
    closed = A if start.feedback is None else A + B @ start.feedback
    values, vectors = np.linalg.eig(closed)
    index = int(np.argmax(np.abs(values)))
    fastest = float(np.abs(values[index]))
    dof = int(np.argmax(np.abs(vectors[: robot.nv, index]) + np.abs(vectors[robot.nv :, index])))
    joint = robot.dofs[dof].name
    if controller is not None and float(np.abs(np.linalg.eigvals(A)).max()) < 0.5 * fastest:
        return fastest, joint, f"the {type(controller).__name__} gains"
    if damped and robot.joint_damping.any():
        rigid = float(np.abs(np.linalg.eigvals(linearize(robot, q, v, tau, joint_friction=False)[0])).max())
        if rigid < 0.5 * fastest:
            return fastest, joint, "the joints' damping on light links"
    return fastest, joint, "the robot's own dynamics"


def _feedback(plan: RunPlan, torque: Torque) -> np.ndarray:
    """``[∂τ/∂q, ∂τ/∂v]`` of the controller at the start (q in the tangent space), shape (nv, 2 nv).

    ``q ⊕ step`` is :meth:`Robot.integrate`'s arithmetic on the plan's checked ``q`` (Pinocchio's
    ``integrate`` for a floating base, else addition) without its input checks."""
    robot, q, v = plan.robot, plan.q0, plan.v0
    model = robot.model
    plus = (lambda step: pin.integrate(model, q, step)) if robot.floating_base else (lambda step: q + step)
    columns = []
    for which in ("q", "v"):
        for i in range(robot.nv):
            step = np.zeros(robot.nv)
            step[i] = h = _DIFFERENCE * max(1.0, abs(float(v[i])) if which == "v" else 1.0)
            if which == "q":
                plus_torque, minus_torque = torque(plus(step), v), torque(plus(-step), v)
            else:
                plus_torque, minus_torque = torque(q, v + step), torque(q, v - step)
            columns.append((np.asarray(plus_torque, dtype=float) - np.asarray(minus_torque, dtype=float)) / (2 * h))
    return np.array(columns).T


def task_warning(plan: RunPlan) -> str | None:
    """One sentence when an operational-space task starts at (or near) a singularity: its
    smallest singular value (:meth:`OperationalSpace.singular_value`) below the threshold of
    the law's variable damping (:mod:`robodyn.sim.task_damping`), a stretched or folded arm.

    Args:
        plan: The checked simulation request (robot, controller, options).
    """
    law = plan.controller
    if not isinstance(law, OperationalSpace) or law.frame is None:
        return None
    sigma = law.singular_value(plan.q0)
    if sigma >= law.singular_threshold:
        return None
    start = (
        f"{plan.robot.name}: the operational-space task of {law.frame!r} starts near a singularity (its weakest "
        f"direction {sigma:.2g} of the chain's length, below {law.singular_threshold:g}: a stretched or folded arm)"
    )
    if law.singular_damping == 0:
        return start + "; with singular_damping=0 its torques can grow without bound: start away from it, or keep the default"
    return start + (
        f"; its task inertia is damped there (up to {law.singular_damping:g} of its largest eigenvalue), so torques "
        "stay bounded but the task is followed loosely until the arm leaves it"
    )
