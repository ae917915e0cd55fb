"""MJCF bodies and their joints, written as URDF links and joints.

A body's joints act in order at their ``pos`` (a body with several joints becomes a chain
through massless links); the link's frame sits at its last joint's position and
everything in the body is placed relative to it; a body without joints is welded. This
module does not import Pinocchio or MuJoCo.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import numpy as np

from robodyn.exceptions import URDFError
from robodyn.urdf.mjcf_geoms import write_link
from robodyn.urdf.mjcf_physics import joint_effort
from robodyn.urdf.mjcf_state import MjcfRobot, attributes
from robodyn.urdf.mjcf_values import (
    AUTO,
    BOOLEAN,
    angle,
    floats,
    keyword,
    matrix_quaternion,
    number,
    pose,
    text,
    translation,
    unit,
    write_origin,
)

#: MuJoCo's ``mjMINVAL``: the least mass of a moving body.
MIN_MASS = 1e-15


def free_joint(robot: MjcfRobot, body: ET.Element) -> ET.Element | None:
    """The body's free joint (``<freejoint>`` or ``<joint type="free">``), if any.

    Args:
        robot: The MJCF robot being read (its settings, defaults, notes).
        body: The ``<body>`` element.
    """
    for joint in body.findall("freejoint"):
        return joint
    for joint in body.findall("joint"):
        if attributes(robot, joint, body.get("childclass") or "main").get("type") == "free":
            return joint
    return None


def read_body(robot: MjcfRobot, body: ET.Element, parent: str | None, placement: np.ndarray, childclass: str) -> None:
    """One body and everything below it.

    Args:
        robot: The URDF being written.
        body: The ``<body>``.
        parent: The parent link (``None`` for a floating root).
        placement: The body frame in the parent link's frame, 4×4 (before this body's pos).
        childclass: The class in force.
    """
    childclass = body.get("childclass") or childclass
    values = attributes(robot, body, childclass)
    body_id = robot.next_id("body")  # an unnamed body is named after MuJoCo's id
    name = robot.unique(body.get("name") or f"body{body_id}", "an MJCF body")
    where = f'body "{name}"'
    if keyword(robot.label, where, "mocap", values.get("mocap", "false"), BOOLEAN) == "true":
        raise URDFError(robot.label, f"{where}: mocap bodies are not read by robodyn")
    if number(robot.label, f"{where}: gravcomp", values.get("gravcomp", "0")) != 0:
        robot.note("body gravcomp settings", name)
    frame = placement @ pose(robot, where, values) if parent is not None else np.eye(4)
    if parent is None:  # a free body starts where the file puts it (MuJoCo's qpos0)
        start = pose(robot, where, values)
        robot.base_pose = (*start[:3, 3].tolist(), *matrix_quaternion(start[:3, :3]).tolist())
    link, offset = _read_joints(robot, body, name, parent, frame, childclass)
    robot.offsets[name] = offset
    mass = write_link(robot, body, name, link, offset, childclass)
    moves = parent is None or any(node.tag in ("joint", "freejoint") for node in body)
    if moves and not mass >= MIN_MASS:
        raise URDFError(robot.label, f"{where} moves and has no mass (MuJoCo refuses a moving body under {MIN_MASS} kg)")
    for child in body.findall("body"):
        read_body(robot, child, name, translation(-offset), childclass)


def _read_joints(
    robot: MjcfRobot, body: ET.Element, name: str, parent: str | None, frame: np.ndarray, childclass: str
) -> tuple[ET.Element, np.ndarray]:
    """The body's joints as a URDF chain ending at the body's link; returns the link and
    the link frame's position in the body frame (its last joint's ``pos``)."""
    joints = [node for node in body if node.tag in ("joint", "freejoint")]
    moving = [node for node in joints if not (parent is None and node is free_joint(robot, body))]
    if parent is None and moving:
        raise URDFError(robot.label, f'body "{name}": a free body with more joints is not read by robodyn')
    if parent is not None and any(node.tag == "freejoint" for node in joints):
        raise URDFError(robot.label, f'body "{name}": a free joint is only read on the top body (a floating base)')
    ids = {id(node): robot.next_id("joint") for node in joints}  # MuJoCo's joint ids, the free joint's too
    previous, previous_pos = parent, np.zeros(3)
    for index, node in enumerate(moving):
        values = attributes(robot, node, childclass)
        joint_name = node.get("name") or f"joint{ids[id(node)]}"
        position = floats(robot.label, f'joint "{joint_name}"', values.get("pos", "0 0 0"), 3)
        link_name = name if index == len(moving) - 1 else robot.unique(f"{name}__{joint_name}", "a link between joints")
        origin = frame @ translation(position) if index == 0 else translation(position - previous_pos)
        assert previous is not None
        _write_joint(robot, joint_name, values, previous, link_name, origin)
        previous, previous_pos = link_name, position
        if link_name != name:
            ET.SubElement(robot.urdf, "link", name=link_name)
    link = ET.SubElement(robot.urdf, "link", name=name)
    if not moving and parent is not None:
        fixed = ET.SubElement(robot.urdf, "joint", name=robot.unique(f"{name}_weld", "a welded body's joint"), type="fixed")
        write_origin(fixed, frame)
        ET.SubElement(fixed, "parent", link=parent)
        ET.SubElement(fixed, "child", link=name)
    return link, previous_pos


def _write_joint(robot: MjcfRobot, name: str, values: dict[str, str], parent: str, child: str, origin: np.ndarray) -> None:
    """One hinge or slide joint; its ``ref`` kept as the offset of robodyn's coordinate
    (q = qpos − ref: the body sits at its modelled pose at q = 0), its range shifted by it."""
    where = f'joint "{name}"'
    kind = keyword(robot.label, where, "type", values.get("type", "hinge"), ("hinge", "slide", "ball", "free"))
    if kind not in ("hinge", "slide"):
        reason = "ball joints are not read by robodyn" if kind == "ball" else f"a {kind} joint is not read here"
        raise URDFError(robot.label, f"{where}: {reason} (hinge, slide and a free top body are)")
    ref = number(robot.label, f"{where}: ref", values.get("ref", "0"))
    ref = angle(robot, ref) if kind == "hinge" else ref
    if ref:
        robot.refs[name] = ref
    if number(robot.label, f"{where}: stiffness", values.get("stiffness", "0")) != 0 and "spring" not in robot.disabled:
        robot.note("joint stiffnesses (springs)", name)
    axis = unit(robot.label, where, floats(robot.label, where, values.get("axis", "0 0 1"), 3))
    lower, upper = _range(robot, where, values, kind)
    urdf_type = "prismatic" if kind == "slide" else ("revolute" if math.isfinite(lower) else "continuous")
    joint = ET.SubElement(robot.urdf, "joint", name=name, type=urdf_type)
    robot.joints.add(name)
    write_origin(joint, origin)
    ET.SubElement(joint, "parent", link=parent)
    ET.SubElement(joint, "child", link=child)
    ET.SubElement(joint, "axis", xyz=text(axis))
    effort = joint_effort(robot, where, name, values)
    limit = {} if math.isinf(effort) else {"effort": repr(effort)}
    if not lower <= ref <= upper:  # MuJoCo starts it outside its range; robodyn at the nearest limit
        robot.outside.append(name)
    if math.isfinite(lower):
        ET.SubElement(joint, "limit", {"lower": repr(lower - ref), "upper": repr(upper - ref), **limit})
    elif urdf_type == "prismatic":  # Bullet's encoding of no position limit, marked as robodyn's own (no warning)
        ET.SubElement(joint, "limit", {"lower": "1.0", "upper": "-1.0", "unlimited": "true", **limit})
    elif limit:
        ET.SubElement(joint, "limit", limit)
    damping, friction, armature = (
        number(robot.label, f"{where}: {key}", values.get(key, "0")) for key in ("damping", "frictionloss", "armature")
    )
    damping = 0.0 if "damper" in robot.disabled else damping  # <flag damper="disable"/>, as MuJoCo
    friction = 0.0 if "frictionloss" in robot.disabled else friction
    if damping or friction or armature:
        ET.SubElement(joint, "dynamics", damping=repr(damping), friction=repr(friction), armature=repr(armature))


def _range(robot: MjcfRobot, where: str, values: dict[str, str], kind: str) -> tuple[float, float]:
    limited = keyword(robot.label, where, "limited", values.get("limited", "auto"), AUTO)
    if limited == "auto":
        limited = "true" if robot.compiler.autolimits and "range" in values else "false"
    if limited != "true":
        return -math.inf, math.inf
    lower, upper = floats(robot.label, where, values.get("range", "0 0"), 2)
    if kind == "hinge":
        lower, upper = angle(robot, lower), angle(robot, upper)
    if lower >= upper:
        raise URDFError(robot.label, f"{where}: range [{lower}, {upper}] must have lower < upper")
    return float(lower), float(upper)
