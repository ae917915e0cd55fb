"""A run's requests in the forms the command line writes them: task and pose targets, pushes.

``X,Z`` or ``X,Y,Z`` task targets (:func:`task_target`; ``X,Z`` only for a frame that stays
in the plane ``Y = 0``: :func:`check_planar`), ``X,Y,Z[,ROLL,PITCH,YAW]`` pose targets
(:func:`pose_target`) and pushes ``T:FX,FY,FZ[@FRAME]`` (:func:`parse_push`), which become
external wrenches stepping on at their time (:func:`push_wrenches`), and a recorded motion to
track (:class:`TrajectoryReference`, :func:`tracked`). Used by
:func:`robodyn.sim.experiment.run_simulation`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from robodyn.common.text import counted
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError
from robodyn.sim.observer import MomentumObserver
from robodyn.sim.plan import ExternalWrench, external_torques
from robodyn.sim.report import ObserverOutcome, Push
from robodyn.trajectory import Trajectory


def task_target(values: list[float] | np.ndarray) -> np.ndarray:
    """A task-space target from ``X,Z`` (planar arms, ``Y = 0``) or ``X,Y,Z``, in [m].

    Args:
        values: 2 (``X,Z``) or 3 (``X,Y,Z``) numbers, in [m].
    """
    values = np.asarray(values, dtype=float)
    if values.shape == (2,):
        return np.array([values[0], 0.0, values[1]])
    if values.shape == (3,):
        return values
    raise InputError("target", "X,Z or X,Y,Z in [m] for task-space control", counted(values.size, "value"))


def check_planar(robot: Robot, frame: str, q: np.ndarray, size: int) -> None:
    """Refuse an ``X,Z`` target for a frame that does not stay in the plane ``Y = 0``
    (a planar arm in the XY plane, or any 3-D arm): the target would leave ``Y`` at 0.

    Args:
        robot: The controlled robot.
        frame: The task frame's name.
        q: The configuration the frame is checked at, shape (nq,).
        size: How many target values were given (2: ``X,Z``).
    """
    if size != 2:
        return
    sideways = np.abs(robot.frame_jacobian(q, frame)[1]).max(initial=0.0)
    offset = abs(float(robot.frame_position(q, frame)[1]))
    if sideways > 1e-9 or offset > 1e-9:
        raise InputError(
            "target",
            f"3 values X,Y,Z in [m] ({frame!r} moves along or sits off Y = 0; X,Z fits arms in the XZ plane)",
            "2 values",
        )


def pose_target(values: list[float] | np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
    """A pose target from ``X,Y,Z`` (position only) or ``X,Y,Z,ROLL,PITCH,YAW``.

    Args:
        values: 3 or 6 numbers: position in [m], then roll, pitch, yaw in [rad].

    Returns:
        The position in [m], shape (3,), and roll, pitch, yaw in [rad], shape (3,) (``None``
        for a position target).
    """
    values = np.asarray(values, dtype=float)
    if values.shape not in ((3,), (6,)) or not np.isfinite(values).all():
        raise InputError("target", "X,Y,Z in [m] or X,Y,Z,ROLL,PITCH,YAW (rad) for pose control", counted(values.size, "value"))
    return values[:3], (values[3:] if values.size == 6 else None)


def parse_push(text: str) -> Push:
    """A push from ``T:FX,FY,FZ`` or ``T:FX,FY,FZ@FRAME`` (time in [s], force in [N]).

    Args:
        text: The push, e.g. ``"0.5:0,0,-20@link2"``.
    """
    head, _, frame = text.partition("@")
    start, _, force = head.partition(":")
    try:
        time_ = float(start)
        values = [float(value) for value in force.replace(",", " ").split()]
    except ValueError:
        values, time_ = [], float("nan")
    if len(values) != 3 or not np.isfinite([time_, *values]).all() or time_ < 0:
        raise InputError("force_at", "T:FX,FY,FZ[@FRAME] (a time >= 0 in [s], a force in [N])", repr(text))
    return Push(time_, (values[0], values[1], values[2]), frame.strip() or None)


class _StepForce:
    """A force that starts at a time: zero before, constant after (a callable wrench)."""

    def __init__(self, start: float, force: tuple[float, ...]) -> None:
        self.start, self.force, self.zero = start, np.asarray(force, dtype=float), np.zeros(3)

    def __call__(self, t: float) -> np.ndarray:
        return self.force if t >= self.start else self.zero


def push_wrenches(
    robot: Robot, pushes: Sequence[str | Push], frame: str | None = None
) -> tuple[tuple[Push, ...], list[ExternalWrench]]:
    """The pushes (frames resolved: ``frame`` when a push names none, then the robot's end
    effector) and their wrenches.

    Args:
        robot: The simulated robot.
        pushes: Pushes, as :class:`Push` or as text for :func:`parse_push`.
        frame: The frame of a push that names none (``None``: the robot's end effector).
    """
    resolved = []
    for push in pushes:
        push = parse_push(push) if isinstance(push, str) else push
        resolved.append(replace(push, frame=robot.task_frame(push.frame or frame, "a push")))
    return tuple(resolved), [ExternalWrench(push.frame, _StepForce(push.time, push.force)) for push in resolved]  # type: ignore[arg-type]


class TrajectoryReference:
    """A recorded motion as a joint reference ``t -> (q_d, v_d, a_d)`` for computed torque:
    each column interpolated linearly between samples; before the first sample its state,
    after the last one at rest there.

    Args:
        trajectory: The motion (fixed base: ``q`` and ``v`` of the same size), in the
            robot's joint order.
    """

    def __init__(self, trajectory: Trajectory) -> None:
        self.t, self.q, self.v, self.a = trajectory.t, trajectory.q, trajectory.v, trajectory.a
        self.rest = np.zeros(trajectory.v.shape[1])

    def __call__(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        if t >= self.t[-1]:
            return self.q[-1], self.rest, self.rest
        t = max(float(t), float(self.t[0]))
        k = int(np.clip(np.searchsorted(self.t, t, side="right") - 1, 0, len(self.t) - 2))
        s = (t - self.t[k]) / (self.t[k + 1] - self.t[k])
        return tuple((1 - s) * x[k] + s * x[k + 1] for x in (self.q, self.v, self.a))


def tracked(
    robot: Robot, controller: str, reference: Trajectory, target: list[float] | None, q0: list[float] | None
) -> tuple[Trajectory, list[float], list[float]]:
    """The reference in the robot's joint order, its goal as the target and its start as ``q0``
    (unless given); refused with another controller, a target, a floating base or one sample.

    Args:
        robot: The simulated robot.
        controller: The controller's name (only ``"computed-torque"`` tracks a reference).
        reference: The motion to track (a fixed-base robot's, at least two samples).
        target: A target given besides (refused: the reference's last sample is the target).
        q0: Initial configuration in [rad] / [m] (``None``: the reference's first sample).
    """
    if controller != "computed-torque":
        raise InputError("reference", "given only with the computed-torque controller", repr(controller))
    if target is not None:
        raise InputError("target", "left out with a reference (its last sample is the target)", counted(np.size(target), "value"))
    reference = reference.for_robot(robot)
    if robot.floating_base or len(reference) < 2:
        raise InputError("reference", "a fixed-base robot's motion of at least two samples", counted(len(reference), "sample"))
    return reference, list(reference.q[-1]), list(reference.q[0]) if q0 is None else q0


def applied_torques(robot: Robot, trajectory: Trajectory, external: Sequence[ExternalWrench]) -> np.ndarray:
    """The joint torques external wrenches applied at each sample, ``Σ J(q)ᵀ w(t)``, shape (N, nv).

    Args:
        robot: The plant.
        trajectory: The run.
        external: The wrenches it applied.
    """
    return np.array([external_torques(robot, q, float(t), external) for t, q in zip(trajectory.t, trajectory.q, strict=True)])


def observer_outcome(
    robot: Robot, trajectory: Trajectory, observer: MomentumObserver, external: list[ExternalWrench]
) -> ObserverOutcome:
    """The observer's residual at every sample, against the external torques applied there.

    Args:
        robot: The plant.
        trajectory: The run.
        observer: The observer run along it.
        external: The external wrenches the run applied.
    """
    residual = np.array(observer.residuals)
    applied = applied_torques(robot, trajectory, external)
    gain = float(np.max(np.asarray(observer.gain, dtype=float)))
    error = float(np.abs(residual[-1] - applied[-1]).max())
    return ObserverOutcome(gain, tuple(residual[-1].tolist()), tuple(applied[-1].tolist()), error, residual, applied)
