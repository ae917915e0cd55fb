"""The analytic derivative of the reference's mass matrix, ``∂M/∂θ``, for a stack of states.

Moving joint ``k`` rotates everything beyond it about ``z_k``, so each derivative of a body
Jacobian is a cross product with a joint axis (see :mod:`robodyn.reference.numeric`):
``∂J[b, i]/∂θ_k = z_k × J[b, i]`` when ``k`` is ``i`` or an ancestor of it and revolute;
``∂J_v[b, i]/∂θ_k = z_i × J_v[b, k]`` when ``i`` is a revolute strict ancestor of ``k``;
``∂(R I Rᵀ)/∂θ_k = [z_k]× RIRᵀ − RIRᵀ [z_k]×``. No Pinocchio here.
"""

from __future__ import annotations

import numpy as np


def _pair_cross(columns: np.ndarray, others: np.ndarray) -> np.ndarray:
    """``out[n, i, j] = Σ_b columns[n, b, i] × others[n, b, j]``, shape (N, n, n, 3): from the
    nine sums ``Σ_b columns[n, b, i, d] others[n, b, j, e]``, each one matrix product a state."""
    products = np.einsum("nbid,nbje->nijde", columns, others, optimize=True)
    return np.stack(
        [
            products[..., 1, 2] - products[..., 2, 1],
            products[..., 2, 0] - products[..., 0, 2],
            products[..., 0, 1] - products[..., 1, 0],
        ],
        axis=-1,
    )


def mass_derivative(
    linear: np.ndarray,
    angular: np.ndarray,
    weighted: np.ndarray,
    world_inertia: np.ndarray,
    axes: np.ndarray,
    *,
    ancestors: np.ndarray,
    revolute: np.ndarray,
) -> np.ndarray:
    """``dM[n, i, j, k] = ∂M_ij/∂θ_k``, shape (N, n, n, n), in the body coordinates θ.

    ``∂M_ij/∂θ_k = Σ_b m_b (∂J_v[b,i]/∂θ_k · J_v[b,j] + J_v[b,i] · ∂J_v[b,j]/∂θ_k)`` plus the
    rotational terms; each ``∂J/∂θ_k`` is a cross product with a joint axis, so by the
    triple product ``(z × x) · y = z · (x × y)`` the sums over bodies are taken first (one
    3-vector per pair of joints) and dotted with the axes after.

    Args:
        linear: Linear Jacobians of the bodies' centres of mass, shape (N, B, n, 3), in [m].
        angular: Angular Jacobians of the bodies, shape (N, B, n, 3).
        weighted: ``linear`` times each body's mass, shape (N, B, n, 3), in [kg m].
        world_inertia: Inertias about the centres of mass in world axes, shape (N, B, 3, 3), in [kg m²].
        axes: World joint axes, shape (N, B, 3).
        ancestors: Boolean (B, B): ``ancestors[b, i]`` when joint ``i`` is ``b`` or an ancestor of it.
        revolute: Boolean (B,): which joints are revolute.
    """
    # dJ[b, i]/dθ_k = z_k × J[b, i] where k is i or an ancestor of i, and revolute.
    rotating = ancestors & revolute[None, :]  # [i, k]
    # dJ_v[b, i]/dθ_k = z_i × J_v[b, k] where i is a revolute strict ancestor of k.
    lever = ancestors.T & ~np.eye(len(revolute), dtype=bool) & revolute[:, None]  # [i, k]
    moving = (ancestors & revolute[None, :]).astype(float)  # [b, k]
    inertia_angular = world_inertia @ np.swapaxes(angular, -1, -2)  # (N, B, 3, n): I_b J_ω[b, j]
    inertia_angular = np.swapaxes(inertia_angular, -1, -2)  # (N, B, n, 3)
    # P[n, i, j] = Σ_b J_v[b, i] × m_b J_v[b, j];  Q[n, i, j] = Σ_b J_ω[b, i] × I_b J_ω[b, j]
    linear_pairs = _pair_cross(linear, weighted)
    angular_pairs = _pair_cross(angular, inertia_angular)
    # (z_k × J[b,i]) · Y[b,j] = z_k · (J[b,i] × Y[b,j]);  (z_i × J_v[b,k]) · W[b,j] = z_i · P[k, j]
    along_k = np.einsum("nija,nka->nijk", linear_pairs + angular_pairs, axes, optimize=True) * rotating[None, :, None, :]
    along_i = np.einsum("nkja,nia->nijk", linear_pairs, axes, optimize=True) * lever[None, :, None, :]
    half = along_k + along_i
    # Σ_b J_ω[b,i] · (∂(R I Rᵀ)/∂θ_k) J_ω[b,j] = Σ_b moving[b,k] z_k · (I J_ω[b,j] × J_ω[b,i] − J_ω[b,j] × I J_ω[b,i])
    spin = np.cross(inertia_angular[:, :, None, :, :], angular[:, :, :, None, :]) - np.cross(
        angular[:, :, None, :, :], inertia_angular[:, :, :, None, :]
    )  # (N, B, i, j, 3)
    summed = np.einsum("bk,nbija->nijka", moving, spin, optimize=True)  # Σ_b moving[b, k] (…)[b, i, j]
    spin_term = np.einsum("nijka,nka->nijk", summed, axes, optimize=True)
    return half + np.swapaxes(half, 1, 2) + spin_term
