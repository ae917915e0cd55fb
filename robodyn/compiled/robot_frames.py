"""The :class:`~robodyn.compiled.robot.CompiledRobot`'s frame kinematics: one small compiled
module a frame (:mod:`robodyn.compiled.kinematics`), built on first use and cached, with the
shape rules of :class:`robodyn.Robot` (fixed bases only).
"""

from __future__ import annotations

from types import ModuleType
from typing import TYPE_CHECKING

import numpy as np

from robodyn.compiled.cache import robot_key
from robodyn.exceptions import CompileError

if TYPE_CHECKING:
    from robodyn.dynamics.robot import Robot

_ndarray = np.ndarray


class CompiledFrames:
    """Where the robot's frames are, in generated C: a part of :class:`~robodyn.compiled.robot.CompiledRobot`."""

    robot: Robot
    name: str

    def frame_module(self, frame: str) -> ModuleType:
        """The compiled kinematics of a frame (built on first use, then cached on disk and here).

        Args:
            frame: Name of a frame of the robot (a link, a joint or a fixed frame).

        Raises:
            FrameError: Unknown frame. CompileError: If the build fails.
        """
        modules = self.__dict__.setdefault("_frames", {})
        if frame not in modules:
            fixed_base_only(self.robot, "frame kinematics")
            from robodyn.compiled.kinematics import build_frame  # the generator: only when first asked for

            modules[frame] = build_frame(self.robot, frame, robot_key(self.robot))
        return modules[frame]

    def _frame_call(self, kind: str, frame: str, **named: np.ndarray) -> np.ndarray:
        function = getattr(self.frame_module(frame), kind)
        result = function(*named.values())
        if result.__class__ is _ndarray:
            return result
        arrays, _ = self.robot.validate(**named)
        result = function(*[np.ascontiguousarray(array, dtype=np.float64) for array in arrays])
        if result.__class__ is not _ndarray:  # cannot happen after validate(): refuse rather than guess
            raise CompileError(self.name, f"the compiled frame {kind} refused checked inputs (status {result})")
        return result

    def frame_position(self, q: np.ndarray, frame: str) -> np.ndarray:
        """Position of a frame's origin in the world frame, shape (3,) or (N, 3), in [m]
        (as :meth:`robodyn.Robot.frame_position`, in generated C).

        Args:
            q: Configuration, shape (nq,) or (N, nq), in [rad] / [m] (fixed base only).
            frame: Name of a frame of the robot (a link, a joint or a fixed frame).
        """
        return self._frame_call("position", frame, q=q)

    def frame_rotation(self, q: np.ndarray, frame: str) -> np.ndarray:
        """Rotation world <- frame, shape (3, 3) or (N, 3, 3).

        Args:
            q: Configuration, shape (nq,) or (N, nq), in [rad] / [m] (fixed base only).
            frame: Name of a frame of the robot (a link, a joint or a fixed frame).
        """
        return self._frame_call("rotation", frame, q=q)

    def frame_jacobian(self, q: np.ndarray, frame: str) -> np.ndarray:
        """Frame Jacobian, shape (6, nv) or (N, 6, nv): linear rows then angular, world-aligned
        axes at the frame's origin (Pinocchio's ``LOCAL_WORLD_ALIGNED``, as
        :meth:`robodyn.Robot.frame_jacobian`).

        Args:
            q: Configuration, shape (nq,) or (N, nq), in [rad] / [m] (fixed base only).
            frame: Name of a frame of the robot (a link, a joint or a fixed frame).
        """
        return self._frame_call("jacobian", frame, q=q)

    def frame_bias_acceleration(self, q: np.ndarray, v: np.ndarray, frame: str, *, angular: bool = False) -> np.ndarray:
        """``J̇(q, v) v``: the classical acceleration of the frame's origin at zero joint
        acceleration, world axes, shape (3,) or (N, 3), in [m/s²] (as
        :meth:`robodyn.Robot.frame_bias_acceleration`); with ``angular=True`` the angular
        acceleration in [rad/s²] follows, shape (6,) or (N, 6).

        Args:
            q: Configuration, shape (nq,) or (N, nq), in [rad] / [m] (fixed base only).
            v: Velocity, shape (nv,) or (N, nv), in [rad/s] / [m/s].
            frame: Name of a frame of the robot (a link, a joint or a fixed frame).
            angular: Also return the angular part (rows 3–5) after the linear.
        """
        bias = self._frame_call("bias", frame, q=q, v=v)
        return bias if angular else bias[..., :3].copy()


def fixed_base_only(robot: Robot, what: str) -> None:
    """Refuse a floating base for the compiled ``what`` (its kernels model fixed bases).

    Args:
        robot: The loaded robot.
        what: What is asked for, in the refusal's sentence (``"derivatives"``, ``"frame kinematics"``).

    Raises:
        CompileError: If the robot has a floating base.
    """
    if robot.floating_base:
        raise CompileError(robot.name, f"it has a floating base; the compiled {what} model fixed-base robots")
