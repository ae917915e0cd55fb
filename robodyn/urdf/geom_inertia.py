"""Mass properties of MJCF geoms, as MuJoCo's compiler computes a body's inertia from them
(``<compiler inertiafromgeom>``): solid primitives of uniform density.

This module does not import Pinocchio or MuJoCo.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

#: Geom types whose mass properties are computed here (MuJoCo's solid primitives).
SOLIDS = ("sphere", "capsule", "cylinder", "ellipsoid", "box")


def solid_properties(kind: str, size: Sequence[float], *, density: float, mass: float | None) -> tuple[float, np.ndarray]:
    """Mass and principal inertia of a solid geom about its centre, in its own frame.

    Args:
        kind: One of :data:`SOLIDS`.
        size: MuJoCo's ``size``: radius (sphere); radius, half-length (capsule, cylinder);
            semi-axes (ellipsoid); half-sizes (box); in [m].
        density: Density in [kg/m³] (used when ``mass`` is ``None``).
        mass: The geom's ``mass`` attribute in [kg], or ``None``.

    Returns:
        The mass in [kg] and the diagonal of the inertia, shape (3,), in [kg m²].
    """
    if kind == "sphere":
        radius = size[0]
        volume = 4 * math.pi * radius**3 / 3
        weight = density * volume if mass is None else mass
        return weight, np.full(3, 2 * weight * radius**2 / 5)
    if kind == "capsule":
        return _capsule(size[0], 2 * size[1], density, mass)
    if kind == "cylinder":
        radius, height = size[0], 2 * size[1]
        weight = density * math.pi * radius**2 * height if mass is None else mass
        side = weight * (3 * radius**2 + height**2) / 12
        return weight, np.array([side, side, weight * radius**2 / 2])
    a, b, c = size[:3]
    if kind == "ellipsoid":
        weight = density * 4 * math.pi * a * b * c / 3 if mass is None else mass
        return weight, weight / 5 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])
    weight = density * 8 * a * b * c if mass is None else mass  # box
    return weight, weight / 3 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])


def _capsule(radius: float, height: float, density: float, mass: float | None) -> tuple[float, np.ndarray]:
    """A cylinder of ``height`` with two hemispherical caps, as MuJoCo computes it."""
    cylinder, sphere = math.pi * radius**2 * height, 4 * math.pi * radius**3 / 3
    total = density * (cylinder + sphere) if mass is None else mass
    sphere_mass = total * sphere / (cylinder + sphere)
    cylinder_mass = total - sphere_mass
    side = cylinder_mass * (3 * radius**2 + height**2) / 12
    side += 2 * sphere_mass * radius**2 / 5 + sphere_mass * height * (3 * radius + 2 * height) / 8
    return total, np.array([side, side, cylinder_mass * radius**2 / 2 + 2 * sphere_mass * radius**2 / 5])


def combine(parts: Sequence[tuple[float, np.ndarray, np.ndarray, np.ndarray]]) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass, centre of mass and inertia about it of rigidly joined parts.

    Args:
        parts: ``(mass, position (3,), rotation (3, 3), principal inertia (3,))`` each, in
            one frame, in [kg], [m], [kg m²].

    Returns:
        Total mass, centre of mass (3,) and 3×3 inertia about it, in that frame.
    """
    total = sum(part[0] for part in parts)
    if total <= 0:
        return 0.0, np.zeros(3), np.zeros((3, 3))
    centre = sum(mass * position for mass, position, _, _ in parts) / total
    inertia = np.zeros((3, 3))
    for mass, position, rotation, principal in parts:
        offset = position - centre
        inertia += rotation @ np.diag(principal) @ rotation.T + mass * (offset @ offset * np.eye(3) - np.outer(offset, offset))
    return float(total), np.asarray(centre), inertia
