"""Where a run that drives a frame left it (:func:`robodyn.sim.experiment.run_simulation`'s
task-space, operational-space and impedance runs): the final position and attitude error
against the target, by the plant's forward kinematics, and an impedance's deflection under
a push against ``K⁻¹ F``, as a :class:`~robodyn.sim.report.TaskOutcome`.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pinocchio as pin

from robodyn.dynamics.robot import Robot
from robodyn.sim.operational_space import Impedance, OperationalSpace, orientation_error, target_rotation
from robodyn.sim.report import Push, TaskOutcome
from robodyn.trajectory import Trajectory

#: Final task error below which a target counts as reached, in [m] (and [rad]).
REACHED = 1e-3


def task_outcome(robot: Robot, trajectory: Trajectory, frame: str, task: np.ndarray) -> TaskOutcome:
    """Where a task-space run left ``frame``, against the target ``task`` in [m].

    Args:
        robot: The simulated robot.
        trajectory: The run.
        frame: The controlled frame.
        task: The target position in [m], shape (3,).
    """
    position = robot.frame_position(trajectory.q[-1], frame)
    error = float(np.linalg.norm(position - task))
    return TaskOutcome(frame, tuple(task.tolist()), tuple(position.tolist()), error, error < REACHED)


def frame_pose(robot: Robot, q: np.ndarray, frame: str) -> tuple[np.ndarray, np.ndarray]:
    """A frame's position in [m] (3,) and attitude (3, 3), by the robot's forward kinematics.

    Args:
        robot: The robot.
        q: Configuration, shape (nq,), in [rad] / [m].
        frame: The frame's name.
    """
    model, data = robot.model, robot.data
    pin.framesForwardKinematics(model, data, np.asarray(q, dtype=float))
    placement = data.oMf[robot.frame_id(frame)]
    return placement.translation.copy(), placement.rotation.copy()


def pose_outcome(
    robot: Robot, trajectory: Trajectory, law: OperationalSpace | Impedance, pushes: tuple[Push, ...]
) -> TaskOutcome:
    """Where an osc or impedance run left its frame (the plant's forward kinematics), and an
    impedance's deflection against ``K⁻¹ F`` when every push acts at that frame.

    Args:
        robot: The simulated robot.
        trajectory: The run.
        law: The run's operational-space or impedance controller (its frame and target).
        pushes: The pushes applied during the run.
    """
    frame = str(law.frame)
    target = np.asarray(law.position, dtype=float)
    position, rotation = frame_pose(robot, trajectory.q[-1], frame)
    error = float(np.linalg.norm(position - target))
    rpy = None if law.orientation is None else np.asarray(law.orientation, dtype=float)
    angle = None if rpy is None else float(np.linalg.norm(orientation_error(rotation, target_rotation(rpy))))
    outcome = TaskOutcome(
        frame, tuple(target.tolist()), tuple(position.tolist()), error, error < REACHED and (angle or 0.0) < REACHED,
        None if rpy is None else tuple(rpy.tolist()), angle,
    )  # fmt: skip
    end = float(trajectory.t[-1])
    acting = [push for push in pushes if push.time <= end]
    if not isinstance(law, Impedance) or not acting or any(push.frame != frame for push in acting):
        return outcome
    force = np.sum([push.force for push in acting], axis=0)
    expected = force / np.asarray(law.stiffness, dtype=float)[:3]
    deflection = position - target
    relative = float(np.linalg.norm(deflection - expected) / max(float(np.linalg.norm(expected)), 1e-300))
    return replace(
        outcome, deflection=tuple(deflection.tolist()), expected_deflection=tuple(expected.tolist()), deflection_error=relative
    )
