"""The reference's centroidal quantities: centre of mass and momentum summed body by body.

Independent of Pinocchio's ``centerOfMass`` and ``computeCentroidalMap`` (the composite
rigid-body route): for bodies of mass ``mᵢ`` whose centres of mass are at ``pᵢ`` and move
with ``vᵢ``, turning with ``ωᵢ``, inertia ``Iᵢ`` about their centre of mass in world
axes (``Rᵢ Īᵢ Rᵢᵀ``), the sums straight from the definitions

    c = Σ mᵢ pᵢ / m,       l = Σ mᵢ vᵢ,       k = Σ (pᵢ − c) × mᵢ vᵢ + Iᵢ ωᵢ

(``k``: the angular momentum about the centre of mass, world axes). The bodies' motion
comes from the reference's own kinematics (:meth:`ReferenceRobot.body_motion`). A joint's
armature (the reference's rotor bodies) is a model of the motor's inertia reflected to the
joint, not a body of the robot: it is left out here, as Pinocchio leaves it out. The
bodies are the moving ones (links welded to a fixed base's world are not counted).
"""

from __future__ import annotations

import numpy as np


def center_of_mass(masses: np.ndarray, positions: np.ndarray) -> np.ndarray:
    """``Σ mᵢ pᵢ / m``.

    Args:
        masses: Shape (B,), in [kg].
        positions: Centres of mass of the bodies, shape (N, B, 3), in [m].

    Returns:
        Shape (N, 3), in [m].
    """
    return np.einsum("b,nba->na", masses, positions) / masses.sum()


def centroidal_momentum(
    masses: np.ndarray, positions: np.ndarray, velocities: np.ndarray, inertias: np.ndarray, omegas: np.ndarray
) -> np.ndarray:
    """``(Σ mᵢ vᵢ, Σ (pᵢ − c) × mᵢ vᵢ + Iᵢ ωᵢ)``.

    Args:
        masses: Shape (B,), in [kg].
        positions, velocities: Centres of mass and their velocities, shape (N, B, 3), in
            [m] and [m/s].
        inertias: Inertias about the centres of mass in world axes, shape (N, B, 3, 3),
            in [kg m²].
        omegas: Angular velocities, shape (N, B, 3), in [rad/s].

    Returns:
        Linear [kg m/s] then angular momentum [kg m²/s] about the centre of mass, world
        axes, shape (N, 6).
    """
    linear = masses[None, :, None] * velocities
    lever = positions - center_of_mass(masses, positions)[:, None, :]
    angular = np.cross(lever, linear).sum(axis=1) + np.einsum("nbij,nbj->ni", inertias, omegas)
    return np.concatenate([linear.sum(axis=1), angular], axis=1)


__all__ = ["center_of_mass", "centroidal_momentum"]
