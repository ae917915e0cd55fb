"""The URDF document Pinocchio builds from, written by robodyn from the validated spec.

Pinocchio never reads the user's text: every number it gets was parsed by the validator
(:func:`robodyn.urdf.validation.parse_number`) and written back here as ``repr(float)``,
so robodyn's checks, :class:`~robodyn.dynamics.robot.Robot`, the reference and the viewer
cannot disagree about a mass, an inertia, an origin, an axis, a limit or a mimic relation
(``" 1.0 "``, ``"1_000"`` or ``"２"`` are either refused by the validator or read the
same everywhere). A moving joint's ``<dynamics damping friction>`` is written back (Pinocchio
reads it into ``model.damping`` and ``model.friction``, as it would from the user's file);
what Pinocchio reads and robodyn does not use (visuals, collisions, gazebo tags) is left out.

The copy is also normalised:

- continuous joints become revolute joints with limits ±:data:`UNBOUNDED`, so that ``q``
  holds their angle (one number a degree of freedom) instead of a (cos, sin) pair;
- joint axes have unit length;
- a ``<mimic>`` on a fixed joint, or of a joint that does not exist, is dropped;
- joints get canonical names ``j0000000``, ``j0000001``, ... (:func:`normalised_urdf`
  returns the map back to the URDF's names). Pinocchio orders sibling subtrees by joint
  name; the canonical names keep that order except where a mimic joint's subtree would
  come before its source's, which Pinocchio refuses (romeo, talos_full): there the
  source's subtree is moved first.

This module does not import Pinocchio.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import numpy as np

from robodyn.urdf.validation import JointSpec, URDFSpec

#: Limit written for continuous joints, in [rad].
UNBOUNDED = 1e10


def _numbers(values: np.ndarray) -> str:
    return " ".join(repr(float(value)) for value in values)


def _ordered_joints(spec: URDFSpec) -> list[JointSpec]:
    """Joints in the depth-first order Pinocchio will use for the written document."""
    children = {link: sorted(spec.child_joints(link), key=lambda joint: joint.name) for link in spec.links}
    # Joints below each joint (its subtree), to move a mimic's source subtree first.
    below: dict[str, set[str]] = {}

    def subtree(joint: JointSpec) -> set[str]:
        names, stack = set(), [joint]
        while stack:
            current = stack.pop()
            names.add(current.name)
            stack += children.get(current.child, [])
        return names

    sources = {joint.mimic.joint for joint in spec.joints.values() if joint.mimic is not None and joint.type != "fixed"}

    def ordered(link: str) -> list[JointSpec]:
        siblings = children.get(link, [])
        if sources and len(siblings) > 1:
            siblings = _sources_first(siblings, spec, sources, below, subtree)
        return siblings

    order: list[JointSpec] = []
    stack = list(reversed(ordered(spec.root)))
    while stack:
        joint = stack.pop()
        order.append(joint)
        stack += reversed(ordered(joint.child))
    return order


def _sources_first(siblings: list[JointSpec], spec: URDFSpec, sources: set[str], below: dict, subtree) -> list[JointSpec]:
    """Siblings (sorted by name) with every subtree holding a mimic source moved before
    the subtrees holding joints that mimic it (a stable topological sort)."""
    for joint in siblings:
        if joint.name not in below:
            below[joint.name] = subtree(joint)
    holder = {name: sibling.name for sibling in siblings for name in below[sibling.name]}
    after: dict[str, set[str]] = {sibling.name: set() for sibling in siblings}  # must come after
    for sibling in siblings:
        for name in below[sibling.name]:
            mimic = spec.joints[name].mimic
            if mimic is not None and spec.joints[name].type != "fixed":
                source_holder = holder.get(mimic.joint)
                if source_holder is not None and source_holder != sibling.name:
                    after[sibling.name].add(source_holder)
    ordered: list[JointSpec] = []
    remaining = list(siblings)
    while remaining:
        placed = {joint.name for joint in ordered}
        ready = next((joint for joint in remaining if after[joint.name] <= placed), remaining[0])
        ordered.append(ready)
        remaining.remove(ready)
    return ordered


def normalised_urdf(spec: URDFSpec) -> tuple[str, dict[str, str]]:
    """The URDF text Pinocchio builds from, and the map canonical joint name -> URDF name.

    Args:
        spec: The validated URDF.

    Returns:
        The document, and ``{"j0000000": "shoulder_pan_joint", ...}``.
    """
    order = _ordered_joints(spec)
    canonical = {joint.name: f"j{index:07d}" for index, joint in enumerate(order)}
    root = ET.Element("robot", name="robodyn")
    for name, inertial in spec.links.items():
        link = ET.SubElement(root, "link", name=name)
        if inertial is None:
            continue
        node = ET.SubElement(link, "inertial")
        ET.SubElement(node, "origin", xyz=_numbers(inertial.origin_xyz), rpy=_numbers(inertial.origin_rpy))
        ET.SubElement(node, "mass", value=repr(float(inertial.mass)))
        matrix = inertial.inertia
        ET.SubElement(
            node,
            "inertia",
            {key: repr(float(matrix[i, j])) for key, (i, j) in _INERTIA_INDEX.items()},
        )
    for joint in order:
        moving = joint.type != "fixed"
        node = ET.SubElement(
            root, "joint", name=canonical[joint.name], type="revolute" if joint.type == "continuous" else joint.type
        )
        ET.SubElement(node, "origin", xyz=_numbers(joint.origin_xyz), rpy=_numbers(joint.origin_rpy))
        ET.SubElement(node, "parent", link=joint.parent)
        ET.SubElement(node, "child", link=joint.child)
        if not moving:
            continue
        ET.SubElement(node, "axis", xyz=_numbers(joint.axis))
        lower, upper = (-UNBOUNDED, UNBOUNDED) if joint.type == "continuous" else (joint.lower, joint.upper)
        lower, upper = max(lower, -UNBOUNDED), min(upper, UNBOUNDED)  # no limit (lower > upper in the URDF)
        ET.SubElement(
            node,
            "limit",
            lower=repr(float(lower)),
            upper=repr(float(upper)),
            effort=repr(float(joint.effort)) if math.isfinite(joint.effort) else "0.0",
            velocity=repr(float(joint.velocity)) if math.isfinite(joint.velocity) else "0.0",
        )
        if joint.damping or joint.friction:  # Pinocchio reads them into model.damping, model.friction
            ET.SubElement(node, "dynamics", damping=repr(float(joint.damping)), friction=repr(float(joint.friction)))
        if joint.mimic is not None and joint.mimic.joint in canonical:
            ET.SubElement(
                node,
                "mimic",
                joint=canonical[joint.mimic.joint],
                multiplier=repr(float(joint.mimic.multiplier)),
                offset=repr(float(joint.mimic.offset)),
            )
    return ET.tostring(root, encoding="unicode"), {value: key for key, value in canonical.items()}


_INERTIA_INDEX = {"ixx": (0, 0), "ixy": (0, 1), "ixz": (0, 2), "iyy": (1, 1), "iyz": (1, 2), "izz": (2, 2)}

__all__ = ["UNBOUNDED", "normalised_urdf"]
