"""URDF validation: one strict reader in front of both Pinocchio and the reference.

:func:`parse_urdf` reads URDF text with a strict XML parser (no recovery, no DOCTYPE, no
entities, no network), checks the structure and the physics of the model, and returns a
small :class:`URDFSpec`. Every problem found is a :class:`Problem`; :func:`parse_urdf`
raises the first error as a :class:`~robodyn.exceptions.URDFError`, and :func:`lint_urdf`
returns them all, warnings included.

Conventions enforced here and relied on downstream:
    - joint axes are finite, non-zero and normalised to unit length;
    - ``<mimic>`` joints are honoured (``q_mimic = multiplier * q_source + offset``);
    - numbers follow one grammar (:func:`robodyn.urdf.xmltext.parse_number`); Pinocchio
      later reads only numbers robodyn wrote (:mod:`robodyn.urdf.normalised`);
    - masses are finite and non-negative; a moving link with positive mass has a
      positive semi-definite inertia (tolerance relative to the body's scale); breaking
      the triangle inequality is a loud warning (:class:`~robodyn.exceptions.RobodynWarning`),
      an error with ``strict=True``;
    - a ``<mimic>`` of a joint that does not exist is dropped with a loud warning;
    - a joint's ``<dynamics damping friction>`` (viscous damping b, Coulomb friction f) are
      finite and non-negative (0 where not given); on a fixed joint they have no effect
      (a warning ``lint`` shows);
    - a revolute or prismatic joint with ``lower > upper`` (Bullet's encoding of an
      unlimited joint, e.g. pybullet_data's cube_no_rotation.urdf) has no position limit,
      with a loud warning;
    - revolute limits that look written in degrees (±90, ±180, ±270, ±360, or beyond four
      turns) are kept as written, with a loud warning naming the values in radians.

The pieces live in :mod:`robodyn.urdf.xmltext` (XML and numbers), :mod:`robodyn.urdf.spec`
(the result types) and :mod:`robodyn.urdf.inertias` (mass properties).

This module does not import Pinocchio.
"""

from __future__ import annotations

import math
import warnings
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import overload

import numpy as np

from robodyn.common.text import printable, quoted
from robodyn.exceptions import RobodynWarning, URDFError
from robodyn.urdf.inertias import BODY_SCALE, TRIANGLE_TOLERANCE, check_inertias, check_moving_masses, moving_links
from robodyn.urdf.meshes import mesh_problems
from robodyn.urdf.spec import Inertial, JointSpec, Mimic, Problem, URDFSpec, child_index
from robodyn.urdf.xmltext import MAX_XML_DEPTH, parse_number, parse_xml, split_numbers

#: Joint types robodyn knows. ``floating`` and ``planar`` are refused with a clear reason.
MOVING_JOINT_TYPES = ("revolute", "continuous", "prismatic")
KNOWN_JOINT_TYPES = (*MOVING_JOINT_TYPES, "fixed", "floating", "planar")
#: Deepest kinematic chain accepted (Pinocchio's parser crashes around 4000).
MAX_DEPTH = 1000
#: Largest magnitude accepted for a length, angle, mass, inertia or limit (SI units):
#: beyond it the dynamics overflow long before they mean anything.
MAX_MAGNITUDE = 1e12


_DEFAULTS: dict[str, tuple[float, ...]] = {}


class _Reader:
    """Collects problems while reading numbers and attributes out of elements."""

    def __init__(self) -> None:
        self.problems: list[Problem] = []

    def error(self, element: str | None, rule: str) -> None:
        self.problems.append(Problem(element, rule))

    def warn(self, element: str | None, rule: str, *, loud: bool = False) -> None:
        self.problems.append(Problem(element, rule, "warning", loud))

    def floats(self, where: str, node: ET.Element | None, attribute: str, default: str) -> np.ndarray:
        text = default if node is None else node.get(attribute, default)
        fallback = _DEFAULTS.setdefault(default, tuple(float(token) for token in default.split()))
        parsed = [parse_number(token) for token in split_numbers(text)]
        values = [value for value in parsed if value is not None]
        problem = None
        if len(values) != len(parsed):
            problem = "is not a list of numbers"
        elif len(values) != len(fallback):
            problem = f"must have {len(fallback)} numbers"
        elif not all(math.isfinite(value) for value in values):
            problem = "must be finite"
        elif max(map(abs, values), default=0.0) > MAX_MAGNITUDE:
            problem = f"is beyond ±{MAX_MAGNITUDE:g}: not a physical robot"
        if problem is not None:
            self.error(where, f"{attribute}={quoted(text)} {problem}")
            values = list(fallback)
        return np.array(values, dtype=float)

    @overload
    def number(self, where: str, node: ET.Element | None, attribute: str, default: float, *, bounded: bool = True) -> float: ...
    @overload
    def number(
        self, where: str, node: ET.Element | None, attribute: str, default: None, *, bounded: bool = True
    ) -> float | None: ...
    def number(
        self, where: str, node: ET.Element | None, attribute: str, default: float | None, *, bounded: bool = True
    ) -> float | None:
        text = None if node is None else node.get(attribute)
        if text is None:
            return default
        value = parse_number(text)
        if value is None or math.isnan(value):
            self.error(where, f"{attribute}={quoted(text)} is not a number")
            return default
        if bounded and math.isfinite(value) and abs(value) > MAX_MAGNITUDE:
            self.error(where, f"{attribute}={quoted(text)} is beyond ±{MAX_MAGNITUDE:g}: not a physical robot")
            return default
        return value


def _read_inertial(reader: _Reader, where: str, node: ET.Element) -> Inertial | None:
    origin = node.find("origin")
    mass_node = node.find("mass")
    if mass_node is None:
        reader.error(where, "<inertial> has no <mass>")
        return None
    mass = reader.number(where, mass_node, "value", None)
    if mass is None:
        if mass_node.get("value") is None:
            reader.error(where, "<mass> has no value")
        return None
    if not math.isfinite(mass):
        reader.error(where, f"mass {mass} must be finite")
        return None
    if mass < 0:
        reader.error(where, f"mass {mass} kg must not be negative")
        return None
    inertia_node = node.find("inertia")
    values = {}
    for key in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"):
        value = reader.number(where, inertia_node, key, 0.0)
        if not math.isfinite(value):
            reader.error(where, f"inertia {key}={value} must be finite")
            return None
        values[key] = value
    inertia = np.array(
        [
            [values["ixx"], values["ixy"], values["ixz"]],
            [values["ixy"], values["iyy"], values["iyz"]],
            [values["ixz"], values["iyz"], values["izz"]],
        ]
    )
    return Inertial(mass, reader.floats(where, origin, "xyz", "0 0 0"), reader.floats(where, origin, "rpy", "0 0 0"), inertia)


def _read_joint(reader: _Reader, node: ET.Element, index: int) -> JointSpec | None:
    """One ``<joint>``, or ``None`` (with the errors reported) if it cannot be read."""
    name = node.get("name")
    where = f'joint "{name}"' if name else f"joint #{index + 1}"
    if not name:
        reader.error(where, "has no name")
        return None
    joint_type = node.get("type")
    if joint_type not in KNOWN_JOINT_TYPES:
        reader.error(where, f"unknown joint type {joint_type!r} (known: {', '.join(KNOWN_JOINT_TYPES)})")
        return None
    if joint_type in ("floating", "planar"):
        reader.error(where, f"{joint_type} joints inside a URDF are not supported (use floating_base=True for a free root)")
        return None
    parent, child = node.find("parent"), node.find("child")
    parent_link = None if parent is None else parent.get("link")
    child_link = None if child is None else child.get("link")
    if parent_link is None or child_link is None:
        reader.error(where, "needs <parent link=...> and <child link=...>")
        return None
    placement = _read_placement(reader, where, node, joint_type)
    limits = None if placement is None else _read_limits(reader, where, node, joint_type)
    if placement is None or limits is None:
        return None
    readable, mimic = _read_mimic(reader, where, node)
    dynamics = _read_dynamics(reader, where, node, joint_type)
    if not readable or dynamics is None:
        return None
    return JointSpec(name, joint_type, parent_link, child_link, *placement, *limits, mimic, *dynamics)


def _read_placement(
    reader: _Reader, where: str, node: ET.Element, joint_type: str
) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """A joint's origin (``xyz`` in [m], ``rpy`` in [rad]) and unit axis, or ``None`` for a
    moving joint with a zero axis."""
    origin = node.find("origin")
    xyz = reader.floats(where, origin, "xyz", "0 0 0")
    rpy = reader.floats(where, origin, "rpy", "0 0 0")
    axis = reader.floats(where, node.find("axis"), "xyz", "1 0 0")
    norm = float(np.linalg.norm(axis))
    if joint_type != "fixed" and norm < 1e-12:
        reader.error(where, "axis must not be zero")
        return None
    return xyz, rpy, axis / norm if norm >= 1e-12 else axis


def _read_limits(reader: _Reader, where: str, node: ET.Element, joint_type: str) -> tuple[float, float, float, float] | None:
    """A joint's ``(lower, upper, effort, velocity)`` limits (±inf where not given, and for
    ``lower > upper``), or ``None`` for a revolute or prismatic joint without finite limits."""
    limit = node.find("limit")
    lower, upper = -math.inf, math.inf
    effort = reader.number(where, limit, "effort", math.inf, bounded=False)
    velocity = reader.number(where, limit, "velocity", math.inf, bounded=False)
    if joint_type in ("revolute", "prismatic"):
        if limit is None:
            reader.error(where, f"a {joint_type} joint needs a <limit> element")
            return None
        lower = reader.number(where, limit, "lower", 0.0)
        upper = reader.number(where, limit, "upper", 0.0)
        if not (math.isfinite(lower) and math.isfinite(upper)):
            reader.error(where, f"limits [{lower}, {upper}] must be finite")
            return None
        if lower > upper and limit.get("unlimited") == "true":  # written so by robodyn's MJCF reader
            lower, upper = -math.inf, math.inf
        elif lower > upper:  # Bullet's (and urdfdom's) encoding of a joint without a position limit
            reader.warn(
                where,
                f"lower limit {lower} is above upper limit {upper}: read as no position limit (Bullet's encoding)",
                loud=True,
            )
            lower, upper = -math.inf, math.inf
        elif joint_type == "revolute" and _in_degrees(lower, upper):
            reader.warn(
                where,
                f"limits [{lower:g}, {upper:g}] look like degrees (URDF limits are radians: {max(abs(lower), abs(upper)):g} rad"
                f" is {max(abs(lower), abs(upper)) / math.tau:.3g} turns); in radians they would be "
                f"[{math.radians(lower):.6g}, {math.radians(upper):.6g}]",
                loud=True,
            )
    for label, value in (("effort", effort), ("velocity", velocity)):
        if value is not None and value < 0:
            reader.error(where, f"{label} limit {value} must not be negative")
        elif value == 0 and joint_type != "fixed":
            reader.warn(where, f"{label} limit is zero: the joint cannot move under that limit")
    return lower, upper, effort, velocity


#: Turns beyond which a revolute limit is taken for degrees whatever its value (30° written
#: as 30 is 4.8 turns; placeholders such as ±10 rad, 1.6 turns, are radians).
DEGREE_TURNS = 4.0
#: Limits in degrees that no joint limit in radians is written as (each beyond a turn).
_RIGHT_ANGLES = (90.0, 180.0, 270.0, 360.0)


def _in_degrees(lower: float, upper: float) -> bool:
    """Whether a revolute joint's limits look written in degrees: beyond
    :data:`DEGREE_TURNS` turns, or a whole multiple of 90 such as ±180."""
    largest = max(abs(lower), abs(upper))
    return largest > DEGREE_TURNS * math.tau or any(abs(value) in _RIGHT_ANGLES for value in (lower, upper))


def _read_mimic(reader: _Reader, where: str, node: ET.Element) -> tuple[bool, Mimic | None]:
    """A joint's ``<mimic>``: whether it could be read, and the mimic (``None`` if none)."""
    mimic_node = node.find("mimic")
    if mimic_node is None:
        return True, None
    source_joint = mimic_node.get("joint")
    if not source_joint:
        reader.error(where, "<mimic> needs a joint attribute")
        return False, None
    mimic = Mimic(
        source_joint,
        reader.number(where, mimic_node, "multiplier", 1.0),
        reader.number(where, mimic_node, "offset", 0.0),
    )
    if not (math.isfinite(mimic.multiplier) and math.isfinite(mimic.offset)):
        reader.error(where, "mimic multiplier and offset must be finite")
        return False, None
    return True, mimic


def _read_dynamics(reader: _Reader, where: str, node: ET.Element, joint_type: str) -> tuple[float, float] | None:
    """A joint's ``<dynamics damping friction>``: viscous damping b in [N m s/rad] or [N s/m]
    and Coulomb friction f in [N m] or [N] (0 where not given), or ``None`` if they are not
    finite, non-negative numbers."""
    dynamics = node.find("dynamics")
    if dynamics is None:
        return 0.0, 0.0
    values = []
    for attribute in ("damping", "friction"):
        value = reader.number(where, dynamics, attribute, 0.0)
        if not math.isfinite(value) or value < 0:
            reader.error(where, f"<dynamics {attribute}={quoted(dynamics.get(attribute, ''))}> must be a finite number >= 0")
            return None
        values.append(value)
    if joint_type == "fixed" and any(values):
        reader.warn(where, "is fixed, so its <dynamics> has no effect")
    return values[0], values[1]


def _check_tree(reader: _Reader, links: dict, joints: dict[str, JointSpec]) -> str | None:
    """Check that joints connect the links into one tree; return the root link."""
    parent_of: dict[str, str] = {}
    for joint in joints.values():
        where = f'joint "{joint.name}"'
        for role, link in (("parent", joint.parent), ("child", joint.child)):
            if link not in links:
                reader.error(where, f"its {role} link {link!r} does not exist")
        if joint.child in parent_of:
            reader.error(
                f'link "{joint.child}"',
                f"has two parent joints ({parent_of[joint.child]!r} and {joint.name!r}); a URDF must be a tree",
            )
        else:
            parent_of[joint.child] = joint.name
    if any(problem.severity == "error" for problem in reader.problems):
        return None
    roots = [link for link in links if link not in parent_of]
    if len(roots) != 1:
        rule = (
            "no root link (the joints form a cycle)"
            if not roots
            else f"{len(roots)} root links {roots[:5]}; a URDF needs exactly one"
        )
        reader.error(None, rule)
        return None
    depth = {roots[0]: 0}
    stack = [roots[0]]
    children = child_index(joints)
    while stack:
        link = stack.pop()
        for joint in children.get(link, []):
            depth[joint.child] = depth[link] + 1
            if depth[joint.child] > MAX_DEPTH:
                reader.error(f'link "{joint.child}"', f"the kinematic chain is deeper than {MAX_DEPTH} links")
                return None
            stack.append(joint.child)
    unreached = [link for link in links if link not in depth]
    if unreached:
        reader.error(f'link "{unreached[0]}"', "is part of a cycle of joints, not of the tree under the root")
        return None
    return roots[0]


def _check_mimics(reader: _Reader, joints: dict[str, JointSpec]) -> None:
    """Check mimic relations; a mimic of a joint that does not exist is dropped (loud warning)."""
    for joint in list(joints.values()):
        if joint.mimic is None:
            continue
        where = f'joint "{joint.name}"'
        source = joints.get(joint.mimic.joint)
        if source is None:
            reader.warn(
                where,
                f"mimics joint {joint.mimic.joint!r}, which does not exist: it moves independently",
                loud=True,
            )
            joints[joint.name] = replace(joint, mimic=None)
        elif joint.type == "fixed":
            reader.warn(where, "is fixed, so its <mimic> has no effect")
        elif source.type == "fixed":
            reader.error(where, f"mimics the fixed joint {source.name!r}; a mimic relation needs two moving joints")
        elif source.mimic is not None:
            reader.error(where, f"mimics {source.name!r}, which is itself a mimic joint")
        elif source.type != joint.type:
            reader.error(where, f"a {joint.type} joint cannot mimic the {source.type} joint {source.name!r}")


def lint_urdf(
    text: str,
    source: str = "<string>",
    *,
    floating_base: bool = False,
    check_inertia: bool = True,
    strict: bool = False,
    base_dir: Path | None = None,
    package_dirs: Sequence[Path] = (),
) -> tuple[URDFSpec | None, list[Problem]]:
    """Check URDF text and return its spec (``None`` if it has errors) and every problem.

    Args:
        text: The URDF document.
        source: Where it came from, for messages.
        floating_base: Whether the root link moves freely (then every link moves).
        check_inertia: If false, physically impossible inertias of moving links are
            warnings instead of errors (some published URDFs have them).
        strict: Loud warnings (an inertia breaking the triangle inequality, a mimic of a
            joint that does not exist, ``lower > upper`` read as no limit) are errors.
        base_dir: Folder of the URDF file, for relative mesh paths.
        package_dirs: Folders under which ``package://`` mesh paths resolve.

    Returns:
        The validated spec, or ``None`` when any error was found, and the list of problems
        (errors and warnings) in document order.

    Raises:
        URDFError: Only if the text is not well-formed XML or not a ``<robot>`` document.
    """
    root = parse_xml(text, source)
    reader = _Reader()
    links: dict[str, Inertial | None] = {}
    for index, node in enumerate(root.findall("link")):
        name = node.get("name")
        if not name:
            reader.error(f"link #{index + 1}", "has no name")
            continue
        if name in links:
            reader.error(f'link "{name}"', "is defined twice")
            continue
        inertial = node.find("inertial")
        links[name] = None if inertial is None else _read_inertial(reader, f'link "{name}"', inertial)
    joints: dict[str, JointSpec] = {}
    for index, node in enumerate(root.findall("joint")):
        joint = _read_joint(reader, node, index)
        if joint is None:
            continue
        if joint.name in joints:
            reader.error(f'joint "{joint.name}"', "is defined twice")
            continue
        joints[joint.name] = joint
    if not links:
        reader.error(None, "the robot has no links")
    tree_root = _check_tree(reader, links, joints) if links else None
    _check_mimics(reader, joints)
    for element, rule, severity in mesh_problems(root, base_dir=base_dir, package_dirs=package_dirs):
        (reader.error if severity == "error" else reader.warn)(element, rule)
    if tree_root is not None:
        children = child_index(joints)
        check_inertias(reader, links, moving_links(tree_root, children, floating_base), check_inertia, strict)
        check_moving_masses(reader, links, joints, children)
        if not floating_base and all(joint.type == "fixed" for joint in joints.values()):
            reader.error(None, "the robot has no moving joint (floating_base=True gives its root six degrees of freedom)")
    if strict:
        reader.problems = [Problem(problem.element, problem.rule) if problem.loud else problem for problem in reader.problems]
    errors = [problem for problem in reader.problems if problem.severity == "error"]
    spec = None if errors or tree_root is None else URDFSpec(root.get("name", "robot"), tree_root, links, joints, root)
    return spec, reader.problems


def parse_urdf(
    text: str,
    source: str = "<string>",
    *,
    floating_base: bool = False,
    check_inertia: bool = True,
    strict: bool = False,
    base_dir: Path | None = None,
    package_dirs: Sequence[Path] = (),
) -> URDFSpec:
    """Validate URDF text and return its spec (arguments as for :func:`lint_urdf`).

    Loud warnings are shown as :class:`~robodyn.exceptions.RobodynWarning` (one each).

    Raises:
        URDFError: Naming the source, the element and the rule of the first error found.
    """
    spec, problems = lint_urdf(
        text,
        source,
        floating_base=floating_base,
        check_inertia=check_inertia,
        strict=strict,
        base_dir=base_dir,
        package_dirs=package_dirs,
    )
    if spec is None:
        first = next(problem for problem in problems if problem.severity == "error")
        rule = first.rule
        if "inertia" in rule and check_inertia:
            rule += " (check_inertia=False loads it anyway)"
        raise URDFError(source, rule, first.element)
    for problem in problems:
        if problem.loud:
            warnings.warn(printable(f"{source}: {problem} (strict=True refuses it)"), RobodynWarning, stacklevel=3)
    return spec


__all__ = [
    "BODY_SCALE",
    "KNOWN_JOINT_TYPES",
    "MAX_DEPTH",
    "MAX_MAGNITUDE",
    "MAX_XML_DEPTH",
    "MOVING_JOINT_TYPES",
    "TRIANGLE_TOLERANCE",
    "Inertial",
    "JointSpec",
    "Mimic",
    "Problem",
    "URDFSpec",
    "lint_urdf",
    "parse_number",
    "parse_urdf",
    "parse_xml",
]
