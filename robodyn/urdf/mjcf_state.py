"""The state of one MJCF reading: the compiler's settings, the default classes, the URDF
being written and what is reported beside it.

This module does not import Pinocchio or MuJoCo.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

from robodyn.exceptions import URDFError


@dataclass(frozen=True)
class Compiler:
    """The ``<compiler>`` settings that change numbers."""

    degree: bool = True
    eulerseq: str = "xyz"
    autolimits: bool = True
    inertiafromgeom: str = "auto"
    meshdir: Path | None = None
    inertiagroups: str = "0 5"
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
        floating: Whether the top body has a free joint.
    """

    label: str
    compiler: Compiler
    defaults: dict[str, dict[str, dict[str, str]]]
    urdf: ET.Element
    names: set[str] = field(default_factory=set)
    notes: dict[str, list[str]] = field(default_factory=dict)
    floating: bool = False

    def note(self, kind: str, name: str) -> None:
        """Report ``name`` under ``kind`` (one warning line a kind)."""
        self.notes.setdefault(kind, []).append(name)

    def unique(self, name: str, what: str) -> str:
        """``name``, claimed for one link or joint of the URDF.

        Raises:
            URDFError: If it is taken already.
        """
        if name in self.names:
            raise URDFError(self.label, f"two links would be named {name!r} ({what}): rename one in the MJCF")
        self.names.add(name)
        return name


def attributes(robot: MjcfRobot, node: ET.Element, childclass: str) -> dict[str, str]:
    """An element's attributes with its class's defaults under them.

    Raises:
        URDFError: If its class is not defined.
    """
    name = node.get("class") or childclass
    if name not in robot.defaults and name != "main":
        raise URDFError(robot.label, f"MJCF class {name!r} is not defined in <default>")
    merged = dict(robot.defaults.get(name, {}).get(node.tag, {}))
    merged.update(node.attrib)
    return merged
