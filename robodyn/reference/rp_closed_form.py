"""The RP arm's equations of motion, written out by hand from ``rp-arm.md``.

The rigid-body model of the generated arm (:mod:`robodyn.urdf.models.rp_arm`): link 2's centre
of mass is at ``r2 = l1 + q2 + c2`` from the shoulder. With ``g`` the magnitude of gravity:

    M(q)   = [[m1 l1²/4 + Iz1 + m2 r2² + Iz2, 0], [0, m2]]
    C(q,v) = [[m2 r2 q2', m2 r2 q1'], [−m2 r2 q1', 0]]        (Christoffel form)
    C v    = (2 m2 r2 q1' q2', −m2 r2 q1'²)
    G(q)   = ((m1 l1/2 + m2 r2) g cos q1, m2 g sin q1)
    tau    = M q'' + C q' + G

Nothing here is derived by a program: it is the closed form a student writes, kept as an
independent check of Pinocchio and of the symbolic reference. No Pinocchio import.
"""

from __future__ import annotations

import numpy as np

from robodyn.common.constants import STANDARD_GRAVITY_MAGNITUDE
from robodyn.urdf.models.rp_arm import RPArmParameters


def _r2(p: RPArmParameters, q: np.ndarray) -> np.ndarray:
    return p.l1 + q[..., 1] + p.c2


def mass_matrix(p: RPArmParameters, q: np.ndarray) -> np.ndarray:
    """``M(q)``, shape (2, 2) or (N, 2, 2).

    Args:
        p: The arm's masses [kg], lengths [m] and inertias [kg m²].
        q: ``(q1, q2)``: shoulder angle in [rad], slide in [m]; shape (2,) or (N, 2).
    """
    q = np.asarray(q, float)
    r2 = _r2(p, q)
    M = np.zeros((*q.shape[:-1], 2, 2))
    M[..., 0, 0] = p.m1 * p.l1**2 / 4 + p.inertia1 + p.m2 * r2**2 + p.inertia2
    M[..., 1, 1] = p.m2
    return M


def coriolis_matrix(p: RPArmParameters, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``C(q, v)`` from the Christoffel symbols of ``M``, shape (2, 2) or (N, 2, 2).

    Args:
        p: The arm's masses [kg], lengths [m] and inertias [kg m²].
        q: ``(q1, q2)``: shoulder angle in [rad], slide in [m]; shape (2,) or (N, 2).
        v: ``(q1', q2')`` in [rad/s], [m/s]; shape (2,) or (N, 2).
    """
    q, v = np.asarray(q, float), np.asarray(v, float)
    h = p.m2 * _r2(p, q)
    C = np.zeros((*q.shape[:-1], 2, 2))
    C[..., 0, 0] = h * v[..., 1]
    C[..., 0, 1] = h * v[..., 0]
    C[..., 1, 0] = -h * v[..., 0]
    return C


def coriolis_forces(p: RPArmParameters, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``C(q, v) v``, shape (2,) or (N, 2).

    Args:
        p: The arm's masses [kg], lengths [m] and inertias [kg m²].
        q: ``(q1, q2)``: shoulder angle in [rad], slide in [m]; shape (2,) or (N, 2).
        v: ``(q1', q2')`` in [rad/s], [m/s]; shape (2,) or (N, 2).
    """
    q, v = np.asarray(q, float), np.asarray(v, float)
    h = p.m2 * _r2(p, q)
    return np.stack([2 * h * v[..., 0] * v[..., 1], -h * v[..., 0] ** 2], axis=-1)


def gravity(p: RPArmParameters, q: np.ndarray, g: float = STANDARD_GRAVITY_MAGNITUDE) -> np.ndarray:
    """``G(q)``, shape (2,) or (N, 2).

    Args:
        p: The arm's masses [kg], lengths [m] and inertias [kg m²].
        q: ``(q1, q2)``: shoulder angle in [rad], slide in [m]; shape (2,) or (N, 2).
        g: Magnitude of gravity in [m/s²] (it acts along −z, the arm swinging in the XZ plane).
    """
    q = np.asarray(q, float)
    return np.stack([(p.m1 * p.l1 / 2 + p.m2 * _r2(p, q)) * g * np.cos(q[..., 0]), p.m2 * g * np.sin(q[..., 0])], axis=-1)


def inverse_dynamics(
    p: RPArmParameters, q: np.ndarray, v: np.ndarray, a: np.ndarray, g: float = STANDARD_GRAVITY_MAGNITUDE
) -> np.ndarray:
    """``tau = M(q) a + C(q, v) v + G(q)``, shape (2,) or (N, 2).

    Args:
        p: The arm's masses [kg], lengths [m] and inertias [kg m²].
        q: ``(q1, q2)``: shoulder angle in [rad], slide in [m]; shape (2,) or (N, 2).
        v: ``(q1', q2')`` in [rad/s], [m/s]; shape (2,) or (N, 2).
        a: ``(q1'', q2'')`` in [rad/s²], [m/s²]; shape (2,) or (N, 2).
        g: Magnitude of gravity in [m/s²] (it acts along −z, the arm swinging in the XZ plane).
    """
    a = np.asarray(a, float)
    return np.einsum("...ij,...j->...i", mass_matrix(p, q), a) + coriolis_forces(p, q, v) + gravity(p, q, g)


def kinetic_energy(p: RPArmParameters, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``½ vᵀ M v`` in [J].

    Args:
        p: The arm's masses [kg], lengths [m] and inertias [kg m²].
        q: ``(q1, q2)``: shoulder angle in [rad], slide in [m]; shape (2,) or (N, 2).
        v: ``(q1', q2')`` in [rad/s], [m/s]; shape (2,) or (N, 2).
    """
    v = np.asarray(v, float)
    return 0.5 * np.einsum("...i,...ij,...j->...", v, mass_matrix(p, q), v)


def potential_energy(p: RPArmParameters, q: np.ndarray, g: float = STANDARD_GRAVITY_MAGNITUDE) -> np.ndarray:
    """``m1 g (l1/2) sin q1 + m2 g r2 sin q1`` in [J] (zero at the shoulder's height).

    Args:
        p: The arm's masses [kg], lengths [m] and inertias [kg m²].
        q: ``(q1, q2)``: shoulder angle in [rad], slide in [m]; shape (2,) or (N, 2).
        g: Magnitude of gravity in [m/s²] (it acts along −z, the arm swinging in the XZ plane).
    """
    q = np.asarray(q, float)
    return (p.m1 * p.l1 / 2 + p.m2 * _r2(p, q)) * g * np.sin(q[..., 0])
