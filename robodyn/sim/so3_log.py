"""The right Jacobian of SO(3)'s logarithm and its rate, for an attitude task's acceleration.

``φ = log(R_dᵀ R)`` moves as ``φ̇ = Jr⁻¹(φ) ω_b`` (``ω_b``: the body angular velocity);
:class:`robodyn.sim.operational_space.OperationalSpace` solves ``φ̈`` for the angular
acceleration that gives its attitude error the wanted linear law.
"""

from __future__ import annotations

import numpy as np

from robodyn.common.rotations import skew

#: Below this rotation angle in [rad], the log Jacobian's coefficients use their series.
SMALL_ANGLE = 0.05


def log_jacobian(phi: np.ndarray) -> np.ndarray:
    """``Jr⁻¹(φ) = I + φ̂/2 + c(θ) φ̂²``: ``d/dt log(R) = Jr⁻¹ ω_b`` (θ = ‖φ‖, shape (3, 3)).

    Args:
        phi: ``φ``, a rotation vector in [rad], shape (3,).
    """
    cross = skew(phi)
    return np.eye(3) + 0.5 * cross + log_coefficients(float(np.linalg.norm(phi)))[0] * cross @ cross


def log_jacobian_rate(phi: np.ndarray, phi_dot: np.ndarray) -> np.ndarray:
    """``d/dt Jr⁻¹(φ)`` along ``φ̇``, shape (3, 3).

    Args:
        phi: ``φ`` in [rad], shape (3,).
        phi_dot: ``φ̇`` in [rad/s], shape (3,).
    """
    cross, cross_dot = skew(phi), skew(phi_dot)
    c, c_prime_over_theta = log_coefficients(float(np.linalg.norm(phi)))
    return (
        0.5 * cross_dot + c * (cross_dot @ cross + cross @ cross_dot) + c_prime_over_theta * float(phi @ phi_dot) * cross @ cross
    )


def log_coefficients(theta: float) -> tuple[float, float]:
    """``c(θ) = 1/θ² − cot(θ/2)/(2θ)`` and ``c'(θ)/θ`` (series below :data:`SMALL_ANGLE`).

    Args:
        theta: ``θ`` in [rad].
    """
    if theta < SMALL_ANGLE:
        return 1 / 12 + theta**2 / 720 + theta**4 / 30240, 1 / 360 + theta**2 / 7560
    cot = 1 / np.tan(theta / 2)
    c = 1 / theta**2 - cot / (2 * theta)
    c_prime = -2 / theta**3 + cot / (2 * theta**2) + 1 / (4 * theta * np.sin(theta / 2) ** 2)
    return float(c), float(c_prime / theta)
