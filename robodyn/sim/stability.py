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
"""

from __future__ import annotations

import numpy as np

from robodyn.compiled.controllers import HasTwin
from robodyn.exceptions import RobodynError
from robodyn.sim.linearize import linearize
from robodyn.sim.operational_space import OperationalSpace
from robodyn.sim.plan import RunPlan

#: ``|λ| dt`` at the edge of each integrator's stability region (RK4: the real-axis limit).
STABLE_RATE = {"rk4": 2.78, "semi-implicit-euler": 2.0}
#: Relative step of the central differences of a controller.
_DIFFERENCE = 1e-6


def largest_stable_step(plan: RunPlan) -> tuple[float, str, str] | None:
    """The largest stable step in [s] at the plan's start, the joint its fastest mode moves
    most and that mode's likely cause; ``None`` when the start cannot be linearized (a
    singular mass matrix: the run reports its own error)."""
    try:
        fastest, joint, cause = _rates(plan)
    except (RobodynError, np.linalg.LinAlgError, FloatingPointError, ValueError):
        return None
    return (STABLE_RATE[plan.integrator] / fastest if fastest > 0 else float("inf")), joint, cause


def step_warning(plan: RunPlan) -> str | None:
    """One sentence when ``plan.dt`` exceeds the largest stable step at the start, else ``None``."""
    found = largest_stable_step(plan)
    if found is None or plan.dt <= found[0]:
        return None
    limit, joint, cause = found
    fastest = STABLE_RATE[plan.integrator] / limit
    return (
        f"{plan.robot.name}: dt = {plan.dt:.3g} s is above the largest stable step of its fastest mode at the start, "
        f"about {limit:.2g} s ({fastest:.3g} 1/s, mostly joint {joint!r}, set by {cause}): the run will likely "
        f"diverge; use dt <= {limit:.2g} s"
    )


def _rates(plan: RunPlan) -> tuple[float, str, str]:
    """The fastest closed-loop rate in [1/s], the joint its mode moves most, and its cause."""
    robot, q, v = plan.robot, plan.q0, plan.v0
    controller = plan.controller if isinstance(plan.controller, HasTwin) else None
    tau = np.zeros(robot.nv) if controller is None else np.asarray(controller(0.0, q, v), dtype=float)
    damped = plan.friction and not plan.coulomb
    A, B = linearize(robot, q, v, tau, joint_friction=damped)
    closed = A if controller is None else A + B @ _feedback(plan, tau)
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


def _feedback(plan: RunPlan, tau: np.ndarray) -> np.ndarray:
    """``[∂τ/∂q, ∂τ/∂v]`` of the controller at the start (q in the tangent space), shape (nv, 2 nv)."""
    robot, q, v, controller = plan.robot, plan.q0, plan.v0, plan.controller
    assert controller is not None
    columns = []
    for which in ("q", "v"):
        for i in range(robot.nv):
            step = np.zeros(robot.nv)
            step[i] = h = _DIFFERENCE * max(1.0, abs(float(v[i])) if which == "v" else 1.0)
            if which == "q":
                plus, minus = controller(0.0, robot.integrate(q, step), v), controller(0.0, robot.integrate(q, -step), v)
            else:
                plus, minus = controller(0.0, q, v + step), controller(0.0, q, v - step)
            columns.append((np.asarray(plus, dtype=float) - np.asarray(minus, dtype=float)) / (2 * h))
    return np.array(columns).T


def task_warning(plan: RunPlan) -> str | None:
    """One sentence when an operational-space task starts at (or near) a singularity: its
    smallest singular value (:meth:`OperationalSpace.singular_value`) below the threshold of
    the law's variable damping (:mod:`robodyn.sim.task_damping`), a stretched or folded arm."""
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
