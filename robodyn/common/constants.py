"""Physical constants shared by the layers."""

from __future__ import annotations

#: Magnitude of the standard gravity of URDF and Pinocchio, in [m/s²].
STANDARD_GRAVITY_MAGNITUDE = 9.81

#: The default gravity vector in the world frame (along -Z), in [m/s²].
STANDARD_GRAVITY = (0.0, 0.0, -STANDARD_GRAVITY_MAGNITUDE)
