"""What an MJCF body holds, written into its URDF link: the inertial (``<inertial>``, or the
body's solid geoms where MuJoCo's ``inertiafromgeom`` would take them), geoms as visuals
and sites as frames; ``<compiler settotalmass>``.

Geoms that collide with the world's plane by MuJoCo's rule (``contype & conaffinity`` of
the pair, either way; both 1 by default, ``<default>`` classes apply) are also written as
``<collision>`` s: spheres, boxes and cylinders as their URDF shapes, a capsule as its
cylinder in a collision named ``mjcf:capsule``; the others (ellipsoids, meshes, height
fields) as a ``<mjcf_collision type="KIND"/>`` element of the link, which URDF readers
ignore (the ground code, :mod:`robodyn.sim.ground`, reports what it does not model). ``<worldbody>``'s first plane geom is the robot's ground (:func:`plane_ground`).

This module does not import Pinocchio or MuJoCo.
"""

from __future__ import annotations

import math
import warnings
import xml.etree.ElementTree as ET

import numpy as np

from robodyn.common.text import printable
from robodyn.exceptions import RobodynWarning, URDFError
from robodyn.urdf.geom_inertia import SOLIDS, combine, solid_properties
from robodyn.urdf.mjcf_state import MjcfRobot, attributes
from robodyn.urdf.mjcf_values import (
    BOOLEAN,
    ORIENTATIONS,
    floats,
    fromto_pose,
    keyword,
    number,
    pose,
    text,
    translation,
    write_origin,
)
from robodyn.urdf.xmltext import split_numbers

#: MuJoCo's geom types.
GEOM_TYPES = ("plane", "hfield", "sphere", "capsule", "ellipsoid", "cylinder", "box", "mesh", "sdf")
#: How many ``size`` numbers each solid needs.
SIZES = {"sphere": 1, "capsule": 2, "cylinder": 2, "ellipsoid": 3, "box": 3}


def write_link(robot: MjcfRobot, body: ET.Element, name: str, link: ET.Element, offset: np.ndarray, childclass: str) -> float:
    """The body's inertial, visuals and sites, placed in the link frame (``offset`` from
    the body frame); returns the body's mass in [kg].

    Args:
        robot: The MJCF robot being read (its settings, defaults, notes).
        body: The ``<body>`` element.
        name: The body's name, for messages.
        link: The URDF ``<link>`` element written to.
        offset: The link frame's origin in the body frame, shape (3,), in [m].
        childclass: The default class the body's elements inherit.
    """
    shift = translation(-offset)
    inertial = body.find("inertial")
    geoms = [
        (geom, _geom_values(robot, geom, f'geom #{index + 1} of body "{name}"', childclass))
        for index, geom in enumerate(body.findall("geom"))
    ]
    needs_geoms = robot.compiler.inertiafromgeom == "true" or (inertial is None and robot.compiler.inertiafromgeom == "auto")
    mass = 0.0
    if geoms and needs_geoms:
        mass = _write_geom_inertial(robot, geoms, name, link, shift)
    elif inertial is not None:
        mass = _write_inertial(robot, inertial, name, link, shift)
    for index, (_, values) in enumerate(geoms):
        _write_visual(robot, values, f'geom #{index + 1} of body "{name}"', link, shift)
    for index, (_, values) in enumerate(geoms):
        if collides(robot, values, f'geom #{index + 1} of body "{name}"'):
            _write_collision(robot, values, f'geom #{index + 1} of body "{name}"', link, shift)
    write_sites(robot, body, name, shift, childclass)
    return mass


def write_sites(robot: MjcfRobot, body: ET.Element, name: str, shift: np.ndarray, childclass: str) -> None:
    """The body's sites as frames: massless links on fixed joints, named as the site, or
    ``site:NAME`` where a body has the name (MuJoCo's bodies and sites are separate
    namespaces; robodyn's links are one); an unnamed one ``siteN``, N its MuJoCo id.

    Args:
        robot: The reading's state.
        body: The ``<body>`` (or ``<worldbody>``) holding the sites.
        name: The link the sites hang from.
        shift: The body's frame in its link's, 4×4.
        childclass: The default class in force.
    """
    for site in body.findall("site"):
        values = attributes(robot, site, childclass)
        site_id = robot.next_id("site")  # an unnamed site is named after MuJoCo's id
        given = site.get("name") or f"site{site_id}"
        site_name = robot.unique(f"site:{given}" if given in robot.bodies else given, "an MJCF site")
        joint = ET.SubElement(robot.urdf, "joint", name=robot.unique(f"{site_name}_site", "a site's joint"), type="fixed")
        write_origin(joint, shift @ _site_pose(robot, f'site "{given}"', values))
        ET.SubElement(joint, "parent", link=name)
        ET.SubElement(joint, "child", link=site_name)
        ET.SubElement(robot.urdf, "link", name=site_name)


def _site_pose(robot: MjcfRobot, where: str, values: dict[str, str]) -> np.ndarray:
    """A site's pose in its body's frame: its ``fromto`` (centre, z along the segment: it
    overrides ``pos`` and the orientation, as in MuJoCo) where given, else ``pos`` and orientation.

    Raises:
        URDFError: ``fromto`` on a site type MuJoCo refuses it for (a sphere).
    """
    if "fromto" not in values:
        return pose(robot, where, values)
    kind = keyword(robot.label, where, "type", values.get("type", "sphere"), GEOM_TYPES)
    if kind not in ("capsule", "cylinder", "box", "ellipsoid"):
        raise URDFError(robot.label, f"{where}: fromto requires a capsule, cylinder, box or ellipsoid site, not a {kind}")
    return fromto_pose(robot, where, values["fromto"])[0]


def _geom_values(robot: MjcfRobot, geom: ET.Element, where: str, childclass: str) -> dict[str, str]:
    """A geom's attributes, checked as MuJoCo checks them: its type, positive sizes, and
    (in the inertia groups) a mass and density that are not negative.

    Raises:
        URDFError: Naming the geom and the value MuJoCo refuses.
    """
    values = attributes(robot, geom, childclass)
    kind = keyword(robot.label, where, "type", values.get("type", "sphere"), GEOM_TYPES)
    keyword(robot.label, where, "shellinertia", values.get("shellinertia", "false"), BOOLEAN)
    size = [number(robot.label, f"{where}: size", token) for token in split_numbers(values.get("size", ""))]
    if "fromto" in values and kind not in ("capsule", "cylinder"):
        raise URDFError(robot.label, f"{where}: fromto on a {kind} is not read by robodyn")
    needed = 1 if "fromto" in values else SIZES.get(kind, 0)
    if len(size) < needed:
        raise URDFError(robot.label, f"{where}: a {kind} needs {needed} size numbers")
    if any(value <= 0 for value in size[:needed]):
        raise URDFError(robot.label, f"{where}: size {values['size']!r} must be positive, as MuJoCo requires")
    low, high = robot.compiler.inertiagroups
    if low <= int(number(robot.label, f"{where}: group", values.get("group", "0"))) <= high:
        for key in ("mass", "density"):
            if key in values and number(robot.label, f"{where}: {key}", values[key]) < 0:
                raise URDFError(robot.label, f"{where}: {key}={values[key]!r} is negative (MuJoCo refuses it)")
    return values


def _write_inertial(robot: MjcfRobot, node: ET.Element, name: str, link: ET.Element, shift: np.ndarray) -> float:
    where = f'the <inertial> of body "{name}"'
    if "mass" not in node.attrib:
        raise URDFError(robot.label, f"{where} needs a mass")
    given = [key for key in ORIENTATIONS if key in node.attrib]
    if "fullinertia" in node.attrib and given:
        raise URDFError(robot.label, f"{where}: fullinertia cannot have an orientation ({given[0]}), as in MuJoCo")
    placed = shift @ pose(robot, where, dict(node.attrib))
    if "fullinertia" in node.attrib:
        ixx, iyy, izz, ixy, ixz, iyz = floats(robot.label, where, node.attrib["fullinertia"], 6)
    elif "diaginertia" in node.attrib:
        (ixx, iyy, izz), ixy, ixz, iyz = floats(robot.label, where, node.attrib["diaginertia"], 3), 0.0, 0.0, 0.0
    else:
        raise URDFError(robot.label, f"{where} needs diaginertia or fullinertia")
    mass = number(robot.label, f"{where}: mass", node.attrib["mass"])
    if mass < 0 or min(ixx, iyy, izz) < 0:
        raise URDFError(robot.label, f"{where}: a mass or principal inertia is negative (MuJoCo refuses it)")
    element = ET.SubElement(link, "inertial")
    write_origin(element, placed)
    ET.SubElement(element, "mass", value=repr(mass))
    values = {"ixx": ixx, "iyy": iyy, "izz": izz, "ixy": ixy, "ixz": ixz, "iyz": iyz}
    ET.SubElement(element, "inertia", {key: repr(float(value)) for key, value in values.items()})
    return mass


def _write_geom_inertial(
    robot: MjcfRobot, geoms: list[tuple[ET.Element, dict[str, str]]], name: str, link: ET.Element, shift: np.ndarray
) -> float:
    """The body's inertia from its geoms, as MuJoCo's compiler computes it (uniform
    solids); returns its mass in [kg]."""
    parts = []
    low, high = robot.compiler.inertiagroups
    for index, (_, values) in enumerate(geoms):
        where = f'geom #{index + 1} of body "{name}"'
        kind = values.get("type", "sphere")
        if not low <= int(number(robot.label, where, values.get("group", "0"))) <= high or kind in ("plane", "hfield"):
            continue
        if kind not in SOLIDS or values.get("shellinertia", "false") == "true":
            raise URDFError(
                robot.label,
                f'body "{name}" has no <inertial> and a {kind} geom robodyn does not compute inertia from '
                "(solid sphere, capsule, cylinder, ellipsoid, box): add <inertial>",
            )
        size, placed = _geom_size_and_pose(robot, where, values, kind)
        given = values.get("mass")
        density = number(robot.label, where, values.get("density", "1000"))
        try:
            mass, principal = solid_properties(
                kind, size, density=density, mass=None if given is None else number(robot.label, where, given)
            )
        except OverflowError:
            mass, principal = math.inf, np.full(3, math.inf)
        if not (math.isfinite(mass) and np.isfinite(principal).all()):
            raise URDFError(
                robot.label,
                f"{where}: its mass or inertia overflows (size {values.get('size', '')!r}); robodyn reads finite ones",
            )
        placed = shift @ placed
        parts.append((mass, placed[:3, 3], placed[:3, :3], principal))
    mass, centre, inertia = combine(parts)
    if mass <= 0:
        return 0.0
    if not (math.isfinite(mass) and np.isfinite(centre).all() and np.isfinite(inertia).all()):
        raise URDFError(robot.label, f'body "{name}": the mass properties of its geoms overflow; robodyn reads finite ones')
    element = ET.SubElement(link, "inertial")
    ET.SubElement(element, "origin", xyz=text(centre), rpy="0 0 0")
    ET.SubElement(element, "mass", value=repr(mass))
    entries = {"ixx": (0, 0), "iyy": (1, 1), "izz": (2, 2), "ixy": (0, 1), "ixz": (0, 2), "iyz": (1, 2)}
    ET.SubElement(element, "inertia", {key: repr(float(inertia[i, j])) for key, (i, j) in entries.items()})
    return mass


def _geom_size_and_pose(robot: MjcfRobot, where: str, values: dict[str, str], kind: str) -> tuple[list[float], np.ndarray]:
    """A geom's ``size`` and pose in its body's frame (``fromto`` for capsules and cylinders)."""
    size = [number(robot.label, where, token) for token in split_numbers(values.get("size", ""))]
    needed = SIZES.get(kind, 0)
    if "fromto" not in values:
        if len(size) < needed:
            raise URDFError(robot.label, f"{where}: a {kind} needs {needed} size numbers")
        return size, pose(robot, where, values)
    if kind not in ("capsule", "cylinder"):
        raise URDFError(robot.label, f"{where}: fromto on a {kind} is not read by robodyn")
    placed, half = fromto_pose(robot, where, values["fromto"])
    if not size:
        raise URDFError(robot.label, f"{where}: a {kind} needs a radius")
    return [size[0], half], placed


def _write_visual(robot: MjcfRobot, values: dict[str, str], where: str, link: ET.Element, shift: np.ndarray) -> None:
    """A geom as a URDF visual (drawings only); planes, height fields and meshes are skipped."""
    kind = values.get("type", "sphere")
    size = [number(robot.label, where, token) for token in split_numbers(values.get("size", ""))]
    placed = pose(robot, where, {key: value for key, value in values.items() if key != "fromto"})
    if "fromto" in values:
        placed, half = fromto_pose(robot, where, values["fromto"])
        size = [*size[:1], half]
    shape = _shape(kind, size)
    if shape is None:
        return
    visual = ET.SubElement(link, "visual")
    write_origin(visual, shift @ placed)
    geometry = ET.SubElement(visual, "geometry")
    ET.SubElement(geometry, shape[0], shape[1])


def _write_collision(robot: MjcfRobot, values: dict[str, str], where: str, link: ET.Element, shift: np.ndarray) -> None:
    """A colliding geom as a URDF ``<collision>`` (module docstring)."""
    kind = values.get("type", "sphere")
    size = [number(robot.label, where, token) for token in split_numbers(values.get("size", ""))]
    placed = pose(robot, where, {key: value for key, value in values.items() if key != "fromto"})
    if "fromto" in values:
        placed, half = fromto_pose(robot, where, values["fromto"])
        size = [*size[:1], half]
    robot.colliding.append(values)
    if kind not in ("sphere", "box", "capsule", "cylinder"):  # no URDF shape: a marker the ground code reports
        ET.SubElement(link, "mjcf_collision", type=kind)
        return
    shape = ("sphere", {"radius": repr(size[0])}) if kind == "sphere" else _shape("cylinder" if kind == "capsule" else kind, size)
    assert shape is not None  # sizes checked by _geom_values
    collision = ET.SubElement(link, "collision", {"name": "mjcf:capsule"} if kind == "capsule" else {})
    write_origin(collision, shift @ placed)
    ET.SubElement(ET.SubElement(collision, "geometry"), shape[0], shape[1])


def _integer(robot: MjcfRobot, where: str, values: dict[str, str], key: str) -> int:
    value = number(robot.label, f"{where}: {key}", values.get(key, "1"))
    if value != int(value) or value < 0:
        raise URDFError(robot.label, f"{where}: {key}={values.get(key)!r} is not a non-negative integer (MuJoCo refuses it)")
    return int(value)


def collides(robot: MjcfRobot, values: dict[str, str], where: str) -> bool:
    """Whether a geom collides with the world's plane by MuJoCo's rule: ``(contype &
    plane.conaffinity) or (plane.contype & conaffinity)`` (the plane's both 1 without one).

    Args:
        robot: The reading (its :attr:`~robodyn.urdf.mjcf_state.MjcfRobot.plane`).
        values: The geom's attributes, its defaults under them.
        where: The geom, for messages.

    Raises:
        URDFError: For a ``contype`` or ``conaffinity`` that is not a non-negative integer.
    """
    plane = robot.plane or {}
    contype, affinity = _integer(robot, where, values, "contype"), _integer(robot, where, values, "conaffinity")
    return bool(
        (contype & _integer(robot, "the plane", plane, "conaffinity"))
        or (_integer(robot, "the plane", plane, "contype") & affinity)
    )


def read_plane(root: ET.Element, robot: MjcfRobot) -> None:
    """``<worldbody>``'s first plane geom into :attr:`~robodyn.urdf.mjcf_state.MjcfRobot.plane`;
    further planes are reported (one line).

    Args:
        root: The ``<mujoco>`` element.
        robot: The reading.
    """
    world = root.find("worldbody")
    for index, geom in enumerate([] if world is None else world.findall("geom")):
        values = _geom_values(robot, geom, f"worldbody geom #{index + 1}", "main")
        if values.get("type", "sphere") != "plane":
            continue
        if robot.plane is None:
            robot.plane = values
        else:
            robot.note("ground planes after the first", values.get("name") or f"worldbody geom #{index + 1}")


def _friction(robot: MjcfRobot, values: dict[str, str], where: str) -> tuple[float, int]:
    """A geom's sliding friction and its ``condim``."""
    tokens = split_numbers(values.get("friction", "1")) or ["1"]
    sliding = number(robot.label, f"{where}: friction", tokens[0])
    if sliding < 0:
        raise URDFError(robot.label, f"{where}: friction={values['friction']!r} is negative")
    condim = _integer(robot, where, values, "condim") if "condim" in values else 3
    return sliding, condim


def plane_ground(robot: MjcfRobot) -> tuple[float, tuple[float, float, float], float] | None:
    """The file's ground: ``(height, normal, friction)`` of its plane, or ``None``.

    The plane ``n · (x − p) = 0`` (``p`` its ``pos``, ``n`` its ``z`` axis) meets world ``z``
    at ``height = n · p / n_z``. The friction is a pair's, combined as MuJoCo does by
    default: the larger sliding coefficient of the geom and the plane (0 where both have
    ``condim="1"``); where the colliding geoms' pairs differ, the largest is taken and said
    in one line. Torsional and rolling friction (``condim`` 4 or 6) are reported in one line.
    These lines are warnings that ``strict=True`` does not refuse (they concern contacts,
    not the dynamics).

    Args:
        robot: The reading, its bodies written (:attr:`~robodyn.urdf.mjcf_state.MjcfRobot.colliding`).
    """
    if robot.plane is None:
        return None
    name = robot.plane.get("name") or "the worldbody plane"
    placed = pose(robot, "the worldbody plane", robot.plane)
    normal, point = placed[:3, 2], placed[:3, 3]
    if normal[2] < 1e-6:
        robot.note("ground planes that do not face up (+z)", name)
        return None
    plane = _friction(robot, robot.plane, "the worldbody plane")
    pairs = [(_friction(robot, values, "a geom"), values.get("name") or "geom") for values in robot.colliding]
    mus = [0.0 if max(condim, plane[1]) == 1 else max(mu, plane[0]) for (mu, condim), _ in pairs] or [plane[0]]
    lines = []
    if len(set(mus)) > 1:
        lines.append(f"friction differs between geoms and the plane: the ground takes the largest, mu = {max(mus)!r}")
    torsional = [geom for (_, condim), geom in pairs if max(condim, plane[1]) > 3]
    if torsional:
        lines.append(f"torsional and rolling friction (condim 4 or 6) of contacts are not modelled ({len(torsional)} geoms)")
    for line in lines:  # contacts only, not the dynamics: said, never refused by strict=True
        warnings.warn(f"{robot.label}: MJCF {line} ({printable(name)})", RobodynWarning, stacklevel=6)
    height = float(normal @ point / normal[2])
    return height, (float(normal[0]), float(normal[1]), float(normal[2])), float(max(mus))


def _shape(kind: str, size: list[float]) -> tuple[str, dict[str, str]] | None:
    """The URDF shape drawing a geom (mesh assets are drawn as nothing yet)."""
    if kind == "box" and len(size) >= 3:
        return "box", {"size": text(2 * np.array(size[:3]))}
    if kind in ("sphere", "ellipsoid") and size:
        return "sphere", {"radius": repr(max(size))}
    if kind in ("capsule", "cylinder") and len(size) >= 2:
        return "cylinder", {"radius": repr(size[0]), "length": repr(2 * size[1])}
    return None


def set_total_mass(urdf: ET.Element, total: float) -> None:
    """Scale every mass and inertia so that they add up to ``total`` (``<compiler settotalmass>``).

    Args:
        urdf: The URDF's ``<robot>`` element being written.
        total: The total mass in [kg].
    """
    inertials = urdf.findall("link/inertial")
    current = sum(float(mass.get("value", "0")) for mass in urdf.findall("link/inertial/mass"))
    if current <= 0:
        return
    for node in inertials:
        for element in (node.find("mass"), node.find("inertia")):
            assert element is not None  # written by this module
            for key, value in element.attrib.items():
                element.set(key, repr(float(value) * total / current))
