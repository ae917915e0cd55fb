"""What robodyn knows of each degree of freedom: name, type and limits."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class JointInfo:
    """One degree of freedom of a robot.

    Attributes:
        name: Joint name in the URDF.
        type: ``"revolute"``, ``"continuous"``, ``"prismatic"`` or ``"floating"``.
        lower, upper: Position limits in [rad] or [m] (±inf when unlimited).
        effort: Effort limit in [N m] or [N] (inf when not given).
        velocity: Velocity limit in [rad/s] or [m/s] (inf when not given).
    """

    name: str
    type: str
    lower: float
    upper: float
    effort: float
    velocity: float
