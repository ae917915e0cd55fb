"""Attitudes for the pose controllers (:mod:`robodyn.sim.operational_space`, which
re-exports both): a target attitude from a rotation matrix, a quaternion or roll-pitch-yaw
angles, and the attitude error ``log(Rᵀ R_d)`` between a frame and its target.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from robodyn.common.rotations import rpy_matrix
from robodyn.exceptions import InputError


def target_rotation(orientation: np.ndarray | list[float]) -> np.ndarray:
    """A target attitude as a rotation matrix (world axes), shape (3, 3).

    Args:
        orientation: A rotation matrix (3, 3), a unit quaternion ``(x, y, z, w)`` (4,) or
            URDF roll-pitch-yaw angles in [rad] (3,).

    Raises:
        InputError: For another shape, non-finite values, a matrix that is not a rotation
            or a quaternion that is not unit (to 1e-6).
    """
    value = np.asarray(orientation, dtype=float)
    if not np.isfinite(value).all():
        raise InputError("orientation", "finite values", "non-finite values")
    if value.shape == (3,):
        return rpy_matrix(value)
    if value.shape == (4,):
        if abs(np.linalg.norm(value) - 1) > 1e-6:
            raise InputError("orientation", "a unit quaternion (x, y, z, w)", f"norm {np.linalg.norm(value):.6g}")
        return pin.Quaternion(value[3], *value[:3]).toRotationMatrix()
    if value.shape == (3, 3):
        if not (np.allclose(value @ value.T, np.eye(3), atol=1e-6) and np.linalg.det(value) > 0):
            raise InputError("orientation", "a rotation matrix (orthonormal, determinant +1)", "another 3 × 3 matrix")
        return value
    raise InputError(
        "orientation", "a 3 × 3 rotation matrix, a quaternion (x, y, z, w) or roll, pitch, yaw", f"shape {value.shape}"
    )


def orientation_error(rotation: np.ndarray, target: np.ndarray) -> np.ndarray:
    """``log(Rᵀ R_d)``: the rotation from the frame to the target, as an axis times an angle.

    The axis is the same in the frame's and in the target's axes; the angle, in [rad], is
    the attitude error ``|e|`` (at most π).

    Args:
        rotation: The frame's attitude ``R``, shape (3, 3).
        target: The target attitude ``R_d``, shape (3, 3).

    Returns:
        Shape (3,), in [rad].
    """
    return pin.log3(rotation.T @ target)
