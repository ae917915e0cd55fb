"""The file-wide settings of an MJCF document: ``<compiler>``, ``<option>`` and the
``<default>`` classes.

This module does not import Pinocchio or MuJoCo.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from robodyn.exceptions import URDFError
from robodyn.urdf.mjcf_state import ACTUATOR_TAGS, Compiler, MjcfRobot
from robodyn.urdf.mjcf_values import AUTO, BOOLEAN, floats, keyword, number


def read_compiler(root: ET.Element, label: str, base_dir: Path | None) -> Compiler:
    """The ``<compiler>`` settings (the last element's value of each, as MuJoCo).

    Args:
        root: The ``<mujoco>`` element.
        label: The file's name, for the error.
        base_dir: The file's folder (``None`` for text), for ``meshdir``.

    Raises:
        URDFError: For settings robodyn does not read, and values MuJoCo refuses.
    """
    settings: dict[str, str] = {}
    for node in root.findall("compiler"):
        settings.update(node.attrib)
    for option in ("boundmass", "boundinertia"):
        if option in settings and number(label, f"<compiler {option}>", settings[option]) > 0:
            raise URDFError(label, f"<compiler {option}> rescales masses or inertias: robodyn does not read it")
    balance = keyword(label, "<compiler>", "balanceinertia", settings.get("balanceinertia", "false"), BOOLEAN)
    autolimits = keyword(label, "<compiler>", "autolimits", settings.get("autolimits", "true"), BOOLEAN)
    coordinate = keyword(label, "<compiler>", "coordinate", settings.get("coordinate", "local"), ("local", "global"))
    if balance == "true" or coordinate != "local":
        raise URDFError(label, "<compiler balanceinertia / coordinate=global> is not read by robodyn")
    angle = keyword(label, "<compiler>", "angle", settings.get("angle", "degree"), ("degree", "radian"))
    sequence = settings.get("eulerseq", "xyz")
    if len(sequence) != 3 or any(axis not in "xyzXYZ" for axis in sequence):
        raise URDFError(label, f"<compiler eulerseq={sequence!r}> must be three of x, y, z, X, Y, Z")
    meshdir = settings.get("meshdir", settings.get("assetdir"))
    folder = None if base_dir is None else (base_dir / meshdir if meshdir else base_dir)
    groups = floats(label, "<compiler inertiagrouprange>", settings.get("inertiagrouprange", "0 5"), 2)
    if any(group != int(group) for group in groups):
        raise URDFError(label, f"<compiler inertiagrouprange={settings['inertiagrouprange']!r}> must be two integers")
    return Compiler(
        angle == "degree",
        sequence,
        autolimits == "true",
        keyword(label, "<compiler>", "inertiafromgeom", settings.get("inertiafromgeom", "auto"), AUTO),
        folder,
        (int(groups[0]), int(groups[1])),
        number(label, "<compiler settotalmass>", settings.get("settotalmass", "-1")),
    )


def check_option(root: ET.Element, robot: MjcfRobot) -> None:
    """Report ``<option>`` settings the dynamics does not take.

    Args:
        root: The ``<mujoco>`` element.
        robot: The MJCF robot being read (its settings, defaults, notes).
    """
    for option in root.findall("option"):
        gravity = option.get("gravity")
        if gravity is not None and not np.allclose(floats(robot.label, "option", gravity, 3), [0, 0, -9.81]):
            robot.note("<option gravity> settings", f"gravity {gravity.strip()} (pass gravity= instead)")


def read_defaults(root: ET.Element, label: str) -> dict[str, dict[str, dict[str, str]]]:
    """Every class of the ``<default>`` trees: attributes by element kind, inherited
    downwards, as MuJoCo reads them.

    The top ``<default>`` is the class ``main`` (several top elements add to it); a nested
    class needs a name no other class has.

    Args:
        root: The ``<mujoco>`` element.
        label: The file's name, for the error.

    Raises:
        URDFError: For a renamed top class, a nested class without a name, or a name
            defined twice (MuJoCo refuses each).
    """
    table: dict[str, dict[str, dict[str, str]]] = {}
    for top in root.findall("default"):
        name = top.get("class", "main")
        if name != "main":
            raise URDFError(label, f"the top <default> is the class 'main' and cannot be renamed ({name!r}), as in MuJoCo")
        _read_class(top, "main", table.get("main", {}), table, label)
    return table


def _read_class(node: ET.Element, name: str, inherited: dict[str, dict[str, str]], table: dict, label: str) -> None:
    own = {kind: dict(values) for kind, values in inherited.items()}
    for child in node:
        if child.tag != "default":
            own.setdefault(_kind(child.tag), {}).update(child.attrib)
    table[name] = own
    for child in node.findall("default"):
        nested = child.get("class")
        if not nested:
            raise URDFError(label, f"a <default> inside class {name!r} has no class name (MuJoCo refuses an empty one)")
        if nested in table:
            raise URDFError(label, f"the <default> class {nested!r} is defined twice (MuJoCo refuses a repeated name)")
        _read_class(child, nested, own, table, label)


def _kind(tag: str) -> str:
    """The kind of defaults an element sets (every actuator element: ``general``)."""
    return "general" if tag in ACTUATOR_TAGS else tag
