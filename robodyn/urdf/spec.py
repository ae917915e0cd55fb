"""The validated form of a URDF: links, joints, inertials, mimic relations, problems.

Produced by :func:`robodyn.urdf.validation.parse_urdf` (which re-exports these names).
This module does not import Pinocchio.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field

import numpy as np

from robodyn.common.text import printable


@dataclass(frozen=True)
class Problem:
    """One problem found in a URDF.

    Attributes:
        element: The offending element, e.g. ``'link "l1"'``, or ``None`` for the document.
        rule: The rule broken, as a sentence fragment.
        severity: ``"error"`` (the model is refused) or ``"warning"`` (legal but suspicious).
        loud: A warning that loading shows (a :class:`~robodyn.exceptions.RobodynWarning`)
            and that ``strict=True`` turns into an error; other warnings only ``lint`` shows.
    """

    element: str | None
    rule: str
    severity: str = "error"
    loud: bool = False

    def __str__(self) -> str:
        return printable(f"{self.element}: {self.rule}" if self.element else self.rule)


@dataclass(frozen=True)
class Inertial:
    """Mass properties of a link, in the link frame.

    Attributes:
        mass: Mass in [kg].
        origin_xyz: Centre of mass in [m].
        origin_rpy: Orientation of the inertia frame, roll-pitch-yaw in [rad].
        inertia: 3×3 inertia about the centre of mass, in the inertia frame, in [kg m²].
    """

    mass: float
    origin_xyz: np.ndarray
    origin_rpy: np.ndarray
    inertia: np.ndarray


@dataclass(frozen=True)
class Mimic:
    """A joint driven by another: ``q = multiplier * q_source + offset``."""

    joint: str
    multiplier: float = 1.0
    offset: float = 0.0


@dataclass(frozen=True)
class JointSpec:
    """One URDF joint, validated.

    Attributes:
        name, type, parent, child: As in the URDF.
        origin_xyz: Joint frame position in the parent link frame, in [m].
        origin_rpy: Joint frame orientation, roll-pitch-yaw in [rad].
        axis: Unit joint axis in the joint frame.
        lower, upper: Position limits in [rad] or [m] (±inf for continuous joints).
        effort, velocity: Effort limit in [N m] or [N], velocity limit in [rad/s] or [m/s].
        mimic: The mimic relation, or ``None``.
        damping: Viscous damping b (``<dynamics damping>``, MJCF ``damping``): the joint
            torque −b q̇, in [N m s/rad] or [N s/m].
        friction: Coulomb friction f (``<dynamics friction>``, MJCF ``frictionloss``): the
            largest torque the joint's friction resists with, in [N m] or [N].
        armature: Rotor inertia reflected to the joint (MJCF ``armature``, ``load(armature=)``),
            added to the diagonal of M, in [kg m²] or [kg].
    """

    name: str
    type: str
    parent: str
    child: str
    origin_xyz: np.ndarray
    origin_rpy: np.ndarray
    axis: np.ndarray
    lower: float = -math.inf
    upper: float = math.inf
    effort: float = math.inf
    velocity: float = math.inf
    mimic: Mimic | None = None
    damping: float = 0.0
    friction: float = 0.0
    armature: float = 0.0


@dataclass
class URDFSpec:
    """A validated URDF: its links, joints (document order) and the parsed XML tree."""

    name: str
    root: str
    links: dict[str, Inertial | None]
    joints: dict[str, JointSpec]
    xml: ET.Element = field(repr=False)

    def child_joints(self, link: str) -> list[JointSpec]:
        """Joints whose parent is ``link``, in document order.

        Args:
            link: The link's name.
        """
        if not hasattr(self, "_children"):
            self._children = child_index(self.joints)
        return list(self._children.get(link, []))


def child_index(joints: dict[str, JointSpec]) -> dict[str, list[JointSpec]]:
    """Child joints of every link, in document order (one pass: linear time).

    Args:
        joints: The joints by name.
    """
    children: dict[str, list[JointSpec]] = {}
    for joint in joints.values():
        children.setdefault(joint.parent, []).append(joint)
    return children
