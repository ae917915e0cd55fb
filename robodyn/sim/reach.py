"""Whether a task target is within a frame's reach: one refusal for every task-space controller."""

from __future__ import annotations

import numpy as np

from robodyn.dynamics import frames
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError


def check_reach(robot: Robot, frame: str, target: np.ndarray, *, parameter: str) -> None:
    """Refuse a target position no configuration can reach (outside the chain's reach ball).

    The ball is :func:`robodyn.dynamics.frames.reach` (an upper bound of the workspace:
    what it refuses is certainly out of reach).

    Args:
        robot: The robot.
        frame: The controlled frame.
        target: Position in [m], shape (3,).
        parameter: The argument's name, for the message.

    Raises:
        InputError: If the target lies outside the ball.
    """
    lower, upper = robot.physical_limits()
    ball = frames.reach(robot.model, robot.frame_id(frame), lower, upper)
    if ball is None:
        return
    centre, radius = ball
    distance = float(np.linalg.norm(target - np.asarray(centre)))
    if distance > radius:
        where = ", ".join(f"{c:.3g}" for c in centre)
        raise InputError(
            parameter,
            f"within the reach of {frame!r} ({radius:.3f} m of its first joint at ({where}) m)",
            f"a point {distance:.3f} m away",
        )
