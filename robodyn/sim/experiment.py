"""A simulation experiment: a robot, a controller aiming at a target, and what came of it.

:func:`run_simulation` builds the chosen controller (on its own copy of the model),
simulates, and returns the trajectory with a summary with units: final error, peak torque, energy drift, real-time factor,
and the joints that left their limits (the simulation has no joint stops or contacts).
Used by ``robodyn simulate``.
"""

from __future__ import annotations

import time

import numpy as np

from robodyn.dynamics.loading import rebuild
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError
from robodyn.sim.control import ComputedTorque, PDGravity, TaskSpace, quintic_reference
from robodyn.sim.simulation import Trajectory, simulate

CONTROLLERS = ("passive", "pd", "computed-torque", "task-space")


def controller_model(robot: Robot) -> Robot:
    """An independent copy of the robot for a controller (same URDF, its own data)."""
    return rebuild(robot)


def task_target(values: list[float] | np.ndarray) -> np.ndarray:
    """A task-space target from ``X,Z`` (planar arms, ``Y = 0``) or ``X,Y,Z``, in [m]."""
    values = np.asarray(values, dtype=float)
    if values.shape == (2,):
        return np.array([values[0], 0.0, values[1]])
    if values.shape == (3,):
        return values
    raise InputError("--target", "X,Z or X,Y,Z in [m] for task-space control", f"{values.size} values")


def run_simulation(
    robot: Robot,
    *,
    controller: str = "passive",
    target: list[float] | None = None,
    frame: str | None = None,
    q0: list[float] | None = None,
    duration: float = 3.0,
    dt: float = 1e-3,
    integrator: str = "rk4",
) -> tuple[Trajectory, dict]:
    """Simulate ``robot`` under a named controller and summarise.

    Args:
        robot: The plant.
        controller: ``"passive"``, ``"pd"`` (PD + gravity to a joint target),
            ``"computed-torque"`` (quintic from ``q0`` to a joint target in half the
            duration) or ``"task-space"`` (drive ``frame`` to a position target).
        target: Joint target (nq values) or task target (X,Z or X,Y,Z in [m]).
        frame: Controlled frame for task-space control.
        q0: Initial configuration; default neutral.
        duration, dt, integrator: As for :func:`robodyn.simulate`.

    Returns:
        The trajectory and a JSON-ready summary with units in the keys.
    """
    if controller not in CONTROLLERS:
        raise InputError("controller", f"one of {', '.join(CONTROLLERS)}", repr(controller))
    if controller != "passive" and target is None:
        raise InputError("--target", f"given for the {controller} controller", "nothing")
    start = robot.neutral_configuration() if q0 is None else np.asarray(q0, dtype=float)
    task = None
    law = None
    if controller == "pd":
        law = PDGravity(controller_model(robot), np.asarray(target, float))
    elif controller == "computed-torque":
        law = ComputedTorque(controller_model(robot), quintic_reference(start, np.asarray(target, float), duration / 2))
    elif controller == "task-space":
        task = task_target(target)
        law = TaskSpace(controller_model(robot), frame, task)
    if law is not None and controller != "task-space" and np.size(target) != robot.nq:
        raise InputError("--target", f"{robot.nq} joint values for the {controller} controller", f"{np.size(target)} values")
    began = time.perf_counter()
    trajectory = simulate(robot, start, np.zeros(robot.nv), duration, dt, controller=law, integrator=integrator)
    elapsed = time.perf_counter() - began
    energy = robot.kinetic_energy(trajectory.q, trajectory.v) + robot.potential_energy(trajectory.q)
    summary: dict = {
        "robot": robot.name,
        "controller": controller,
        "integrator": integrator,
        "duration_s": duration,
        "dt_s": dt,
        "real_time_factor": duration / elapsed if elapsed > 0 else float("inf"),
        "final_q": trajectory.q[-1].tolist(),
        "peak_abs_torque": np.abs(trajectory.tau).max(axis=0).tolist(),
        "energy_change_J": float(energy[-1] - energy[0]),
    }
    if task is not None:
        position = robot.frame_position(trajectory.q[-1], frame)
        summary["frame"] = frame
        summary["target_m"] = task.tolist()
        summary["final_position_m"] = position.tolist()
        summary["final_error_m"] = float(np.linalg.norm(position - task))
    elif controller != "passive":
        summary["final_joint_error"] = float(np.abs(trajectory.q[-1] - np.asarray(target, float)).max())
    joints = robot.joints[1:] if robot.floating_base else robot.joints
    positions = trajectory.q[:, robot.nq - len(joints) :]
    summary["joint_limit_violations"] = [
        joint.name
        for index, joint in enumerate(joints)
        if positions[:, index].min() < joint.lower - 1e-9 or positions[:, index].max() > joint.upper + 1e-9
    ]
    return trajectory, summary
