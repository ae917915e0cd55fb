"""The Pinocchio backend's constrained runs: a plan whose robot has constraints (closed loops,
welds: :attr:`robodyn.Robot.constraints`), stepped by :mod:`robodyn.sim.constrained`.

RK4 on the constrained accelerations, then the state projected back onto ``Φ(q) = 0`` and
``J v = 0`` after each step (the module's stated stabilisation); the initial state is
projected first. The plan's controller (evaluated at every stage) and external wrenches give
the torques, and the joints' viscous damping acts (``−b v``) when the plan's ``friction``
does. The run's arrays go back to the engine like any run's, with
its multipliers and residual (:class:`robodyn.sim.constrained.ConstrainedSimulation`: the
summary's lines, the CSV's ``lambda[...]`` columns).
"""

from __future__ import annotations

from time import perf_counter

import numpy as np

from robodyn.compiled.simulation import SimulationArrays
from robodyn.sim.constrained import simulate_constrained
from robodyn.sim.plan import Outcome, RunPlan, external_torques


def run(plan: RunPlan) -> Outcome:
    """Run a plan whose robot has constraints (the plan refused what this loop does not model).

    Args:
        plan: The run plan (its robot has constraints; RK4, no ground, no observer).
    """
    robot, controller, external = plan.robot, plan.controller, plan.external
    damping = robot.joint_damping if plan.friction else None

    def torques(t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        tau = np.zeros(robot.nv) if controller is None else np.asarray(controller(t, q, v), dtype=float)
        if external:
            tau = tau + external_torques(robot, q, t, external)
        return tau if damping is None else tau - damping * v

    began = perf_counter()
    result = simulate_constrained(robot, plan.q0, plan.v0, duration=plan.steps * plan.dt, dt=plan.dt, tau=torques)
    loop_time = perf_counter() - began
    trajectory = result.trajectory
    assert trajectory.tau is not None  # a constrained run records its torques
    arrays = SimulationArrays(trajectory.t, trajectory.q, trajectory.v, trajectory.a, trajectory.tau)
    return Outcome(arrays, loop_time, constrained=result)


__all__ = ["run"]
