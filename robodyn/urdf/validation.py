"""URDF validation: one strict reader in front of both Pinocchio and the reference.

:func:`parse_urdf` reads URDF text with a strict XML parser (no recovery, no DOCTYPE, no
entities, no network), checks the structure and the physics of the model, and returns a
small :class:`URDFSpec`. Every problem found is a :class:`Problem`; :func:`parse_urdf`
raises the first error as a :class:`~robodyn.exceptions.URDFError`, and :func:`lint_urdf`
returns them all, warnings included.

Conventions enforced here and relied on downstream:
    - joint axes are finite, non-zero and normalised to unit length;
    - ``<mimic>`` joints are honoured (``q_mimic = multiplier * q_source + offset``);
    - masses are finite and non-negative; a link with positive mass has a symmetric
      positive-definite inertia satisfying the triangle inequality.

This module does not import Pinocchio.
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from collections.abc import Sequence
import warnings
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from robodyn.exceptions import RobodynWarning, URDFError, printable, quoted
from robodyn.urdf.meshes import mesh_problems

#: Joint types robodyn knows. ``floating`` and ``planar`` are refused with a clear reason.
MOVING_JOINT_TYPES = ("revolute", "continuous", "prismatic")
KNOWN_JOINT_TYPES = (*MOVING_JOINT_TYPES, "fixed", "floating", "planar")
#: Deepest kinematic chain accepted (Pinocchio's parser crashes around 4000).
MAX_DEPTH = 1000
#: Largest magnitude accepted for a length, angle, mass, inertia or limit (SI units):
#: beyond it the dynamics overflow long before they mean anything.
MAX_MAGNITUDE = 1e12
#: Relative tolerance on the triangle inequality of principal moments of inertia.
TRIANGLE_TOLERANCE = 1e-6
#: Smallest length that matters for a body's inertia, in [m]: a principal moment is
#: compared with ``mass × BODY_SCALE²`` (see :func:`_check_inertias`).
BODY_SCALE = 1e-3
#: Deepest nesting of XML elements accepted (a URDF needs 5; xacro output about 10).
MAX_XML_DEPTH = 100


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


@dataclass
class URDFSpec:
    """A validated URDF: its links, joints (document order) and the parsed XML tree."""

    name: str
    root: str
    links: dict[str, Inertial | None]
    joints: dict[str, JointSpec]
    xml: ET.Element = field(repr=False)

    def child_joints(self, link: str) -> list[JointSpec]:
        """Joints whose parent is ``link``, in document order."""
        if not hasattr(self, "_children"):
            self._children = _children(self.joints)
        return list(self._children.get(link, []))


def _children(joints: dict[str, JointSpec]) -> dict[str, list[JointSpec]]:
    """Child joints of every link, in document order (one pass: linear time)."""
    children: dict[str, list[JointSpec]] = {}
    for joint in joints.values():
        children.setdefault(joint.parent, []).append(joint)
    return children


_FORBIDDEN_XML = re.compile(r"<!DOCTYPE|<!ENTITY", re.IGNORECASE)


def parse_xml(text: str, source: str) -> ET.Element:
    """Parse URDF text strictly and return its ``<robot>`` element.

    Whitespace (and a byte-order mark) before the XML declaration is accepted, as urdfdom
    does. Elements nested deeper than :data:`MAX_XML_DEPTH` are refused while parsing
    (the parser never recurses, nor does anything downstream get such a tree).

    Raises:
        URDFError: If the text is not well-formed XML, declares a DOCTYPE or entities,
            nests elements too deeply, or its root element is not ``<robot>``.
    """
    if _FORBIDDEN_XML.search(text):
        raise URDFError(source, "DOCTYPE and entity declarations are not allowed in a URDF")
    text = text.lstrip(" \t\r\n\ufeff")
    parser = ET.XMLPullParser(events=("start", "end"))
    depth, root = 0, None
    try:
        for start in range(0, max(len(text), 1), 1 << 16):
            parser.feed(text[start : start + (1 << 16)])
            for event, element in parser.read_events():
                depth += 1 if event == "start" else -1
                root = element if root is None else root
                if depth > MAX_XML_DEPTH:
                    raise URDFError(source, f"XML elements are nested deeper than {MAX_XML_DEPTH} levels (<{element.tag}>)")
        parser.close()
    except ET.ParseError as error:
        raise URDFError(source, f"not well-formed XML ({error})") from None
    if root.tag != "robot":
        raise URDFError(source, f"the root element must be <robot>, not <{root.tag}>")
    return root


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
        values = [parse_number(token) for token in _split(text)]
        problem = None
        if any(value is None for value in values):
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

    def number(
        self, where: str, node: ET.Element | None, attribute: str, default: float | None, *, bounded: bool = True
    ) -> float | None:
        if node is None or node.get(attribute) is None:
            return default
        text = node.get(attribute)
        value = parse_number(text)
        if value is None or math.isnan(value):
            self.error(where, f"{attribute}={quoted(text)} is not a number")
            return default
        if bounded and math.isfinite(value) and abs(value) > MAX_MAGNITUDE:
            self.error(where, f"{attribute}={quoted(text)} is beyond ±{MAX_MAGNITUDE:g}: not a physical robot")
            return default
        return value


#: The number grammar of a URDF attribute, the only one robodyn accepts: an optional sign,
#: ASCII decimal digits with an optional fraction and exponent, or ``inf`` / ``infinity``
#: (any case; refused later wherever a finite value is needed) and ``nan`` (always
#: refused), after stripping ASCII whitespace. No underscores, no other scripts' digits, no
#: hexadecimal: what Python's ``float`` would also accept but a C++ URDF parser would read
#: differently is refused, and Pinocchio only ever reads numbers robodyn wrote.
_NUMBER = re.compile(r"[+-]?(?:(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?|inf|infinity|nan)", re.IGNORECASE)
_ASCII_SPACE = " \t\n\r"


def parse_number(text: str) -> float | None:
    """The value of one number in URDF text, or ``None`` if it is not in the grammar.

    Args:
        text: The attribute text (surrounding ASCII whitespace allowed).

    Returns:
        The float (``inf`` and ``nan`` included, for the caller to refuse), or ``None``.
    """
    token = text.strip(_ASCII_SPACE)
    return float(token) if _NUMBER.fullmatch(token) else None


def _split(text: str) -> list[str]:
    """Tokens of a list of numbers separated by ASCII whitespace."""
    return [token for token in re.split("[ \t\n\r]+", text.strip(_ASCII_SPACE)) if token]


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


def _fmt(values: np.ndarray) -> str:
    return "(" + ", ".join(f"{value:.4g}" for value in values) + ")"


def _read_joint(reader: _Reader, node: ET.Element, index: int) -> JointSpec | None:
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
    if parent is None or parent.get("link") is None or child is None or child.get("link") is None:
        reader.error(where, "needs <parent link=...> and <child link=...>")
        return None
    origin = node.find("origin")
    xyz = reader.floats(where, origin, "xyz", "0 0 0")
    rpy = reader.floats(where, origin, "rpy", "0 0 0")
    axis = reader.floats(where, node.find("axis"), "xyz", "1 0 0")
    norm = float(np.linalg.norm(axis))
    if joint_type != "fixed" and norm < 1e-12:
        reader.error(where, "axis must not be zero")
        return None
    axis = axis / norm if norm >= 1e-12 else axis
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
        if lower > upper:
            reader.error(where, f"lower limit {lower} is above upper limit {upper}")
            return None
    for label, value in (("effort", effort), ("velocity", velocity)):
        if value is not None and value < 0:
            reader.error(where, f"{label} limit {value} must not be negative")
        elif value == 0 and joint_type != "fixed":
            reader.warn(where, f"{label} limit is zero: the joint cannot move under that limit")
    mimic = None
    mimic_node = node.find("mimic")
    if mimic_node is not None:
        source_joint = mimic_node.get("joint")
        if not source_joint:
            reader.error(where, "<mimic> needs a joint attribute")
            return None
        mimic = Mimic(
            source_joint,
            reader.number(where, mimic_node, "multiplier", 1.0),
            reader.number(where, mimic_node, "offset", 0.0),
        )
        if not (math.isfinite(mimic.multiplier) and math.isfinite(mimic.offset)):
            reader.error(where, "mimic multiplier and offset must be finite")
            return None
    return JointSpec(
        name, joint_type, parent.get("link"), child.get("link"), xyz, rpy, axis,
        lower, upper, effort, velocity, mimic,
    )  # fmt: skip


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
    children = _children(joints)
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


def _moving_links(root: str, children: dict[str, list[JointSpec]], floating_base: bool) -> set[str]:
    """Links that move: below a moving joint, or every link on a floating base (linear time)."""
    moving = set()
    frontier = [(root, floating_base)]
    while frontier:
        link, moves = frontier.pop()
        if moves:
            moving.add(link)
        frontier += [(j.child, moves or j.type != "fixed") for j in children.get(link, ())]
    return moving


def _check_inertias(
    reader: _Reader, links: dict[str, Inertial | None], moving: set[str], check_inertia: bool, strict: bool
) -> None:
    """Physical consistency of each link's inertia.

    On a link that moves, an inertia that is not positive semi-definite is an error (a
    warning with ``check_inertia=False``); one that is positive semi-definite but breaks
    the triangle inequality is a loud warning (peers load it), an error when ``strict``.
    The tolerance is relative to the body's scale: ``1e-9`` of the larger of its largest
    principal moment and ``mass × (1 mm)²``, so rounding noise of ±1e-35 kg m² on a
    point-like body is not a negative moment.
    """
    for name, inertial in links.items():
        if inertial is None:
            continue
        where = f'link "{name}"'
        if inertial.mass == 0:
            if np.abs(inertial.inertia).max() > 0:
                reader.warn(where, "has rotational inertia but no mass (no rigid body does); both dynamics keep the inertia")
            continue
        is_moving = name in moving
        moments = np.linalg.eigvalsh(inertial.inertia)
        tolerance = 1e-9 * max(abs(moments).max(), inertial.mass * BODY_SCALE**2)
        if moments[0] < -tolerance:
            report = reader.error if check_inertia and is_moving else reader.warn
            report(where, f"inertia must be positive semi-definite (principal moments {_fmt(moments)} kg m²)")
        elif moments[2] > (moments[0] + moments[1]) * (1 + TRIANGLE_TOLERANCE) + tolerance:
            rule = f"principal moments of inertia {_fmt(moments)} kg m² break the triangle inequality (no rigid body has them)"
            if strict and is_moving:
                reader.error(where, rule)
            else:
                reader.warn(where, rule, loud=is_moving and check_inertia)
        elif moments[2] < 1e-10 * inertial.mass:
            reader.warn(where, f"tiny inertia (largest principal moment {moments[2]:.3g} kg m²) for mass {inertial.mass:.3g} kg")
        elif is_moving and moments[0] <= tolerance:
            reader.warn(
                where, f"singular inertia (principal moments {_fmt(moments)} kg m²): the mass matrix may be singular"
            )


def _check_moving_masses(reader: _Reader, spec_links: dict, joints: dict[str, JointSpec], children: dict) -> None:
    """Warn about moving joints that carry a massless leaf body (linear time: each link is
    visited once, by the moving joint whose rigid body holds it)."""
    for joint in joints.values():
        if joint.type == "fixed":
            continue
        # The rigid body a moving joint carries: its child plus links welded to it.
        mass, carries_joint, frontier = 0.0, False, [joint.child]
        while frontier:
            link = frontier.pop()
            inertial = spec_links.get(link)
            mass += inertial.mass if inertial is not None else 0.0
            for child in children.get(link, ()):
                if child.type == "fixed":
                    frontier.append(child.child)
                else:
                    carries_joint = True
        if mass == 0 and not carries_joint:
            reader.warn(f'joint "{joint.name}"', "moves a massless leaf body: its mass matrix is singular")


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
            joint that does not exist) are errors.
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
        children = _children(joints)
        _check_inertias(reader, links, _moving_links(tree_root, children, floating_base), check_inertia, strict)
        _check_moving_masses(reader, links, joints, children)
        if not floating_base and all(joint.type == "fixed" for joint in joints.values()):
            reader.error(None, "the robot has no moving joint (floating_base=True gives its root six degrees of freedom)")
    if strict:
        reader.problems = [
            Problem(problem.element, problem.rule) if problem.loud else problem for problem in reader.problems
        ]
    errors = [problem for problem in reader.problems if problem.severity == "error"]
    spec = None if errors else URDFSpec(root.get("name", "robot"), tree_root, links, joints, root)
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
            rule += " (check_inertia=False or --no-check-inertia loads it anyway)"
        raise URDFError(source, rule, first.element)
    for problem in problems:
        if problem.loud:
            warnings.warn(printable(f"{source}: {problem} (strict=True refuses it)"), RobodynWarning, stacklevel=3)
    return spec
