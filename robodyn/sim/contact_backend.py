"""The Pinocchio backend's contact runs: a plan with a ground, stepped by :mod:`robodyn.sim.contact`.

The plan's controller (sampled once a step) and external wrenches give the torques; the
joints' damping acts when the plan's ``friction`` does. The run's arrays go back to the
engine like any run's; the contact forces ride along in :attr:`Outcome.contact`.
"""

from __future__ import annotations

from time import perf_counter

import numpy as np

from robodyn.compiled.simulation import SimulationArrays
from robodyn.sim.contact_run import run_contacts
from robodyn.sim.plan import Outcome, RunPlan, external_torques


def run(plan: RunPlan) -> Outcome:
    """Run a plan that has a ground (``plan.ground`` and ``plan.contacts`` set).

    Args:
        plan: The checked run (:class:`~robodyn.sim.plan.RunPlan`) with its ground and contact points.
    """
    assert plan.ground is not None and plan.contacts is not None  # the caller's branch
    robot, controller, external = plan.robot, plan.controller, plan.external

    def torques(t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        tau = np.zeros(robot.nv) if controller is None else np.asarray(controller(t, q, v), dtype=float)
        return tau + external_torques(robot, q, t, external) if external else tau

    began = perf_counter()
    contact = run_contacts(
        robot,
        plan.ground,
        plan.contacts,
        torques,
        plan.q0,
        plan.v0,
        plan.steps,
        plan.dt,
        joint_friction=plan.friction,
        limits=plan.limits == "enforce",
    )
    loop_time = perf_counter() - began
    trajectory = contact.trajectory
    assert trajectory.tau is not None  # a contact run records its torques
    arrays = SimulationArrays(trajectory.t, trajectory.q, trajectory.v, trajectory.a, trajectory.tau)
    return Outcome(arrays, loop_time, contact=contact)


__all__ = ["run"]
