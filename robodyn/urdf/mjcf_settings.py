"""The file-wide settings of an MJCF document: ``<compiler>``, ``<option>`` and the
``<default>`` classes.

This module does not import Pinocchio or MuJoCo.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from robodyn.exceptions import URDFError
from robodyn.urdf.mjcf_state import Compiler, MjcfRobot
from robodyn.urdf.mjcf_values import floats, number


def read_compiler(root: ET.Element, label: str, base_dir: Path | None) -> Compiler:
    """The ``<compiler>`` settings (the last element's value of each, as MuJoCo).

    Raises:
        URDFError: For settings robodyn does not read.
    """
    settings: dict[str, str] = {}
    for node in root.findall("compiler"):
        settings.update(node.attrib)
    for option in ("boundmass", "boundinertia"):
        if option in settings and number(label, "compiler", settings[option]) > 0:
            raise URDFError(label, f"<compiler {option}> rescales masses or inertias: robodyn does not read it")
    if settings.get("balanceinertia", "false") == "true" or settings.get("coordinate", "local") != "local":
        raise URDFError(label, "<compiler balanceinertia / coordinate=global> is not read by robodyn")
    angle = settings.get("angle", "degree")
    if angle not in ("degree", "radian"):
        raise URDFError(label, f"<compiler angle={angle!r}> must be 'degree' or 'radian'")
    sequence = settings.get("eulerseq", "xyz")
    if len(sequence) != 3 or any(axis not in "xyzXYZ" for axis in sequence):
        raise URDFError(label, f"<compiler eulerseq={sequence!r}> must be three of x, y, z, X, Y, Z")
    meshdir = settings.get("meshdir", settings.get("assetdir"))
    folder = None if base_dir is None else (base_dir / meshdir if meshdir else base_dir)
    return Compiler(
        angle == "degree",
        sequence,
        settings.get("autolimits", "true") == "true",
        settings.get("inertiafromgeom", "auto"),
        folder,
        settings.get("inertiagrouprange", "0 5"),
        number(label, "compiler settotalmass", settings.get("settotalmass", "-1")),
    )


def check_option(root: ET.Element, robot: MjcfRobot) -> None:
    """Report ``<option>`` settings the dynamics does not take."""
    for option in root.findall("option"):
        gravity = option.get("gravity")
        if gravity is not None and not np.allclose(floats(robot.label, "option", gravity, 3), [0, 0, -9.81]):
            robot.note("<option gravity> settings", f"gravity {gravity.strip()} (pass gravity= instead)")


def read_defaults(node: ET.Element, name: str, inherited: dict[str, dict[str, str]], table: dict) -> None:
    """Every class of a ``<default>`` tree: attributes by element kind, inherited downwards."""
    own = {kind: dict(values) for kind, values in inherited.items()}
    for child in node:
        if child.tag != "default":
            own.setdefault(child.tag, {}).update(child.attrib)
    table[name] = own
    for child in node.findall("default"):
        read_defaults(child, child.get("class") or name, own, table)
