"""The Pinocchio backend: a run plan integrated in Python over Pinocchio's ABA.

It models everything a plan can ask (external wrenches, enforced limits, an observer,
stick–slip joint friction, a controller evaluated at every stage or sampled, a ground:
:mod:`robodyn.sim.contact_backend`): :func:`unsupported` names nothing.
"""

from __future__ import annotations

from collections.abc import Sequence
from time import perf_counter

import numpy as np

from robodyn.compiled.simulation import SimulationArrays
from robodyn.dynamics.inertia_rank import inertialess_joints
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import SingularMassMatrixError
from robodyn.sim import constrained_backend, contact_backend
from robodyn.sim.joint_friction import JointFriction
from robodyn.sim.limits import JointLimits
from robodyn.sim.plan import Controller, ExternalWrench, Outcome, RunPlan, external_torques
from robodyn.sim.python_loop import Forward, Stepper, integrate, singular


def unsupported(plan: RunPlan) -> list[str]:
    """What this backend cannot run of a plan, each reason one phrase: nothing.

    Args:
        plan: The checked simulation request.
    """
    return []


def run(plan: RunPlan) -> Outcome:
    """Integrate the plan over Pinocchio's ABA.

    Args:
        plan: The checked simulation request (robot, controller, options).

    Raises:
        SingularMassMatrixError: If the mass matrix is singular at the start (massless
            moving bodies, or point masses some joints turn about one line: named).
        SimulationError: If the state stops being finite (``ControllerFailedError``: if
            the controller's own numerics fail).
    """
    robot = plan.robot
    if robot.massless_joints:
        raise SingularMassMatrixError(robot.name, robot.massless_joints)
    if singular(robot, plan.q0):  # point masses behind joints that turn them about one line
        raise SingularMassMatrixError(robot.name, inertialess_joints(robot, plan.q0), inertialess=True)
    if plan.ground is not None:
        return contact_backend.run(plan)  # on the ground: robodyn.sim.contact's step
    if robot.constraints:
        return constrained_backend.run(plan)  # closed loops and welds: robodyn.sim.constrained
    joint_limits = JointLimits(robot)
    enforce = plan.limits == "enforce"
    controller = _saturated(plan.controller, joint_limits) if enforce else plan.controller
    friction = JointFriction(robot) if plan.friction else None
    stepper = Stepper(
        robot, accelerator(robot, plan.external), controller, hold=plan.every is not None, rk4=plan.rk4,
        observer=plan.observer, every=plan.every or 1, friction=friction,
    )  # fmt: skip
    if friction is not None:
        friction.start(stepper.accelerate, 0.0, plan.q0, plan.v0, stepper.torque(0.0, plan.q0, plan.v0))
    began = perf_counter()
    arrays = integrate(robot, stepper, plan.q0, plan.v0, plan.steps, plan.dt, joint_limits if enforce else None)
    return Outcome(SimulationArrays(plan.times(), *arrays), perf_counter() - began)


def _saturated(controller: Controller | None, joint_limits: JointLimits) -> Controller | None:
    """The controller with its torque saturated at the effort limits (``limits="enforce"``)."""
    if controller is None:
        return None
    commanded = controller
    return lambda t, q, v: joint_limits.saturate(np.asarray(commanded(t, q, v), dtype=float))


def accelerator(robot: Robot, external: Sequence[ExternalWrench]) -> Forward:
    """``a(t, q, v, tau)``: forward dynamics with the external wrenches' torques added.

    Calls Pinocchio without the boundary checks (the plan checked the state once, and the
    loop checks finiteness each step).

    Args:
        robot: The simulated robot.
        external: The external wrenches.
    """
    forward = robot.forward_dynamics_unchecked
    if not external:
        if robot.mimic is None:  # straight to Pinocchio's ABA
            import pinocchio as pin

            aba, model, data = pin.aba, robot.model, robot.data
            return lambda t, q, v, tau: aba(model, data, q, v, tau)
        return lambda t, q, v, tau: forward(q, v, tau)
    return lambda t, q, v, tau: forward(q, v, tau + external_torques(robot, q, t, external))
