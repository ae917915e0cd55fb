"""Kinematics of a loaded robot: frame positions, Jacobians, bias accelerations, wrenches.

Functions of a :class:`~robodyn.dynamics.handle.ModelHandle`, Pinocchio style
(``frame_position(handle, q, frame)``); :class:`robodyn.Robot` has them as methods
(``robot.frame_position(q, frame)``). They follow the Robot's conventions (1-D state → one
result, 2-D → stacked; world axes; [m], [rad]) and its fast path: Pinocchio is tried on the
arguments as they are, and anything doubtful goes through the boundary check.
"""

from __future__ import annotations

import difflib

import numpy as np
import pinocchio as pin

from robodyn.dynamics.handle import ModelHandle
from robodyn.dynamics.kernels import Kernel
from robodyn.exceptions import FrameError, InputError


def frame_id(handle: ModelHandle, frame: str) -> int:
    """Pinocchio index of a frame (link, joint or fixed frame) by name.

    Args:
        handle: The robot's model handle.
        frame: The frame's name.

    Raises:
        FrameError: If the robot has no such frame (with the closest names).
    """
    try:
        return handle.frames[frame]
    except (KeyError, TypeError):
        close = difflib.get_close_matches(str(frame), list(handle.frames), n=3)
        raise FrameError(frame, handle.name, close) from None


def frame_position(handle: ModelHandle, q: np.ndarray, frame: str) -> np.ndarray:
    """Position of a frame's origin in the world frame.

    Args:
        handle: The robot's model handle.
        q: Configuration, shape (nq,) or (N, nq).
        frame: Link or joint name, e.g. ``"end_effector"``.

    Returns:
        Shape (3,) or (N, 3), in [m].
    """
    index = frame_id(handle, frame)
    model, data = handle.model, handle.data

    def position(qi: np.ndarray) -> np.ndarray:
        pin.framesForwardKinematics(model, data, qi)
        return data.oMf[index].translation.copy()

    return handle.evaluate(Kernel("frame position", ("q",), position), q)


def frame_jacobian(handle: ModelHandle, q: np.ndarray, frame: str) -> np.ndarray:
    """Jacobian of a frame: its velocity is ``J v`` (linear first, then angular).

    Both parts are expressed in world-aligned axes at the frame's origin (Pinocchio's
    ``LOCAL_WORLD_ALIGNED``): rows 0-2 give the origin's velocity in [m/s], rows 3-5
    the angular velocity in [rad/s].

    Args:
        handle: The robot's model handle.
        q: Configuration, shape (nq,) or (N, nq).
        frame: Link or joint name.

    Returns:
        Shape (6, nv) or (N, 6, nv).
    """
    index = frame_id(handle, frame)
    model, data = handle.model, handle.data

    def jacobian(qi: np.ndarray) -> np.ndarray:
        # reshape: Pinocchio hands a 6×1 Jacobian (one degree of freedom) back as a vector
        return pin.computeFrameJacobian(model, data, qi, index, pin.LOCAL_WORLD_ALIGNED).reshape(6, model.nv)

    return handle.evaluate(Kernel("frame Jacobian", ("q",), jacobian), q)


def frame_bias_acceleration(handle: ModelHandle, q: np.ndarray, v: np.ndarray, frame: str) -> np.ndarray:
    """``J̇(q, v) v``: the acceleration of a frame's origin at zero joint acceleration.

    The classical (not spatial) acceleration of the origin, in world axes, in [m/s²];
    the frame's acceleration is ``J a + J̇ v`` with ``J`` from :func:`frame_jacobian`.

    Args:
        handle: The robot's model handle.
        q: Configuration, shape (nq,).
        v: Velocity, shape (nv,).
        frame: Link or joint name.

    Returns:
        Shape (3,).
    """
    index = frame_id(handle, frame)
    model, data, zeros = handle.model, handle.data, np.zeros(handle.nv)

    def bias(qi: np.ndarray, vi: np.ndarray) -> np.ndarray:
        pin.forwardKinematics(model, data, qi, vi, zeros)
        return pin.getFrameClassicalAcceleration(model, data, index, pin.LOCAL_WORLD_ALIGNED).linear.copy()

    return handle.evaluate(Kernel("frame bias acceleration", ("q", "v"), bias), q, v)


def wrench_torques(handle: ModelHandle, q: np.ndarray, frame: str, wrench: np.ndarray) -> np.ndarray:
    """Joint torques ``J(q)ᵀ w`` that an external wrench on a frame exerts on the joints.

    Args:
        handle: The robot's model handle.
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
    return frame_jacobian(handle, q, frame).T @ wrench


def integrate(handle: ModelHandle, q: np.ndarray, dq: np.ndarray) -> np.ndarray:
    """The configuration reached from ``q`` along the velocity ``dq`` in unit time.

    ``q + dq`` for joints; the floating base's pose moves on SE(3) (Pinocchio's
    ``integrate``), keeping its quaternion unit.

    Args:
        handle: The robot's model handle.
        q: Configuration, shape (nq,) or (N, nq), in [rad] / [m] (a floating base: position in [m], then its unit quaternion).
        dq: The displacement, a velocity applied for unit time, shape (nv,) or (N, nv), in [rad] / [m].

    Raises:
        InputError: For states of the wrong size, non-finite values or a base
            quaternion that is not unit (an all-zero one included).
    """
    (q, dq), _ = handle.validate(q=q, v=dq)  # refuses a base quaternion that is not unit
    if handle.floating_base:
        if q.ndim == 2:
            return np.array([pin.integrate(handle.model, qi, dqi) for qi, dqi in zip(q, dq, strict=True)])
        return pin.integrate(handle.model, q, dq)
    return q + dq


__all__ = ["frame_bias_acceleration", "frame_id", "frame_jacobian", "frame_position", "integrate", "wrench_torques"]
