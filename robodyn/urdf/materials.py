"""Link materials: densities, and the mass properties of primitive shapes made of them.

Answers the lecture's first question (plastic, aluminium or steel links?) with numbers:
a generated arm takes its links' geometry and a material and gets its masses and inertias
from them (:meth:`robodyn.urdf.models.RPArmParameters.from_material`).
"""

from __future__ import annotations

import numpy as np

from robodyn.exceptions import InputError

#: Densities in [kg/m³] (typical handbook values).
DENSITIES: dict[str, float] = {
    "abs": 1040.0,  # ABS plastic, as 3D-printed or moulded arms
    "aluminium": 2700.0,
    "steel": 7850.0,
}
#: Other names users write for the same materials.
ALIASES = {"plastic": "abs", "aluminum": "aluminium", "al": "aluminium"}


def density(material: str | float) -> float:
    """Density in [kg/m³] of a named material, or a density given as a number.

    Args:
        material: A material name (:data:`DENSITIES`) or a density in [kg/m³].

    Raises:
        InputError: For an unknown name or a non-positive density.
    """
    if isinstance(material, str):
        key = ALIASES.get(material.lower(), material.lower())
        if key in DENSITIES:
            return DENSITIES[key]
        try:
            material = float(material)
        except ValueError:
            raise InputError("material", f"one of {', '.join(DENSITIES)} or a density in kg/m³", repr(material)) from None
    value = float(material)
    if not (np.isfinite(value) and value > 0):
        raise InputError("material", "a positive density in kg/m³", repr(material))
    return value


def box_mass(material: str | float, size: tuple[float, float, float]) -> float:
    """Mass in [kg] of a solid box with sides ``size`` in [m].

    Args:
        material: A material name (:data:`DENSITIES`) or a density in [kg/m³].
        size: Side lengths in [m].
    """
    return density(material) * float(np.prod(size))


def box_inertia(mass: float, size: tuple[float, float, float]) -> np.ndarray:
    """Inertia in [kg m²] about the centre of a solid box, box axes, shape (3, 3).

    Args:
        mass: Mass in [kg].
        size: Side lengths along the box's x, y, z, in [m].
    """
    x, y, z = size
    return mass / 12 * np.diag([y**2 + z**2, x**2 + z**2, x**2 + y**2])
