"""The state of one MJCF reading: the compiler's settings, the default classes, the URDF
being written and what is reported beside it.

This module does not import Pinocchio or MuJoCo.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from robodyn.exceptions import URDFError
from robodyn.urdf.equality import EqualityRecord

#: Actuator elements (their defaults are one kind, ``general``, as in MuJoCo).
ACTUATOR_TAGS = ("general", "motor", "position", "velocity", "intvelocity", "damper", "cylinder", "muscle", "adhesion")
#: Most degrees of freedom read by default: robodyn's ``max_dof`` default
#: (:data:`robodyn.dynamics.options.MAX_DOF`), for readers not given one.
DEFAULT_MAX_DOF = 300
#: Most bodies read per allowed degree of freedom (welded bodies have none).
BODIES_PER_DOF = 20


@dataclass
class Census:
    """Bodies and joints counted while the XML is parsed, refused above the caps before
    the whole tree is built (a 50 MB file of bodies is refused in the first of them).

    The caps: at most ``max_dof`` degrees of freedom (each joint in ``<worldbody>`` counts
    at least one, a free joint six, a ball three) and at most
    ``BODIES_PER_DOF * max_dof`` bodies. ``world`` and ``default`` count the
    ``<worldbody>`` and ``<default>`` elements the parser is inside (an included file is
    parsed with them set to where its ``<include>`` is).
    """

    label: str
    max_dof: int
    bodies: int = 0
    dofs: int = 0
    world: int = 0
    default: int = 0

    def __call__(self, event: str, element: ET.Element) -> None:
        step = 1 if event == "start" else -1
        if element.tag in ("worldbody", "default"):
            self.world += step if element.tag == "worldbody" else 0
            self.default += step if element.tag == "default" else 0
            return
        if event != "start" or not self.world or self.default:
            return
        if element.tag == "body":
            self.bodies += 1
            if self.bodies > BODIES_PER_DOF * self.max_dof:
                limit = BODIES_PER_DOF * self.max_dof
                raise URDFError(
                    self.label,
                    f"the MJCF has more than {limit} bodies ({BODIES_PER_DOF} × max_dof={self.max_dof}; max_dof= raises it)",
                )
        elif element.tag in ("joint", "freejoint"):
            kind = "free" if element.tag == "freejoint" else element.get("type", "hinge")
            self.dofs += {"free": 6, "ball": 3}.get(kind, 1)
            if self.dofs > self.max_dof:
                raise URDFError(
                    self.label, f"the MJCF has more than {self.max_dof} degrees of freedom, above the limit (max_dof= raises it)"
                )


@dataclass(frozen=True)
class Compiler:
    """The ``<compiler>`` settings that change numbers."""

    degree: bool = True
    eulerseq: str = "xyz"
    autolimits: bool = True
    inertiafromgeom: str = "auto"
    meshdir: Path | None = None
    inertiagroups: tuple[int, int] = (0, 5)
    total_mass: float = -1.0


@dataclass
class MjcfRobot:
    """The URDF being written, and what travels beside it.

    Attributes:
        label: The file's label, for messages.
        compiler: The ``<compiler>`` settings.
        defaults: Attributes of each ``<default>`` class by element kind.
        urdf: The ``<robot>`` element being written.
        names: Link and joint names used so far (each URDF name once).
        notes: What the dynamics leaves out, by kind: one warning line each.
        remarks: Readings that differ from MuJoCo's, by sentence: one warning line each.
        floating: Whether the top body has a free joint.
        bodies: The names of every body of the file (sites with one of them are renamed).
        offsets: Each body's link frame in the body frame (its last joint's ``pos``), (3,) in [m].
        joints: The names of the joints written.
        refs: Each joint's nonzero ``ref`` (MuJoCo's qpos = robodyn's q + ref), in [rad] or [m].
        efforts: Each actuated joint's actuator force range, in [N m] or [N].
        actuated: The joints actuators drive (``None``: every joint; no ``<actuator>``
            section, or a transmission other than a joint).
        gravity: The file's gravity in [m/s²] (``None``: it states none).
        disabled: The ``<flag>`` s the file disables that robodyn honours (``damper``, ...).
        equalities: The ``connect`` / ``weld`` records.
        plane: The attributes of ``<worldbody>``'s first plane geom (its defaults under
            them), the robot's ground, or ``None``.
        colliding: The attributes of each geom written as a ``<collision>``.
        base_pose: The free top body's placement in the world (its ``<body pos>`` and
            orientation: MuJoCo's ``qpos0``), position in [m] then quaternion x, y, z, w
            (robodyn's ``q``), or ``None``.
        outside: The joints whose ``qpos0`` (their ``ref``) lies outside their range: the
            robot's start has them at the nearest limit.
        ids: The next MuJoCo id of each kind (``"body"``, ``"joint"``, ``"site"``): an
            unnamed element is named after its id in MuJoCo's order (world body = 0).
    """

    label: str
    compiler: Compiler
    defaults: dict[str, dict[str, dict[str, str]]]
    urdf: ET.Element
    names: set[str] = field(default_factory=set)
    notes: dict[str, list[str]] = field(default_factory=dict)
    remarks: dict[str, list[str]] = field(default_factory=dict)
    floating: bool = False
    bodies: set[str] = field(default_factory=set)
    offsets: dict[str, np.ndarray] = field(default_factory=dict)
    joints: set[str] = field(default_factory=set)
    refs: dict[str, float] = field(default_factory=dict)
    efforts: dict[str, tuple[float, float]] = field(default_factory=dict)
    actuated: set[str] | None = None
    gravity: tuple[float, float, float] | None = None
    disabled: set[str] = field(default_factory=set)
    equalities: tuple[EqualityRecord, ...] = ()
    plane: dict[str, str] | None = None
    colliding: list[dict[str, str]] = field(default_factory=list)
    base_pose: tuple[float, ...] | None = None
    outside: list[str] = field(default_factory=list)
    ids: dict[str, int] = field(default_factory=lambda: {"body": 1, "joint": 0, "site": 0})

    def next_id(self, kind: str) -> int:
        """MuJoCo's id of the next element of a kind in its order (bodies depth first from
        the world's 0; joints and sites body by body).

        Args:
            kind: ``"body"``, ``"joint"`` or ``"site"``.
        """
        self.ids[kind] += 1
        return self.ids[kind] - 1

    def note(self, kind: str, name: str) -> None:
        """Report ``name`` under ``kind``, a kind of what the dynamics leaves out (one
        warning line a kind).

        Args:
            kind: What is left out, e.g. ``"actuators robodyn does not read"``.
            name: The element's name.
        """
        self.notes.setdefault(kind, []).append(name)

    def remark(self, sentence: str, name: str) -> None:
        """Report ``name`` under ``sentence``, a reading that differs from MuJoCo's (one
        warning line a sentence).

        Args:
            sentence: How the reading differs.
            name: The element's name.
        """
        self.remarks.setdefault(sentence, []).append(name)

    def unique(self, name: str, what: str) -> str:
        """``name``, claimed for one link or joint of the URDF.

        Args:
            name: The name.
            what: What the name is for, for the error.

        Raises:
            URDFError: If it is taken already.
        """
        if name in self.names:
            raise URDFError(self.label, f"two links would be named {name!r} ({what}): rename one in the MJCF")
        self.names.add(name)
        return name


def attributes(robot: MjcfRobot, node: ET.Element, childclass: str) -> dict[str, str]:
    """An element's attributes with its class's defaults under them.

    Args:
        robot: The MJCF robot being read (its settings, defaults, notes).
        node: The element.
        childclass: The class its body's ``childclass`` gives (``"main"``: the top class).

    Raises:
        URDFError: If its class is not defined.
    """
    name = node.get("class") or childclass
    if name not in robot.defaults and name != "main":
        raise URDFError(robot.label, f"MJCF class {name!r} is not defined in <default>")
    kind = "general" if node.tag in ACTUATOR_TAGS else node.tag
    merged = dict(robot.defaults.get(name, {}).get(kind, {}))
    merged.update(node.attrib)
    return merged
