"""Rotation helpers in plain numpy (URDF roll-pitch-yaw, cross-product matrices, Rodrigues,
quaternion algebra).

The one copy for the code that does not use Pinocchio: the URDF edits, the viewer, the
equations, the reference and the trajectory files. Angles in [rad]; quaternions stored
``(x, y, z, w)`` as Pinocchio's configuration vectors store them.
"""

from __future__ import annotations

import math

import numpy as np

#: Multiplying a quaternion (x, y, z, w) by this gives its conjugate.
_CONJUGATE = np.array([-1.0, -1.0, -1.0, 1.0])


def rpy_matrix(rpy: np.ndarray) -> np.ndarray:
    """Rotation matrix of URDF roll-pitch-yaw angles in [rad] (fixed axes X, Y, Z).

    Args:
        rpy: Roll, pitch, yaw, shape (3,), in [rad].

    Returns:
        ``Rz(yaw) @ Ry(pitch) @ Rx(roll)``, shape (3, 3).
    """
    roll, pitch, yaw = rpy
    rx = np.array([[1, 0, 0], [0, math.cos(roll), -math.sin(roll)], [0, math.sin(roll), math.cos(roll)]])
    ry = np.array([[math.cos(pitch), 0, math.sin(pitch)], [0, 1, 0], [-math.sin(pitch), 0, math.cos(pitch)]])
    rz = np.array([[math.cos(yaw), -math.sin(yaw), 0], [math.sin(yaw), math.cos(yaw), 0], [0, 0, 1]])
    return rz @ ry @ rx


def matrix_rpy(rotation: np.ndarray) -> np.ndarray:
    """Roll, pitch, yaw in [rad] of a rotation matrix (URDF's fixed-axis X-Y-Z convention).

    Args:
        rotation: A rotation matrix, shape (3, 3).

    Returns:
        Shape (3,); at gimbal lock (pitch ±90°) the roll is 0 and everything is in yaw.
    """
    pitch = math.atan2(-rotation[2, 0], math.hypot(rotation[0, 0], rotation[1, 0]))
    if abs(math.cos(pitch)) < 1e-12:  # gimbal lock: put everything in yaw
        return np.array([0.0, pitch, math.atan2(-rotation[0, 1], rotation[1, 1])])
    return np.array([math.atan2(rotation[2, 1], rotation[2, 2]), pitch, math.atan2(rotation[1, 0], rotation[0, 0])])


def skew(vectors: np.ndarray) -> np.ndarray:
    """Cross-product matrices: ``skew(v) @ w == cross(v, w)``.

    Args:
        vectors: Shape (..., 3).

    Returns:
        Shape (..., 3, 3).
    """
    x, y, z = vectors[..., 0], vectors[..., 1], vectors[..., 2]
    zero = np.zeros_like(x)
    return np.stack([np.stack([zero, -z, y], -1), np.stack([z, zero, -x], -1), np.stack([-y, x, zero], -1)], -2)


def axis_rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rodrigues' rotation by ``angle`` in [rad] about a unit ``axis`` (shape (3,)); shape (3, 3).

    Args:
        axis: Unit axis, shape (3,).
        angle: Angle in [rad].
    """
    cross = skew(np.asarray(axis, dtype=float))
    return np.eye(3) + math.sin(angle) * cross + (1 - math.cos(angle)) * cross @ cross


def quaternion_conjugate(quaternions: np.ndarray) -> np.ndarray:
    """Conjugates of quaternions (x, y, z, w): the inverse rotations of unit ones.

    Args:
        quaternions: Shape (..., 4).

    Returns:
        Shape (..., 4).
    """
    return quaternions * _CONJUGATE


def quaternion_product(left: np.ndarray, right: np.ndarray) -> np.ndarray:
    """Hamilton products ``left ⊗ right`` of quaternions stored (x, y, z, w), row by row.

    Args:
        left: Shape (N, 4).
        right: Shape (N, 4).

    Returns:
        Shape (N, 4).
    """
    lv, lw = left[:, :3], left[:, 3:]
    rv, rw = right[:, :3], right[:, 3:]
    return np.hstack([lw * rv + rw * lv + np.cross(lv, rv), lw * rw - np.sum(lv * rv, axis=1, keepdims=True)])


def rotate_inverse(quaternions: np.ndarray, vectors: np.ndarray) -> np.ndarray:
    """``R(q)ᵀ v`` row by row: world-frame vectors in the frame a unit quaternion rotates to.

    Args:
        quaternions: Unit quaternions (x, y, z, w), shape (N, 4).
        vectors: Shape (N, 3).

    Returns:
        Shape (N, 3): ``q̄ ⊗ (v, 0) ⊗ q`` (vector part).
    """
    pure = np.hstack([vectors, np.zeros((len(vectors), 1))])
    return quaternion_product(quaternion_product(quaternion_conjugate(quaternions), pure), quaternions)[:, :3]
