"""The operational-space task inertia near singularities: a damping that switches on there only.

With the eigen-decomposition ``J M⁻¹ Jᵀ = U S Uᵀ`` (``J``: the task's m rows of the frame
Jacobian), the task inertia is ``Λ = U diag(s / (s² + λ²)) Uᵀ``: a direction the frame cannot
move in (``s = 0``) gets no force instead of an infinite one. ``λ`` is relative to the largest
eigenvalue ``s_max`` and has two parts, ``λ² = (λ₀² + λ_v²) s_max²``:

- ``λ₀`` (``damping``, default :data:`FLOOR`, 1e-8): a constant numerical floor, so that the
  directions a frame never moves in (a planar arm's normal) stay finite. Away from
  singularities the law is the plain ``Λ = (J M⁻¹ Jᵀ)⁻¹`` within ``(λ₀ s_max / s)²``.
- ``λ_v``: the variable damping of Nakamura and Chiaverini, from the conditioning of the
  **kinematics**, not of ``J M⁻¹ Jᵀ`` (whose rows mix units, [m] and [rad], and whose
  eigenvalues spread with the links' inertias: an ordinary ur5 pose has a ratio of 5e-6)::

      σ = σ_r(S J) / ℓ,      λ_v² = λ_max² (1 − (σ / ε)²)  for σ < ε,  else 0

  ``S`` scales the rotation rows by ``ℓ``, the chain's characteristic length in [m] (the sum
  of the joint offsets from its first moving joint to the frame, :func:`characteristic_length`),
  so that every row is in [m]; ``σ_r`` is the smallest of the singular values the frame has
  at a generic configuration (``r``: the task's rank there, so a planar arm's normal is not
  a singularity); ``ε`` = :data:`THRESHOLD` (5 % of the reach) and ``λ_max`` =
  :data:`MAX_DAMPING`. ``λ_v`` is exactly zero for ``σ ≥ ε`` and grows smoothly to
  ``λ_max`` at the singularity, where each eigenvalue of ``Λ`` is at most ``1 / (2 λ_max s_max)``.
"""

from __future__ import annotations

import numpy as np

from robodyn.dynamics.robot import Robot

#: The constant floor ``λ₀`` of the damping, relative to the largest eigenvalue of ``J M⁻¹ Jᵀ``.
FLOOR = 1e-8
#: ``λ_max``: the variable damping at a singularity, relative to the largest eigenvalue.
MAX_DAMPING = 1e-2
#: ``ε``: the variable damping acts where the task's smallest singular value is below this
#: fraction of the characteristic length.
THRESHOLD = 0.05
#: A singular value below this fraction of the largest is a direction the frame never moves in.
RANK_TOLERANCE = 1e-9


def characteristic_length(robot: Robot, frame: str) -> float:
    """``ℓ`` in [m]: the lengths of the joint offsets from the chain's first moving joint to
    the frame, summed (1 m when that is zero: a frame on the first joint's axis).

    Args:
        robot: The robot.
        frame: The task's frame.
    """
    model = robot.model
    frame_id = robot.frame_id(frame)
    chain = [joint for joint in model.supports[model.frames[frame_id].parentJoint] if joint != 0]
    length = float(np.linalg.norm(model.frames[frame_id].placement.translation))
    length += sum(float(np.linalg.norm(model.jointPlacements[joint].translation)) for joint in chain[1:])
    return length if length > 0 else 1.0


def scaled_gram(jacobian: np.ndarray, length: float) -> np.ndarray:
    """``(S J)(S J)ᵀ / ℓ²``: the task rows in [m] (rotation rows times ``ℓ``), shape (m, m).

    Args:
        jacobian: The task's rows of the frame Jacobian (linear, then angular), shape (m, nv).
        length: ``ℓ`` in [m].
    """
    scaled = np.array(jacobian, dtype=float)
    scaled[3:] *= length
    return scaled @ scaled.T / length**2


def relative_singular_value(jacobian: np.ndarray, length: float, rank: int) -> float:
    """``σ = σ_r(S J) / ℓ``: the task's ``rank``-th singular value, relative to ``ℓ``
    (from the eigenvalues of :func:`scaled_gram`, as the compiled twin computes it).

    Args:
        jacobian: The task's rows of the frame Jacobian, shape (m, nv).
        length: ``ℓ`` in [m].
        rank: ``r``, the task's generic rank (:func:`generic_rank`); 0 gives 0.
    """
    values = np.linalg.eigvalsh(scaled_gram(jacobian, length))[::-1]
    return float(np.sqrt(max(float(values[rank - 1]), 0.0))) if rank > 0 else 0.0


def generic_rank(robot: Robot, frame: str, rows: int, *, samples: int = 3) -> int:
    """The task's rank at generic configurations (the largest of a few seeded random ones).

    Args:
        robot: The robot.
        frame: The task's frame.
        rows: The task's rows: 3 (position) or 6 (pose).
        samples: How many random configurations.
    """
    rng = np.random.default_rng(0)
    rank = 0
    for _ in range(samples):
        jacobian = robot.frame_jacobian(robot.random_configuration(rng), frame)[:rows]
        values = np.linalg.svd(jacobian, compute_uv=False)
        rank = max(rank, int((values > RANK_TOLERANCE * max(float(values[0]), 1e-300)).sum()))
    return rank


def variable_damping(sigma: float, threshold: float, maximum: float) -> float:
    """``λ_v = λ_max √(1 − (σ/ε)²)`` for ``σ < ε``, else 0 (relative to the largest eigenvalue).

    Args:
        sigma: ``σ``, the task's relative singular value.
        threshold: ``ε``.
        maximum: ``λ_max``; 0 turns the damping off.
    """
    if sigma >= threshold or maximum == 0.0:
        return 0.0
    return maximum * float(np.sqrt(1.0 - (sigma / threshold) ** 2))


def damped_task_inertia(inverse: np.ndarray, damping: float) -> np.ndarray:
    """``Λ = U diag(s / (s² + λ²)) Uᵀ`` from ``Λ⁻¹ = J M⁻¹ Jᵀ = U S Uᵀ``, ``λ = damping · max(s)``.

    Args:
        inverse: ``J M⁻¹ Jᵀ``, shape (m, m), symmetric positive semi-definite.
        damping: ``λ`` relative to its largest eigenvalue (0: the plain inverse).

    Returns:
        Shape (m, m).
    """
    values, vectors = np.linalg.eigh(inverse)
    values = np.maximum(values, 0.0)
    floor = (damping * values[-1]) ** 2
    if floor == 0.0:
        return vectors @ np.diag(1.0 / values) @ vectors.T
    return vectors @ np.diag(values / (values**2 + floor)) @ vectors.T


def total_damping(floor: float, variable: float) -> float:
    """``√(λ₀² + λ_v²)``: exactly ``λ₀`` where the variable part is off.

    Args:
        floor: ``λ₀``.
        variable: ``λ_v``.
    """
    return floor if variable == 0.0 else float(np.hypot(floor, variable))
