"""Reading an MJCF (MuJoCo XML) robot: robodyn's own reader, without MuJoCo or Pinocchio.

This module is the entry; the reading is split by concern: the file-wide settings
(:mod:`~robodyn.urdf.mjcf_settings`), numbers and poses (:mod:`~robodyn.urdf.mjcf_values`),
bodies and joints (:mod:`~robodyn.urdf.mjcf_bodies`), what a body holds
(:mod:`~robodyn.urdf.mjcf_geoms`), the reading's state (:mod:`~robodyn.urdf.mjcf_state`).

An MJCF file is read into the URDF robodyn would have been given for the same robot, and
every later layer (validation, Pinocchio's model, the independent reference, ``lint``,
equations) reads that URDF (:attr:`~robodyn.urdf.sources.URDFSource.text`). A joint's
``damping``, ``frictionloss`` and ``armature`` are written as ``<dynamics damping friction
armature>`` (``armature`` is robodyn's extension of URDF:
:func:`robodyn.urdf.sources.with_file_dynamics` reads it).

The reading, as MuJoCo's compiler does it (docs/robot-files.md states every rule):

- ``<include file>`` expanded first (:mod:`~robodyn.urdf.mjcf_includes`);
- ``<compiler angle>`` (MuJoCo's default: **degree**), ``eulerseq``, ``autolimits``,
  ``inertiafromgeom``, ``settotalmass``; ``<default>`` classes (nested; ``class``,
  ``childclass``);
- orientations ``quat`` (**w x y z**), ``axisangle``, ``euler``, ``xyaxes``, ``zaxis``;
- bodies: a body's joints act in order at their ``pos`` (a chain through massless links);
  a body without joints is welded; ``hinge``, ``slide`` and a ``free`` top body (its
  ``<body pos quat>`` the robot's start, :attr:`~robodyn.urdf.sources.URDFSource.base_pose`,
  as MuJoCo's ``qpos0``); a joint's ``ref`` is the offset q = qpos − ref (the body in its
  modelled pose at q = 0, limits shifted); unnamed bodies, joints and sites are named
  ``bodyN``, ``jointN``, ``siteN`` after MuJoCo's ids (world body 0); ``<site>`` s are frames (``site:NAME`` where a body has the name; a
  ``fromto`` placed as MuJoCo places it; the world's on the fixed base);
- ``<inertial>`` or the inertia of the body's solid geoms (:mod:`robodyn.urdf.geom_inertia`);
- geoms that collide with the world's plane (``contype`` / ``conaffinity``) as
  ``<collision>`` s, the first ``<worldbody>`` plane as the robot's ground
  (:attr:`~robodyn.urdf.sources.URDFSource.ground`, :mod:`~robodyn.urdf.mjcf_geoms`);
- ``<option gravity>`` / ``<flag gravity>``, actuators (effort limits, the actuated set),
  ``<equality connect/weld>`` records (:mod:`~robodyn.urdf.mjcf_physics`);
- ``<keyframe>`` s kept (:attr:`~robodyn.urdf.sources.URDFSource.keyframes`, a start on
  request) and reported in one line: they are not the start.

Values are read as MuJoCo validates them; bodies and degrees of freedom are counted while
parsing (:class:`~robodyn.urdf.mjcf_state.Census`). Refused with one sentence: ``ball``
joints, a ``free`` joint below the top, a body whose inertia would come from a mesh geom
or a shell, ``<frame>``, ``<replicate>``, ``<attach>``, ``boundmass`` / ``boundinertia``.
Reported in one :class:`~robodyn.exceptions.RobodynWarning` line per kind (``strict=True``
refuses): tendons, equality constraints (read as records, not in the free dynamics), servo
gains, contact pairs / excludes, joint stiffness, ``gravcomp``, fluid forces, ``<flag>``
settings.
"""

from __future__ import annotations

import warnings
import xml.etree.ElementTree as ET
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from robodyn.common.text import printable
from robodyn.exceptions import RobodynWarning, URDFError
from robodyn.urdf.mjcf_bodies import free_joint, read_body
from robodyn.urdf.mjcf_geoms import plane_ground, read_plane, set_total_mass, write_sites
from robodyn.urdf.mjcf_includes import expand_includes
from robodyn.urdf.mjcf_physics import read_actuators, read_equalities, read_option
from robodyn.urdf.mjcf_settings import read_compiler, read_defaults
from robodyn.urdf.mjcf_state import DEFAULT_MAX_DOF, Census, MjcfRobot
from robodyn.urdf.mjcf_values import number, unit
from robodyn.urdf.source_type import URDFSource
from robodyn.urdf.xmltext import parse_xml, split_numbers

if TYPE_CHECKING:
    from robodyn.urdf.packages import PackageLookup

#: Elements whose effect on the motion robodyn does not model: one warning line each.
UNSUPPORTED = {"tendon": "tendons", "contact": "contact pairs and excludes"}
#: Elements refused outright.
REFUSED = ("frame", "replicate", "attach")


def mjcf_source(
    source: URDFSource,
    *,
    strict: bool,
    lookup: PackageLookup,
    max_dof: int | None = None,
    read_file: Callable[[Path], str] | None = None,
    max_bytes: int = 64 * 1024 * 1024,
) -> URDFSource:
    """The source of an MJCF document, as the URDF robodyn reads it (see the module).

    Args:
        source: The MJCF document.
        strict: Refuse what is otherwise reported.
        lookup: The package lookup the robot's source carries.
        max_dof: Most degrees of freedom (:class:`~robodyn.urdf.mjcf_state.Census`; default
            :data:`~robodyn.urdf.mjcf_state.DEFAULT_MAX_DOF`), counted while parsing.
        read_file: Reads an included file (regular files, the size cap); ``None``: no includes.
        max_bytes: Most bytes of included text in all.

    Raises:
        URDFError: One sentence naming what cannot be read.

    Warns:
        RobodynWarning: One line per kind of element the dynamics does not take.
    """
    census = Census(source.label, DEFAULT_MAX_DOF if max_dof is None else max_dof)
    root = parse_xml(source.text, source.label, root="mujoco", on_event=census)
    expand_includes(root, label=source.label, path=source.path, read_file=read_file, max_bytes=max_bytes, census=census)
    base_dir = source.path.parent if source.path is not None else None
    robot = read_mjcf(root, source.label, base_dir)
    ground = plane_ground(robot)
    _report(robot, source.label, strict)
    keyframes = read_keyframes(root, robot)
    if robot.outside:
        _start_line(source.label, "joints whose qpos0 (ref) is outside their range start at the nearest limit", robot.outside)
    return replace(
        source,
        text=ET.tostring(robot.urdf, encoding="unicode"),
        name=robot.urdf.get("name") or source.name,
        floating_base=robot.floating,
        package_dirs=lookup,
        file_format="mjcf",
        equalities=robot.equalities,
        gravity=robot.gravity,
        actuated=None if robot.actuated is None else tuple(sorted(robot.actuated)),
        joint_offsets=tuple(robot.refs.items()),
        ground=ground,
        base_pose=robot.base_pose,
        keyframes=keyframes,
    )


def read_keyframes(root: ET.Element, robot: MjcfRobot) -> tuple[tuple[str, tuple[float, ...]], ...]:
    """The ``<keyframe>`` s' ``qpos`` in MuJoCo's order by name (an unnamed key ``keyN``, N
    its MuJoCo id), as MuJoCo completes them (the values given first, the rest
    ``qpos0``; the free joint's quaternion normalised); reported in one line: they are
    not the start.

    Args:
        root: The ``<mujoco>`` element.
        robot: The reading's state, its bodies and joints read.

    Raises:
        URDFError: A ``qpos`` of more than MuJoCo's ``nq`` numbers, or not finite ones.
    """
    order = [node.get("name", "") for node in robot.urdf.findall("joint") if node.get("type") != "fixed"]
    qpos0 = [robot.refs.get(name, 0.0) for name in order]
    if robot.floating:
        x, y, z, qx, qy, qz, qw = robot.base_pose or (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)
        qpos0 = [x, y, z, qw, qx, qy, qz, *qpos0]
    found = []
    for index, key in enumerate(key for section in root.findall("keyframe") for key in section.findall("key")):
        name = key.get("name") or f"key{index}"
        where = f"keyframe {printable(name)!r}: qpos"
        given = [number(robot.label, where, token) for token in split_numbers(key.get("qpos", ""))]
        if len(given) > len(qpos0):
            raise URDFError(
                robot.label, f"{where} has {len(given)} numbers, more than the model's {len(qpos0)} (as MuJoCo refuses)"
            )
        qpos = np.array(given + qpos0[len(given) :])
        if robot.floating:
            qpos[3:7] = unit(robot.label, where, qpos[3:7])
        found.append((name, tuple(qpos.tolist())))
    if found:
        _start_line(
            robot.label,
            "keyframes are not the start, MuJoCo's qpos0 is",
            [name for name, _ in found],
            "; default_configuration(keyframe=NAME) gives a keyframe's qpos as q (its qvel, act, ctrl are not read)",
        )
    return tuple(found)


def _start_line(label: str, text: str, names: list[str], tail: str = "") -> None:
    """One warning line about the robot's start (never refused: the start is no model)."""
    shown = ", ".join(printable(name) for name in names[:8]) + (", ..." if len(names) > 8 else "")
    warnings.warn(f"{label}: MJCF {text} ({shown}){tail}", RobodynWarning, stacklevel=6)


def _report(robot: MjcfRobot, label: str, strict: bool) -> None:
    """One warning line per kind of what the dynamics leaves out, and per reading that
    differs from MuJoCo's (``strict``: refused)."""
    lines = [(f"MJCF {kind} are not part of robodyn's dynamics", names) for kind, names in robot.notes.items()]
    lines += [(f"MJCF {sentence}", names) for sentence, names in robot.remarks.items()]
    for text, names in lines:
        shown = ", ".join(printable(name) for name in names[:8]) + (", ..." if len(names) > 8 else "")
        if strict:
            raise URDFError(label, f"{text} ({shown}); strict=True refuses")
        left_out = " and are left out" if text.endswith("dynamics") else ""
        warnings.warn(f"{label}: {text}{left_out} ({shown})", RobodynWarning, stacklevel=5)


def read_mjcf(root: ET.Element, label: str, base_dir: Path | None) -> MjcfRobot:
    """Read a ``<mujoco>`` element (its includes expanded) into the URDF of the same robot.

    Args:
        root: The ``<mujoco>`` element.
        label: The file's name, for the error.
        base_dir: The file's folder, for its mesh paths (``None`` for text).

    Raises:
        URDFError: For what cannot be read (see the module).
    """
    for tag in REFUSED:
        if root.find(f".//{tag}") is not None:
            raise URDFError(label, f"MJCF <{tag}> is not read by robodyn (expand it into one file first)")
    robot = MjcfRobot(
        label,
        read_compiler(root, label, base_dir),
        read_defaults(root, label),
        ET.Element("robot", name=root.get("model") or "mjcf"),
    )
    robot.bodies = {body.get("name", "") for body in root.iter("body")}
    for tag, kind in UNSUPPORTED.items():
        for section in root.findall(tag):
            for index, element in enumerate(section):
                robot.note(kind, element.get("name") or f"<{element.tag}> #{index + 1}")
    robot.gravity = read_option(root, robot)
    read_actuators(root, robot)
    read_plane(root, robot)
    _read_world(root, robot)
    for joint in sorted(set(robot.efforts) - robot.joints):
        raise URDFError(label, f"an MJCF actuator drives joint {joint!r}, which the model does not have")
    robot.equalities = read_equalities(root, robot)
    if robot.compiler.total_mass > 0:
        set_total_mass(robot.urdf, robot.compiler.total_mass)
    return robot


def _read_world(root: ET.Element, robot: MjcfRobot) -> None:
    """The bodies of ``<worldbody>``: one free top body, or bodies welded to the world."""
    world = root.find("worldbody")
    bodies = [] if world is None else world.findall("body")
    if not bodies:
        raise URDFError(robot.label, "the MJCF <worldbody> has no <body>: there is no robot to read")
    free = [body for body in bodies if free_joint(robot, body) is not None]
    if free and len(bodies) > 1:
        others = ", ".join(
            repr(printable(body.get("name") or f"body #{index + 1}")) for index, body in enumerate(bodies) if body is not free[0]
        )
        raise URDFError(
            robot.label,
            f"the free-floating MJCF body {printable(free[0].get('name') or 'body #1')!r} has other bodies beside it in "
            f"<worldbody> ({others}): a second robot or object is not modelled (robodyn reads one robot)",
        )
    assert world is not None  # it has bodies
    if free:
        robot.floating = True
        robot.ids["site"] += len(world.findall("site"))  # MuJoCo's ids count the world's sites first
        read_body(robot, bodies[0], None, np.eye(4), "main")
        for index, site in enumerate(world.findall("site")):
            robot.note(
                "<worldbody> sites beside a floating robot (no world link holds them)", site.get("name") or f"#{index + 1}"
            )
        return
    robot.unique("world", "the MJCF worldbody")
    ET.SubElement(robot.urdf, "link", name="world")
    write_sites(robot, world, "world", np.eye(4), "main")
    for body in bodies:
        read_body(robot, body, "world", np.eye(4), "main")
