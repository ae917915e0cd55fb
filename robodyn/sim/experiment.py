"""A simulation experiment: a robot, a controller aiming at a target, and what came of it.

:func:`run_simulation` builds the chosen controller (on its own copy of the model),
simulates, and returns the trajectory with a :class:`~robodyn.sim.report.SimulationSummary`:
final error, peak torque, energy change, real-time factor, and every joint limit the run
broke (joint, first time, worst value, limit; ``limits="enforce"`` saturates torques and stops joints,
see :mod:`robodyn.sim.limits`). Used by ``robodyn simulate``.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import replace
from typing import Literal

import numpy as np

from robodyn.dynamics.loading import rebuild
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError, JointLimitWarning
from robodyn.sim.control import ComputedTorque, PDGravity, TaskSpace, quintic_reference
from robodyn.sim.limits import LimitMode, check_mode, limit_violations
from robodyn.sim.reach import check_reach
from robodyn.sim.report import SimulationSummary, TaskOutcome
from robodyn.sim.simulation import Engine, Integrator, simulate
from robodyn.trajectory import Trajectory

#: The controllers a run can use, by name.
ControllerName = Literal["passive", "pd", "computed-torque", "task-space"]
CONTROLLERS: tuple[ControllerName, ...] = ("passive", "pd", "computed-torque", "task-space")
#: Final task error below which a target counts as reached, in [m].
REACHED = 1e-3


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
    raise InputError("target", "X,Z or X,Y,Z in [m] for task-space control", f"{values.size} values")


def run_simulation(
    robot: Robot,
    *,
    controller: ControllerName = "passive",
    target: list[float] | None = None,
    frame: str | None = None,
    q0: list[float] | None = None,
    duration: float = 3.0,
    dt: float = 1e-3,
    integrator: Integrator = "rk4",
    limits: LimitMode = "warn",
    engine: Engine = "pinocchio",
) -> tuple[Trajectory, SimulationSummary]:
    """Simulate ``robot`` under a named controller and summarise.

    Args:
        robot: The plant.
        controller: ``"passive"``, ``"pd"`` (PD + gravity to a joint target),
            ``"computed-torque"`` (quintic from ``q0`` to a joint target in half the
            duration) or ``"task-space"`` (drive ``frame`` to a position target).
        target: Joint target (nq values) or task target (X,Z or X,Y,Z in [m]).
        frame: Controlled frame for task-space control (default the robot's end effector;
            it must be a frame some joint moves).
        q0: Initial configuration; default :meth:`Robot.default_configuration` (the
            neutral one clipped into the joint limits).
        duration, dt, integrator, limits, engine: As for :func:`robodyn.simulate` (with
            ``engine="compiled"`` the task-space controller is sampled every step).

    Returns:
        The trajectory and its :class:`~robodyn.sim.report.SimulationSummary`
        (``violations``: every broken limit, none with ``limits="ignore"``).

    Raises:
        InputError: Naming the parameter (``controller``, ``target``, ``frame``, ...).
    """
    _check_request(robot, controller, target, frame, limits)
    start = robot.default_configuration() if q0 is None else np.asarray(q0, dtype=float)
    law, task, controlled = _control_law(robot, controller, target, frame, start, duration)
    began = time.perf_counter()
    with warnings.catch_warnings():  # the summary reports the violations; the caller warns
        warnings.simplefilter("ignore", JointLimitWarning)
        trajectory = simulate(
            robot, start, np.zeros(robot.nv), duration, dt, controller=law, integrator=integrator, limits=limits, engine=engine
        )
    elapsed = time.perf_counter() - began
    torques = trajectory.tau
    assert torques is not None  # simulate records the applied torques
    energy = np.atleast_1d(robot.kinetic_energy(trajectory.q, trajectory.v)) + np.atleast_1d(robot.potential_energy(trajectory.q))
    summary = SimulationSummary(
        robot=robot.name, controller=controller, integrator=integrator, limits=limits, engine=engine,
        duration=duration, dt=dt, steps=len(trajectory) - 1,
        real_time_factor=duration / elapsed if elapsed > 0 else None,
        joint_names=tuple(robot.joint_names),
        dof_names=tuple(dof.name for dof in robot.dofs),
        final_q=tuple(trajectory.q[-1].tolist()),
        peak_abs_torque=tuple(np.abs(torques).max(axis=0).tolist()),
        torque_units=tuple(dof.effort_unit for dof in robot.dofs),
        energy_change=float(energy[-1] - energy[0]),
        violations=() if limits == "ignore" else tuple(limit_violations(robot, trajectory)),
    )  # fmt: skip
    if task is not None:
        return trajectory, replace(summary, task=_task_outcome(robot, trajectory, controlled, task))
    if controller != "passive":
        error = float(np.abs(trajectory.q[-1] - np.asarray(target, float)).max())
        return trajectory, replace(summary, final_joint_error=error)
    return trajectory, summary


def _check_request(robot: Robot, controller: str, target: list[float] | None, frame: str | None, limits: str) -> None:
    """Refuse an unknown controller or limits mode, and a target or frame it does not take."""
    if controller not in CONTROLLERS:
        raise InputError("controller", f"one of {', '.join(CONTROLLERS)}", repr(controller))
    check_mode(limits)
    if controller != "passive" and target is None:
        raise InputError("target", f"given for the {controller} controller", "nothing")
    if controller == "passive" and target is not None:
        raise InputError("target", "given only with a controller (the passive run has no target)", f"{np.size(target)} values")
    if controller != "task-space" and frame is not None:
        raise InputError("frame", "given only with the task-space controller", repr(frame))


def _control_law(
    robot: Robot, controller: str, target: list[float] | None, frame: str | None, start: np.ndarray, duration: float
) -> tuple[PDGravity | ComputedTorque | TaskSpace | None, np.ndarray | None, str]:
    """The controller (on its own model), the task target in [m] and the controlled frame
    (task-space control only: ``None`` and ``""`` otherwise)."""
    law: PDGravity | ComputedTorque | TaskSpace | None = None
    task, controlled = None, ""
    if controller == "pd":
        law = PDGravity(controller_model(robot), np.asarray(target, float))
    elif controller == "computed-torque":
        law = ComputedTorque(controller_model(robot), quintic_reference(start, np.asarray(target, float), duration / 2))
    elif controller == "task-space":
        assert target is not None  # checked by _check_request
        task = task_target(target)
        controlled = robot.task_frame(frame, "task-space control")
        check_reach(robot, controlled, task, parameter="target")
        law = TaskSpace(controller_model(robot), controlled, task)
    given = 0 if target is None else int(np.size(np.asarray(target, dtype=float)))
    if controller in ("pd", "computed-torque") and given != robot.nq:
        raise InputError("target", f"{robot.nq} joint values for the {controller} controller", f"{given} values")
    return law, task, controlled


def _task_outcome(robot: Robot, trajectory: Trajectory, frame: str, task: np.ndarray) -> TaskOutcome:
    """Where the run left ``frame``, against the target ``task`` in [m]."""
    position = robot.frame_position(trajectory.q[-1], frame)
    error = float(np.linalg.norm(position - task))
    return TaskOutcome(frame, tuple(task.tolist()), tuple(position.tolist()), error, error < REACHED)
