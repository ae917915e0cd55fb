"""Edits of a validated URDF that give a new robot: locking joints, welding on a link.

Both return URDF text, so the edited robot is an ordinary robot that Pinocchio and the
independent reference read alike. Nothing here imports Pinocchio.

- :func:`lock_joints` turns moving joints into fixed ones at given positions (e.g. a
  gripper's fingers), folding the joint's motion into its origin; joints that mimic a
  locked joint are locked at the matching position.
- :func:`weld_link` adds a link (a payload, a tool) rigidly attached to an existing one.
"""

from __future__ import annotations

import copy
import difflib
import math
import xml.etree.ElementTree as ET
from typing import cast

import numpy as np

from robodyn.common.rotations import axis_rotation, matrix_rpy, rpy_matrix
from robodyn.common.text import quoted
from robodyn.exceptions import InputError
from robodyn.urdf.validation import URDFSpec


def lock_joints(spec: URDFSpec, positions: dict[str, float], source: str = "<string>") -> str:
    """URDF text with the named joints fixed at the given positions.

    Args:
        spec: The validated URDF.
        positions: Joint name -> position in [rad] or [m].
        source: For messages.

    Raises:
        InputError: For an unknown or fixed joint, a non-finite position, or a position
            outside the joint's limits.
    """
    if not isinstance(positions, dict):
        raise InputError("lock", "a dict {joint name: position}", type(positions).__name__)
    values: dict[str, float] = {}
    for name, value in positions.items():
        joint = spec.joints.get(name) if isinstance(name, str) else None
        if joint is None or joint.type == "fixed":
            close = difflib.get_close_matches(str(name), [j.name for j in spec.joints.values() if j.type != "fixed"], n=3)
            hint = f" (did you mean {', '.join(quoted(c) for c in close)}?)" if close else ""
            raise InputError("lock", f"moving joints of {source}{hint}", quoted(name))
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
            raise InputError(f"lock[{quoted(name)}]", "a number in [rad] or [m]", f"{type(value).__name__} {quoted(value)}")
        value = float(value)
        values[name] = value
        if not math.isfinite(value) or not (joint.lower - 1e-12 <= value <= joint.upper + 1e-12):
            raise InputError("lock", f"a position of {quoted(name)} within [{joint.lower}, {joint.upper}]", repr(value))
    for joint in spec.joints.values():  # mimic joints follow their locked source
        if joint.mimic is not None and joint.mimic.joint in values and joint.name not in values:
            values[joint.name] = joint.mimic.multiplier * values[joint.mimic.joint] + joint.mimic.offset
    root = copy.deepcopy(spec.xml)
    for node in root.findall("joint"):
        joint_name = node.get("name")
        if joint_name is None or joint_name not in values:
            continue
        joint = spec.joints[joint_name]
        rotation = rpy_matrix(joint.origin_rpy)
        translation = joint.origin_xyz.copy()
        if joint.type == "prismatic":
            translation = translation + rotation @ joint.axis * values[joint_name]
        else:
            rotation = rotation @ axis_rotation(joint.axis, values[joint_name])
        for child in list(node):
            if child.tag in ("origin", "axis", "limit", "mimic", "dynamics", "safety_controller", "calibration"):
                node.remove(child)
        node.set("type", "fixed")
        ET.SubElement(
            node,
            "origin",
            xyz=" ".join(repr(float(x)) for x in translation),
            rpy=" ".join(repr(float(x)) for x in matrix_rpy(rotation)),
        )
    return ET.tostring(root, encoding="unicode")


def inertial_element(mass: float, com: np.ndarray, inertia: np.ndarray) -> ET.Element:
    """An ``<inertial>`` element (numbers written to round-trip exactly).

    Args:
        mass: In [kg].
        com: Centre of mass in the link frame, shape (3,), in [m].
        inertia: About the centre of mass, link-frame axes, shape (3, 3), in [kg m²].
    """
    element = ET.Element("inertial")
    ET.SubElement(element, "origin", xyz=" ".join(repr(float(x)) for x in com), rpy="0 0 0")
    ET.SubElement(element, "mass", value=repr(float(mass)))
    ET.SubElement(
        element,
        "inertia",
        ixx=repr(float(inertia[0, 0])), ixy=repr(float(inertia[0, 1])), ixz=repr(float(inertia[0, 2])),
        iyy=repr(float(inertia[1, 1])), iyz=repr(float(inertia[1, 2])), izz=repr(float(inertia[2, 2])),
    )  # fmt: skip
    return element


def weld_link(spec: URDFSpec, parent: str, link: ET.Element, xyz: str = "0 0 0", rpy: str = "0 0 0") -> str:
    """URDF text with ``link`` (a ``<link>`` element) welded to ``parent`` by a fixed joint.

    Args:
        spec: The validated URDF.
        parent: The link it is welded to.
        link: The ``<link>`` element to add (named).
        xyz: The joint's origin in ``parent``'s frame, URDF text, in [m].
        rpy: The joint's roll, pitch, yaw, URDF text, in [rad].
    """
    root = copy.deepcopy(spec.xml)
    root.append(link)
    joint = ET.SubElement(root, "joint", name=f"{link.get('name')}_joint", type="fixed")
    ET.SubElement(joint, "parent", link=parent)
    ET.SubElement(joint, "child", link=cast(str, link.get("name")))  # callers build the link with a name
    ET.SubElement(joint, "origin", xyz=xyz, rpy=rpy)
    return ET.tostring(root, encoding="unicode")
