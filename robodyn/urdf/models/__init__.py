"""Robots robodyn generates itself, by name.

``GENERATED`` maps each generated robot's name to a function returning its URDF text with
default parameters; :func:`robodyn.load` accepts these names.
"""

from __future__ import annotations

from collections.abc import Callable

from robodyn.urdf.models.pendulum import pendulum_urdf
from robodyn.urdf.models.rp_arm import RPArmParameters, rp_arm_urdf

GENERATED: dict[str, Callable[[], str]] = {"rp_arm": rp_arm_urdf, "pendulum": pendulum_urdf}

__all__ = ["GENERATED", "RPArmParameters", "pendulum_urdf", "rp_arm_urdf"]
