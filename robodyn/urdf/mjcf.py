"""Reading an MJCF (MuJoCo XML) robot: robodyn's own reader, without MuJoCo or Pinocchio.

An MJCF file is read into the URDF robodyn would have been given for the same robot, and
every later layer (validation, Pinocchio's model, the independent reference, ``lint``,
equations) reads that URDF (:attr:`~robodyn.urdf.sources.URDFSource.text`). A joint's
``damping``, ``frictionloss`` and ``armature`` are written as ``<dynamics damping friction
armature>`` (``armature`` is robodyn's extension of URDF:
:func:`robodyn.urdf.sources.with_file_dynamics` reads it).

The reading, as MuJoCo's compiler does it:

- ``<compiler angle>`` (MuJoCo's default: **degree**), ``eulerseq`` (lower case: axes that
  move with the frame, upper case: fixed axes), ``autolimits``;
- orientations ``quat`` (**w x y z**), ``axisangle``, ``euler``, ``xyaxes``, ``zaxis``;
- ``<default>`` classes (nested; ``class``, ``childclass``);
- bodies: a body's joints act in order at their ``pos`` (a body with several joints becomes
  a chain through massless links); the link's frame sits at its last joint's position,
  everything in the body is placed relative to it; a body without joints is welded;
- joints ``hinge`` (revolute / continuous), ``slide`` (prismatic), ``free`` (on the one
  top body only: a floating base); ``range`` with ``limited`` / ``autolimits``;
- ``<inertial>`` (``diaginertia`` or ``fullinertia``, with its own frame), or, where
  MuJoCo's ``inertiafromgeom`` would, the inertia of the body's solid geoms (sphere,
  capsule, cylinder, ellipsoid, box; ``density`` / ``mass``; :mod:`robodyn.urdf.geom_inertia`);
- ``<site>`` s become frames (massless links on fixed joints, named as the site);
- ``box``, ``sphere``, ``capsule``, ``cylinder``, ``ellipsoid`` and ``mesh`` geoms become
  visuals (drawings only).

Refused with one sentence: ``ball`` joints, a ``free`` joint below the top, a nonzero joint
``ref``, a body whose inertia would come from a mesh geom or a shell, ``<include>``,
``<frame>``, ``<replicate>``, ``<attach>``, ``boundmass`` / ``boundinertia``
(``settotalmass`` is read: masses and inertias scaled as MuJoCo does). Reported
in one :class:`~robodyn.exceptions.RobodynWarning` line per kind (``strict=True`` refuses):
tendons, equality constraints, actuators, contact pairs / excludes, joint stiffness,
``gravcomp``, a non-default ``<option gravity>``.
"""

from __future__ import annotations

import math
import warnings
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from robodyn.common.rotations import axis_rotation, matrix_rpy
from robodyn.common.text import printable
from robodyn.exceptions import RobodynWarning, URDFError
from robodyn.urdf.geom_inertia import SOLIDS, combine, solid_properties
from robodyn.urdf.xmltext import parse_number, parse_xml, split_numbers

if TYPE_CHECKING:
    from robodyn.urdf.packages import PackageLookup
    from robodyn.urdf.sources import URDFSource

#: Elements whose effect on the motion robodyn does not model: one warning line each.
UNSUPPORTED = {
    "tendon": "tendons",
    "equality": "equality constraints",
    "actuator": "actuators (their transmissions and gains)",
    "contact": "contact pairs and excludes",
}
#: Elements refused outright.
REFUSED = ("include", "frame", "replicate", "attach")
_ORIENTATIONS = ("quat", "axisangle", "euler", "xyaxes", "zaxis")


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
class _Robot:
    """The URDF being written, and what travels beside it."""

    label: str
    compiler: Compiler
    defaults: dict[str, dict[str, dict[str, str]]]
    urdf: ET.Element
    names: set[str] = field(default_factory=set)
    notes: dict[str, list[str]] = field(default_factory=dict)
    floating: bool = False

    def note(self, kind: str, name: str) -> None:
        self.notes.setdefault(kind, []).append(name)

    def unique(self, name: str, what: str) -> str:
        if name in self.names:
            raise URDFError(self.label, f"two links would be named {name!r} ({what}): rename one in the MJCF")
        self.names.add(name)
        return name


def mjcf_source(source: URDFSource, *, strict: bool, lookup: PackageLookup) -> URDFSource:
    """The source of an MJCF document, as the URDF robodyn reads it (see the module).

    Raises:
        URDFError: One sentence naming what cannot be read.

    Warns:
        RobodynWarning: One line per kind of element the dynamics does not take.
    """
    root = parse_xml(source.text, source.label, root="mujoco")
    base_dir = source.path.parent if source.path is not None else None
    robot = read_mjcf(root, source.label, base_dir)
    for kind, names in robot.notes.items():
        shown = ", ".join(printable(name) for name in names[:8]) + (", ..." if len(names) > 8 else "")
        message = f"{source.label}: MJCF {kind} are not part of robodyn's dynamics and are left out ({shown})"
        if strict:
            raise URDFError(source.label, f"MJCF {kind} are not part of robodyn's dynamics ({shown}); strict=True refuses")
        warnings.warn(message, RobodynWarning, stacklevel=4)
    text = ET.tostring(robot.urdf, encoding="unicode")
    return replace(
        source,
        text=text,
        name=robot.urdf.get("name") or source.name,
        floating_base=robot.floating,
        package_dirs=lookup,
        file_format="mjcf",
    )


def read_mjcf(root: ET.Element, label: str, base_dir: Path | None) -> _Robot:
    """Read a ``<mujoco>`` element into the URDF of the same robot.

    Raises:
        URDFError: For what cannot be read (see the module).
    """
    for tag in REFUSED:
        if root.find(f".//{tag}") is not None:
            raise URDFError(label, f"MJCF <{tag}> is not read by robodyn (expand it into one file first)")
    compiler = _compiler(root, label, base_dir)
    defaults: dict[str, dict[str, dict[str, str]]] = {}
    for default in root.findall("default"):
        _read_defaults(default, "main", {}, defaults)
    urdf = ET.Element("robot", name=root.get("model") or "mjcf")
    robot = _Robot(label, compiler, defaults, urdf)
    for tag, kind in UNSUPPORTED.items():
        for section in root.findall(tag):
            for index, element in enumerate(section):
                robot.note(kind, element.get("name") or f"<{element.tag}> #{index + 1}")
    _check_option(root, robot)
    world = root.find("worldbody")
    bodies = [] if world is None else world.findall("body")
    if not bodies:
        raise URDFError(label, "the MJCF <worldbody> has no <body>: there is no robot to read")
    free = [body for body in bodies if _free_joint(robot, body) is not None]
    if free and len(bodies) > 1:
        raise URDFError(label, "a free-floating MJCF body must be the only body in <worldbody> (robodyn reads one robot)")
    if free:
        robot.floating = True
        _read_body(robot, bodies[0], None, np.eye(4), "main")
    else:
        robot.unique("world", "the MJCF worldbody")
        ET.SubElement(urdf, "link", name="world")
        for body in bodies:
            _read_body(robot, body, "world", np.eye(4), "main")
    if compiler.total_mass > 0:
        _set_total_mass(urdf, compiler.total_mass)
    return robot


def _set_total_mass(urdf: ET.Element, total: float) -> None:
    """Scale every mass and inertia so that they add up to ``total`` (``<compiler settotalmass>``)."""
    inertials = urdf.findall("link/inertial")
    current = sum(float(mass.get("value", "0")) for mass in urdf.findall("link/inertial/mass"))
    if current <= 0:
        return
    for node in inertials:
        for element in (node.find("mass"), node.find("inertia")):
            assert element is not None  # written by this module
            for key, value in element.attrib.items():
                element.set(key, repr(float(value) * total / current))


def _compiler(root: ET.Element, label: str, base_dir: Path | None) -> Compiler:
    settings: dict[str, str] = {}
    for node in root.findall("compiler"):
        settings.update(node.attrib)
    for option in ("boundmass", "boundinertia"):
        if option in settings and _number(label, "compiler", settings[option]) > 0:
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
        _number(label, "compiler settotalmass", settings.get("settotalmass", "-1")),
    )


def _check_option(root: ET.Element, robot: _Robot) -> None:
    for option in root.findall("option"):
        gravity = option.get("gravity")
        if gravity is not None and not np.allclose(_floats(robot.label, "option", gravity, 3), [0, 0, -9.81]):
            robot.note("<option gravity> settings", f"gravity {gravity.strip()} (pass gravity= instead)")


def _read_defaults(node: ET.Element, name: str, inherited: dict[str, dict[str, str]], table: dict) -> None:
    """Every class of a ``<default>`` tree: attributes by element kind, inherited downwards."""
    own = {kind: dict(values) for kind, values in inherited.items()}
    for child in node:
        if child.tag != "default":
            own.setdefault(child.tag, {}).update(child.attrib)
    table[name] = own
    for child in node.findall("default"):
        _read_defaults(child, child.get("class") or name, own, table)


def _attributes(robot: _Robot, node: ET.Element, childclass: str) -> dict[str, str]:
    """An element's attributes with its class's defaults under them."""
    name = node.get("class") or childclass
    if name not in robot.defaults and name != "main":
        raise URDFError(robot.label, f"MJCF class {name!r} is not defined in <default>")
    merged = dict(robot.defaults.get(name, {}).get(node.tag, {}))
    merged.update(node.attrib)
    return merged


def _number(label: str, where: str, text: str) -> float:
    value = parse_number(text)
    if value is None or not math.isfinite(value):
        raise URDFError(label, f"{where}: {text!r} is not a finite number")
    return value


def _floats(label: str, where: str, text: str, count: int) -> np.ndarray:
    tokens = split_numbers(text)
    if len(tokens) != count:
        raise URDFError(label, f"{where}: {text!r} must be {count} numbers")
    return np.array([_number(label, where, token) for token in tokens])


def _angle(robot: _Robot, value: float) -> float:
    return math.radians(value) if robot.compiler.degree else value


def orientation(robot: _Robot, where: str, attributes: dict[str, str]) -> np.ndarray:
    """The rotation matrix an element's orientation attribute gives (identity if none)."""
    given = [key for key in _ORIENTATIONS if key in attributes]
    if len(given) > 1:
        raise URDFError(robot.label, f"{where}: more than one orientation ({', '.join(given)})")
    if not given:
        return np.eye(3)
    key, text = given[0], attributes[given[0]]
    if key == "quat":
        w, x, y, z = _floats(robot.label, where, text, 4)
        return quaternion_matrix(robot.label, where, np.array([w, x, y, z]))
    if key == "axisangle":
        values = _floats(robot.label, where, text, 4)
        return axis_rotation(_unit(robot.label, where, values[:3]), _angle(robot, values[3]))
    if key == "euler":
        return _euler(robot, _floats(robot.label, where, text, 3))
    if key == "xyaxes":
        values = _floats(robot.label, where, text, 6)
        x = _unit(robot.label, where, values[:3])
        y = _unit(robot.label, where, values[3:] - values[3:] @ x * x)
        return np.column_stack([x, y, np.cross(x, y)])
    return _zaxis(_unit(robot.label, where, _floats(robot.label, where, text, 3)))


def quaternion_matrix(label: str, where: str, wxyz: np.ndarray) -> np.ndarray:
    """The rotation of a quaternion in MuJoCo's order (w, x, y, z), normalised."""
    norm = float(np.linalg.norm(wxyz))
    if norm < 1e-12:
        raise URDFError(label, f"{where}: the quaternion must not be zero")
    w, x, y, z = wxyz / norm
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def _euler(robot: _Robot, angles: np.ndarray) -> np.ndarray:
    rotation = np.eye(3)
    for axis_name, angle in zip(robot.compiler.eulerseq, angles, strict=True):
        axis = np.eye(3)["xyz".index(axis_name.lower())]
        turn = axis_rotation(axis, _angle(robot, float(angle)))
        rotation = rotation @ turn if axis_name.islower() else turn @ rotation
    return rotation


def _zaxis(z: np.ndarray) -> np.ndarray:
    """The smallest rotation taking (0, 0, 1) to ``z``, as MuJoCo's ``zaxis``."""
    cross = np.cross([0.0, 0.0, 1.0], z)
    sine, cosine = float(np.linalg.norm(cross)), float(z[2])
    if sine < 1e-14:
        return np.eye(3) if cosine > 0 else axis_rotation(np.array([1.0, 0.0, 0.0]), math.pi)
    return axis_rotation(cross / sine, math.atan2(sine, cosine))


def _unit(label: str, where: str, vector: np.ndarray) -> np.ndarray:
    norm = float(np.linalg.norm(vector))
    if norm < 1e-12:
        raise URDFError(label, f"{where}: a direction must not be zero")
    return vector / norm


def _pose(robot: _Robot, where: str, attributes: dict[str, str]) -> np.ndarray:
    """The 4×4 pose of an element's ``pos`` and orientation in its body's frame."""
    pose = np.eye(4)
    pose[:3, :3] = orientation(robot, where, attributes)
    pose[:3, 3] = _floats(robot.label, where, attributes.get("pos", "0 0 0"), 3)
    return pose


def _origin(parent: ET.Element, pose: np.ndarray) -> None:
    ET.SubElement(parent, "origin", xyz=_text(pose[:3, 3]), rpy=_text(matrix_rpy(pose[:3, :3])))


def _text(values: np.ndarray) -> str:
    return " ".join(repr(float(value)) for value in values)


def _free_joint(robot: _Robot, body: ET.Element) -> ET.Element | None:
    for joint in body.findall("freejoint"):
        return joint
    for joint in body.findall("joint"):
        if _attributes(robot, joint, body.get("childclass") or "main").get("type") == "free":
            return joint
    return None


def _read_body(robot: _Robot, body: ET.Element, parent: str | None, placement: np.ndarray, childclass: str) -> None:
    """One body and everything below it.

    Args:
        robot: The URDF being written.
        body: The ``<body>``.
        parent: The parent link (``None`` for a floating root).
        placement: The body frame in the parent link's frame, 4×4 (before this body's pos).
        childclass: The class in force.
    """
    childclass = body.get("childclass") or childclass
    attributes = _attributes(robot, body, childclass)
    name = robot.unique(body.get("name") or f"body{len(robot.names)}", "an MJCF body")
    where = f'body "{name}"'
    if body.get("mocap") == "true":
        raise URDFError(robot.label, f"{where}: mocap bodies are not read by robodyn")
    if float(attributes.get("gravcomp", "0") or 0) != 0:
        robot.note("body gravcomp settings", name)
    frame = placement @ _pose(robot, where, attributes) if parent is not None else np.eye(4)
    link, offset = _read_joints(robot, body, name, parent, frame, childclass)
    _write_link(robot, body, name, link, offset, childclass)
    for child in body.findall("body"):
        _read_body(robot, child, name, _translation(-offset), childclass)


def _translation(vector: np.ndarray) -> np.ndarray:
    pose = np.eye(4)
    pose[:3, 3] = vector
    return pose


def _read_joints(
    robot: _Robot, body: ET.Element, name: str, parent: str | None, frame: np.ndarray, childclass: str
) -> tuple[ET.Element, np.ndarray]:
    """The body's joints as a URDF chain ending at the body's link; returns the link and
    the link frame's position in the body frame (its last joint's ``pos``)."""
    joints = [node for node in body if node.tag in ("joint", "freejoint")]
    moving = [node for node in joints if not (parent is None and node is _free_joint(robot, body))]
    if parent is None and moving:
        raise URDFError(robot.label, f'body "{name}": a free body with more joints is not read by robodyn')
    if parent is not None and any(node.tag == "freejoint" for node in joints):
        raise URDFError(robot.label, f'body "{name}": a free joint is only read on the top body (a floating base)')
    previous, previous_pos = parent, np.zeros(3)
    for index, node in enumerate(moving):
        attributes = _attributes(robot, node, childclass)
        joint_name = node.get("name") or f"{name}_joint{index}"
        position = _floats(robot.label, f'joint "{joint_name}"', attributes.get("pos", "0 0 0"), 3)
        link_name = name if index == len(moving) - 1 else robot.unique(f"{name}__{joint_name}", "a link between joints")
        origin = frame @ _translation(position) if index == 0 else _translation(position - previous_pos)
        assert previous is not None
        _write_joint(robot, joint_name, attributes, previous, link_name, origin)
        previous, previous_pos = link_name, position
        if link_name != name:
            ET.SubElement(robot.urdf, "link", name=link_name)
    link = ET.SubElement(robot.urdf, "link", name=name)
    if not moving and parent is not None:
        fixed = ET.SubElement(robot.urdf, "joint", name=robot.unique(f"{name}_weld", "a welded body's joint"), type="fixed")
        _origin(fixed, frame)
        ET.SubElement(fixed, "parent", link=parent)
        ET.SubElement(fixed, "child", link=name)
    return link, previous_pos


def _write_joint(robot: _Robot, name: str, attributes: dict[str, str], parent: str, child: str, origin: np.ndarray) -> None:
    where = f'joint "{name}"'
    kind = attributes.get("type", "hinge")
    if kind not in ("hinge", "slide"):
        reason = "ball joints are not read by robodyn" if kind == "ball" else f"a {kind} joint is not read here"
        raise URDFError(robot.label, f"{where}: {reason} (hinge, slide and a free top body are)")
    if _number(robot.label, where, attributes.get("ref", "0")) != 0:
        raise URDFError(robot.label, f"{where}: a nonzero ref is not read by robodyn (move the body instead)")
    if _number(robot.label, where, attributes.get("stiffness", "0")) != 0:
        robot.note("joint stiffnesses (springs)", name)
    axis = _unit(robot.label, where, _floats(robot.label, where, attributes.get("axis", "0 0 1"), 3))
    lower, upper = _range(robot, where, attributes, kind)
    urdf_type = "prismatic" if kind == "slide" else ("revolute" if math.isfinite(lower) else "continuous")
    joint = ET.SubElement(robot.urdf, "joint", name=name, type=urdf_type)
    _origin(joint, origin)
    ET.SubElement(joint, "parent", link=parent)
    ET.SubElement(joint, "child", link=child)
    ET.SubElement(joint, "axis", xyz=_text(axis))
    if urdf_type != "continuous":
        bounded = math.isfinite(lower)
        if bounded:
            ET.SubElement(joint, "limit", lower=repr(lower), upper=repr(upper))
        else:  # Bullet's encoding of no position limit, marked as robodyn's own (no warning)
            ET.SubElement(joint, "limit", lower="1.0", upper="-1.0", unlimited="true")
    damping, friction, armature = (
        _number(robot.label, where, attributes.get(key, "0")) for key in ("damping", "frictionloss", "armature")
    )
    if damping or friction or armature:
        ET.SubElement(joint, "dynamics", damping=repr(damping), friction=repr(friction), armature=repr(armature))


def _range(robot: _Robot, where: str, attributes: dict[str, str], kind: str) -> tuple[float, float]:
    limited = attributes.get("limited", "auto")
    if limited == "auto":
        limited = "true" if robot.compiler.autolimits and "range" in attributes else "false"
    if limited != "true":
        return -math.inf, math.inf
    lower, upper = _floats(robot.label, where, attributes.get("range", "0 0"), 2)
    if kind == "hinge":
        lower, upper = _angle(robot, lower), _angle(robot, upper)
    if lower >= upper:
        raise URDFError(robot.label, f"{where}: range [{lower}, {upper}] must have lower < upper")
    return float(lower), float(upper)


def _write_link(robot: _Robot, body: ET.Element, name: str, link: ET.Element, offset: np.ndarray, childclass: str) -> None:
    """The body's inertial, visuals and sites, placed in the link frame (``offset`` from the body frame)."""
    shift = _translation(-offset)
    inertial = body.find("inertial")
    geoms = body.findall("geom")
    needs_geoms = robot.compiler.inertiafromgeom == "true" or (inertial is None and robot.compiler.inertiafromgeom == "auto")
    if geoms and needs_geoms:
        _write_geom_inertial(robot, geoms, name, link, shift, childclass)
    elif inertial is not None:
        _write_inertial(robot, inertial, name, link, shift)
    for index, geom in enumerate(geoms):
        _write_visual(robot, geom, f'geom #{index + 1} of body "{name}"', link, shift, childclass)
    for index, site in enumerate(body.findall("site")):
        attributes = _attributes(robot, site, childclass)
        site_name = robot.unique(site.get("name") or f"{name}_site{index}", "an MJCF site")
        joint = ET.SubElement(robot.urdf, "joint", name=robot.unique(f"{site_name}_site", "a site's joint"), type="fixed")
        _origin(joint, shift @ _pose(robot, f'site "{site_name}"', attributes))
        ET.SubElement(joint, "parent", link=name)
        ET.SubElement(joint, "child", link=site_name)
        ET.SubElement(robot.urdf, "link", name=site_name)


def _write_inertial(robot: _Robot, node: ET.Element, name: str, link: ET.Element, shift: np.ndarray) -> None:
    where = f'the <inertial> of body "{name}"'
    if "mass" not in node.attrib:
        raise URDFError(robot.label, f"{where} needs a mass")
    given = [key for key in _ORIENTATIONS if key in node.attrib]
    if "fullinertia" in node.attrib and given:
        raise URDFError(robot.label, f"{where}: fullinertia cannot have an orientation ({given[0]}), as in MuJoCo")
    pose = shift @ _pose(robot, where, dict(node.attrib))
    if "fullinertia" in node.attrib:
        ixx, iyy, izz, ixy, ixz, iyz = _floats(robot.label, where, node.attrib["fullinertia"], 6)
    elif "diaginertia" in node.attrib:
        (ixx, iyy, izz), ixy, ixz, iyz = _floats(robot.label, where, node.attrib["diaginertia"], 3), 0.0, 0.0, 0.0
    else:
        raise URDFError(robot.label, f"{where} needs diaginertia or fullinertia")
    element = ET.SubElement(link, "inertial")
    _origin(element, pose)
    ET.SubElement(element, "mass", value=repr(_number(robot.label, where, node.attrib["mass"])))
    values = {"ixx": ixx, "iyy": iyy, "izz": izz, "ixy": ixy, "ixz": ixz, "iyz": iyz}
    ET.SubElement(element, "inertia", {key: repr(float(value)) for key, value in values.items()})


def _write_geom_inertial(
    robot: _Robot, geoms: list[ET.Element], name: str, link: ET.Element, shift: np.ndarray, childclass: str
) -> None:
    """The body's inertia from its geoms, as MuJoCo's compiler computes it (uniform solids)."""
    parts = []
    for index, geom in enumerate(geoms):
        where = f'geom #{index + 1} of body "{name}"'
        attributes = _attributes(robot, geom, childclass)
        kind = attributes.get("type", "sphere")
        low, high = (int(value) for value in _floats(robot.label, where, robot.compiler.inertiagroups, 2))
        if not low <= int(_number(robot.label, where, attributes.get("group", "0"))) <= high or kind in ("plane", "hfield"):
            continue
        if kind not in SOLIDS or attributes.get("shellinertia", "false") == "true":
            raise URDFError(
                robot.label,
                f'body "{name}" has no <inertial> and a {kind} geom robodyn does not compute inertia from '
                "(solid sphere, capsule, cylinder, ellipsoid, box): add <inertial>",
            )
        size, pose = _geom_size_and_pose(robot, where, attributes, kind)
        given = attributes.get("mass")
        mass, principal = solid_properties(
            kind,
            size,
            density=_number(robot.label, where, attributes.get("density", "1000")),
            mass=None if given is None else _number(robot.label, where, given),
        )
        placed = shift @ pose
        parts.append((mass, placed[:3, 3], placed[:3, :3], principal))
    mass, centre, inertia = combine(parts)
    if mass <= 0:
        return
    element = ET.SubElement(link, "inertial")
    ET.SubElement(element, "origin", xyz=_text(centre), rpy="0 0 0")
    ET.SubElement(element, "mass", value=repr(mass))
    values = {"ixx": (0, 0), "iyy": (1, 1), "izz": (2, 2), "ixy": (0, 1), "ixz": (0, 2), "iyz": (1, 2)}
    ET.SubElement(element, "inertia", {key: repr(float(inertia[i, j])) for key, (i, j) in values.items()})


def _geom_size_and_pose(robot: _Robot, where: str, attributes: dict[str, str], kind: str) -> tuple[list[float], np.ndarray]:
    """A geom's ``size`` and pose in its body's frame (``fromto`` for capsules and cylinders)."""
    size = [_number(robot.label, where, token) for token in split_numbers(attributes.get("size", ""))]
    needed = {"sphere": 1, "capsule": 2, "cylinder": 2, "ellipsoid": 3, "box": 3}.get(kind, 0)
    if "fromto" not in attributes:
        if len(size) < needed:
            raise URDFError(robot.label, f"{where}: a {kind} needs {needed} size numbers")
        return size, _pose(robot, where, attributes)
    if kind not in ("capsule", "cylinder"):
        raise URDFError(robot.label, f"{where}: fromto on a {kind} is not read by robodyn")
    ends = _floats(robot.label, where, attributes["fromto"], 6)
    pose = np.eye(4)
    pose[:3, 3] = (ends[:3] + ends[3:]) / 2
    length = float(np.linalg.norm(ends[3:] - ends[:3]))
    if length > 1e-12:
        pose[:3, :3] = _zaxis((ends[3:] - ends[:3]) / length)
    if not size:
        raise URDFError(robot.label, f"{where}: a {kind} needs a radius")
    return [size[0], length / 2], pose


def _write_visual(robot: _Robot, geom: ET.Element, where: str, link: ET.Element, shift: np.ndarray, childclass: str) -> None:
    """A geom as a URDF visual (drawings only); planes, height fields and unknown types are skipped."""
    attributes = _attributes(robot, geom, childclass)
    kind = attributes.get("type", "sphere")
    size = [_number(robot.label, where, token) for token in split_numbers(attributes.get("size", ""))]
    pose = _pose(robot, where, {key: value for key, value in attributes.items() if key != "fromto"})
    if "fromto" in attributes:
        ends = _floats(robot.label, where, attributes["fromto"], 6)
        pose = np.eye(4)
        pose[:3, 3] = (ends[:3] + ends[3:]) / 2
        length = float(np.linalg.norm(ends[3:] - ends[:3]))
        if length > 1e-12:
            pose[:3, :3] = _zaxis((ends[3:] - ends[:3]) / length)
        size = [*size[:1], length / 2]
    shape = _shape(robot, kind, size, attributes)
    if shape is None:
        return
    visual = ET.SubElement(link, "visual")
    _origin(visual, shift @ pose)
    geometry = ET.SubElement(visual, "geometry")
    ET.SubElement(geometry, shape[0], shape[1])


def _shape(robot: _Robot, kind: str, size: list[float], attributes: dict[str, str]) -> tuple[str, dict[str, str]] | None:
    if kind == "box" and len(size) >= 3:
        return "box", {"size": _text(2 * np.array(size[:3]))}
    if kind in ("sphere", "ellipsoid") and size:
        return "sphere", {"radius": repr(max(size))}
    if kind in ("capsule", "cylinder") and len(size) >= 2:
        return "cylinder", {"radius": repr(size[0]), "length": repr(2 * size[1])}
    if kind == "mesh" and robot.compiler.meshdir is not None and attributes.get("mesh"):
        return None  # mesh assets are drawn as nothing yet (their files are in <asset>)
    return None
