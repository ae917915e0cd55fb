"""Velocities and accelerations of a sampled motion by finite differences.

A trajectory file may hold positions only (or positions and velocities); the missing kinds
are derived here (:func:`derive_velocities`), a floating base's through its quaternion.
"""

from __future__ import annotations

import numpy as np

from robodyn.common.rotations import quaternion_conjugate, quaternion_product, rotate_inverse
from robodyn.exceptions import InputError

#: Fewest samples a second-order difference needs.
MIN_SAMPLES = 3


def derive_velocities(t: np.ndarray, q: np.ndarray, *, floating_base: bool) -> np.ndarray:
    """Velocities from sampled positions by second-order finite differences.

    ``np.gradient(q, t, axis=0, edge_order=2)``: central differences inside (error
    O(h²) for a step h, non-uniform steps allowed), one-sided second-order differences at
    the first and last sample. A floating base's linear velocity is ``Rᵀ ṗ`` and its angular
    velocity ``2 (q̄ ⊗ q̇)`` (vector part), both in the base frame, as Pinocchio's ``v``.
    Applied to ``v`` this gives ``a`` (O(h²) inside, O(h) on the first and last two samples).

    Args:
        t: Times in [s], shape (N,), strictly increasing, N ≥ 3.
        q: Positions, shape (N, nq).
        floating_base: Whether ``q[:, :7]`` is a base pose (position in [m], unit
            quaternion x, y, z, w).

    Returns:
        Shape (N, nv) (nv = nq − 1 with a floating base, else nq).

    Raises:
        InputError: Fewer than 3 samples.
    """
    if len(t) < MIN_SAMPLES:
        raise InputError("trajectory", f"at least {MIN_SAMPLES} samples to derive velocities from positions", f"{len(t)} samples")
    if not floating_base:
        return np.gradient(q, t, axis=0, edge_order=2)
    quaternion = q[:, 3:7].copy()
    flips = np.cumsum(np.sum(quaternion[1:] * quaternion[:-1], axis=1) < 0) % 2  # q and -q are one rotation
    quaternion[1:][flips == 1] *= -1.0
    rates = np.gradient(np.hstack([q[:, :3], quaternion, q[:, 7:]]), t, axis=0, edge_order=2)
    linear = rotate_inverse(quaternion, rates[:, :3])
    angular = 2.0 * quaternion_product(quaternion_conjugate(quaternion), rates[:, 3:7])[:, :3]
    return np.hstack([linear, angular, rates[:, 7:]])


__all__ = ["derive_velocities"]
