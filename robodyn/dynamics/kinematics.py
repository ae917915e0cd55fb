"""Kinematics of a loaded robot: frame positions, Jacobians, bias accelerations, wrenches.

:class:`Kinematics` is a base of :class:`robodyn.Robot`; its methods follow the same
conventions (1-D state → one result, 2-D → stacked; world axes; [m], [rad]).
"""

from __future__ import annotations

import difflib

import numpy as np
import pinocchio as pin

from robodyn.dynamics.handle import ModelHandle, per_state
from robodyn.exceptions import FrameError, InputError


class Kinematics(ModelHandle):
    """Frames of a robot and how they move (through Pinocchio)."""

    def __init__(self, model: pin.Model, *, name: str, floating_base: bool) -> None:
        super().__init__(model, name=name, floating_base=floating_base)
        self._frame_ids = {frame.name: index for index, frame in enumerate(model.frames)}

    @property
    def frame_names(self) -> list[str]:
        """Names of every frame: links, joints and fixed frames of the URDF."""
        return list(self._frame_ids)

    @property
    def frame_ids(self) -> dict[str, int]:
        """Pinocchio index of every frame, by name (a copy)."""
        return dict(self._frame_ids)

    def frame_id(self, frame: str) -> int:
        """Pinocchio index of a frame (link, joint or fixed frame) by name.

        Raises:
            FrameError: If the robot has no such frame (with the closest names).
        """
        try:
            return self._frame_ids[frame]
        except (KeyError, TypeError):
            close = difflib.get_close_matches(str(frame), list(self._frame_ids), n=3)
            raise FrameError(frame, self.name, close) from None

    def frame_position(self, q: np.ndarray, frame: str) -> np.ndarray:
        """Position of a frame's origin in the world frame.

        Args:
            q: Configuration, shape (nq,) or (N, nq).
            frame: Link or joint name, e.g. ``"end_effector"``.

        Returns:
            Shape (3,) or (N, 3), in [m].
        """
        frame_id = self.frame_id(frame)
        (q,), _ = self.validate(q=q)
        return per_state(lambda qi: self._placement(qi, frame_id).translation.copy(), q)

    def _placement(self, q: np.ndarray, frame_id: int) -> pin.SE3:
        data = self.data
        pin.framesForwardKinematics(self.model, data, q)
        return data.oMf[frame_id]

    def frame_jacobian(self, q: np.ndarray, frame: str) -> np.ndarray:
        """Jacobian of a frame: its velocity is ``J v`` (linear first, then angular).

        Both parts are expressed in world-aligned axes at the frame's origin (Pinocchio's
        ``LOCAL_WORLD_ALIGNED``): rows 0-2 give the origin's velocity in [m/s], rows 3-5
        the angular velocity in [rad/s].

        Args:
            q: Configuration, shape (nq,) or (N, nq).
            frame: Link or joint name.

        Returns:
            Shape (6, nv) or (N, 6, nv).
        """
        frame_id = self.frame_id(frame)
        (q,), _ = self.validate(q=q)
        return per_state(
            lambda qi: pin.computeFrameJacobian(self.model, self.data, qi, frame_id, pin.LOCAL_WORLD_ALIGNED).copy(), q
        )

    def frame_bias_acceleration(self, q: np.ndarray, v: np.ndarray, frame: str) -> np.ndarray:
        """``J̇(q, v) v``: the acceleration of a frame's origin at zero joint acceleration.

        The classical (not spatial) acceleration of the origin, in world axes, in [m/s²];
        the frame's acceleration is ``J a + J̇ v`` with ``J`` from :meth:`frame_jacobian`.

        Args:
            q: Configuration, shape (nq,).
            v: Velocity, shape (nv,).
            frame: Link or joint name.

        Returns:
            Shape (3,).
        """
        frame_id = self.frame_id(frame)
        (q, v), _ = self.validate(q=q, v=v)
        data = self.data
        pin.forwardKinematics(self.model, data, q, v, np.zeros(self.nv))
        return pin.getFrameClassicalAcceleration(self.model, data, frame_id, pin.LOCAL_WORLD_ALIGNED).linear.copy()

    def wrench_torques(self, q: np.ndarray, frame: str, wrench: np.ndarray) -> np.ndarray:
        """Joint torques ``J(q)ᵀ w`` that an external wrench on a frame exerts on the joints.

        Args:
            q: Configuration, shape (nq,).
            frame: Link or joint name; the wrench acts at its origin.
            wrench: Force in [N] then torque in [N m], world axes, shape (6,) (or a force
                alone, shape (3,)).

        Returns:
            Shape (nv,): add to the motor torques in forward dynamics, subtract from the
            inverse dynamics' torques.
        """
        wrench = np.asarray(wrench, dtype=float)
        if wrench.shape == (3,):
            wrench = np.concatenate([wrench, np.zeros(3)])
        if wrench.shape != (6,) or not np.isfinite(wrench).all():
            raise InputError("wrench", "6 finite values (force in [N], torque in [N m])", f"shape {wrench.shape}")
        return self.frame_jacobian(q, frame).T @ wrench

    def integrate(self, q: np.ndarray, dq: np.ndarray) -> np.ndarray:
        """The configuration reached from ``q`` along the velocity ``dq`` in unit time.

        ``q + dq`` for joints; the floating base's pose moves on SE(3) (Pinocchio's
        ``integrate``), keeping its quaternion unit.

        Raises:
            InputError: For states of the wrong size, non-finite values or a base
                quaternion that is not unit (an all-zero one included).
        """
        (q, dq), _ = self.validate(q=q, v=dq)  # refuses a base quaternion that is not unit
        if self.floating_base:
            if q.ndim == 2:
                return np.array([pin.integrate(self.model, qi, dqi) for qi, dqi in zip(q, dq, strict=True)])
            return pin.integrate(self.model, q, dq)
        return q + dq
