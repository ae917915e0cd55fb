"""The physics an MJCF file states beside its bodies: ``<option>`` (gravity, the flags,
fluid), ``<actuator>`` (effort limits and the actuated set) and ``<equality>`` (records).

- Gravity: ``<option gravity>`` (MuJoCo's default (0, 0, −9.81)), zero under
  ``<flag gravity="disable"/>``; carried on the source, the robot's gravity unless
  ``gravity=`` is given.
- ``<flag damper|frictionloss|spring="disable">`` zero the joints' damping, Coulomb
  friction and springs as MuJoCo does; flags that change nothing robodyn models
  (:data:`SILENT_FLAGS`: contacts, the constraint solver, numerics) are not reported;
  fluid forces (``density``, ``viscosity``, ``wind``) and the other flags are, one line each; the simulator's numerics (``timestep``, ``integrator``,
  solver settings) are not the model and are not reported.
- Actuators with a joint transmission: the force range of each (``gear`` × ``ctrlrange``
  where the force is the control — ``motor``, a ``general`` of fixed gain and no bias —
  within ``forcerange``), added over a joint's actuators, within the joint's
  ``actuatorfrcrange``, as MuJoCo clamps them; written as URDF ``<limit effort>`` (the
  larger magnitude of an asymmetric range, reported). The actuated set is the joints
  they drive. Servos (a gain on the state or a bias) and other transmissions are reported.
- ``<equality connect/weld>`` between bodies: :class:`~robodyn.urdf.equality.EqualityRecord`
  records in the links' frames; others reported.

This module does not import Pinocchio or MuJoCo.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import numpy as np

from robodyn.exceptions import URDFError
from robodyn.urdf.equality import EqualityRecord
from robodyn.urdf.mjcf_state import ACTUATOR_TAGS, MjcfRobot, attributes
from robodyn.urdf.mjcf_values import AUTO, floats, keyword, number, quaternion_matrix
from robodyn.urdf.xmltext import split_numbers

#: ``<flag>`` s robodyn honours when disabled: gravity (zero), joint damping, Coulomb
#: friction (``frictionloss``) and springs (``stiffness``, then not reported).
HONOURED_FLAGS = ("gravity", "damper", "frictionloss", "spring")
#: ``<flag>`` s that change nothing robodyn models (contacts, constraint solver, numerics,
#: diagnostics): not reported.
SILENT_FLAGS = (
    "contact",
    "constraint",
    "warmstart",
    "filterparent",
    "energy",
    "fwdinv",
    "invdiscrete",
    "multiccd",
    "sensor",
    "midphase",
    "eulerdamp",
    "autoreset",
    "nativeccd",
    "island",
    "sleep",
    "refsafe",
)
#: MuJoCo's actuator activation dynamics.
DYNTYPES = ("none", "integrator", "filter", "filterexact", "muscle", "user")
#: An interval of effort in [N m] or [N] (±inf: unbounded).
Interval = tuple[float, float]


def read_option(root: ET.Element, robot: MjcfRobot) -> tuple[float, float, float] | None:
    """The file's gravity in [m/s²] (``None`` if it states none); the ``<flag>`` s robodyn
    honours into ``robot.disabled``; fluid forces and the other flags that change the
    motion reported.

    Args:
        root: The ``<mujoco>`` element.
        robot: The MJCF robot being read (its settings, defaults, notes).
    """
    gravity: tuple[float, float, float] | None = None
    for option in root.findall("option"):
        if "gravity" in option.attrib:
            x, y, z = floats(robot.label, "<option gravity>", option.attrib["gravity"], 3)
            gravity = (float(x), float(y), float(z))
        for key in ("density", "viscosity", "wind"):
            if key in option.attrib and np.any(
                floats(robot.label, f"<option {key}>", option.attrib[key], 3 if key == "wind" else 1)
            ):
                robot.note("fluid forces (<option density viscosity wind>)", f"{key}={option.attrib[key].strip()}")
        for flag in option.findall("flag"):
            for key, value in flag.attrib.items():
                keyword(robot.label, "<flag>", key, value, ("enable", "disable"))
                if key in HONOURED_FLAGS and value == "disable":
                    robot.disabled.add(key)
                elif key in HONOURED_FLAGS:
                    robot.disabled.discard(key)
                elif key not in SILENT_FLAGS:
                    robot.note("<flag> settings", f"{key}={value}")
    if "gravity" in robot.disabled:
        return (0.0, 0.0, 0.0)
    return gravity


def read_actuators(root: ET.Element, robot: MjcfRobot) -> None:
    """Each actuator's force range into ``robot.efforts`` by joint, the driven joints into
    ``robot.actuated`` (``None`` when a transmission is not a joint).

    Args:
        root: The ``<mujoco>`` element.
        robot: The MJCF robot being read (its settings, defaults, notes).
    """
    sections = root.findall("actuator")
    if not sections:
        return
    robot.actuated = set()
    for section in sections:
        for index, node in enumerate(section):
            if node.tag not in ACTUATOR_TAGS:
                robot.note("actuators robodyn does not read", node.get("name") or f"<{node.tag}> #{index + 1}")
                robot.actuated = None
                continue
            _read_actuator(robot, node, node.get("name") or f"<{node.tag}> #{index + 1}")


def _read_actuator(robot: MjcfRobot, node: ET.Element, name: str) -> None:
    values = attributes(robot, node, "main")
    where = f'actuator "{name}"'
    joint = values.get("joint") or values.get("jointinparent")
    if joint is None:
        robot.note("actuators with a transmission other than a joint (the actuated set is every joint)", name)
        robot.actuated = None
        return
    if robot.actuated is not None:
        robot.actuated.add(joint)
    gear = number(robot.label, f"{where}: gear", (split_numbers(values.get("gear", "1")) or [""])[0])
    force = _force_range(robot, where, node.tag, values, name)
    low, high = sorted((gear * force[0], gear * force[1])) if gear else (0.0, 0.0)
    previous = robot.efforts.get(joint, (0.0, 0.0))
    total = (previous[0] + low, previous[1] + high)
    if all(math.isfinite(value) for value in (*force, *previous)) and not all(math.isfinite(value) for value in total):
        raise URDFError(robot.label, f"{where}: gear × its force range overflows; robodyn reads finite effort limits")
    robot.efforts[joint] = total


def _force_range(robot: MjcfRobot, where: str, tag: str, values: dict[str, str], name: str) -> Interval:
    """An actuator's force before its gear: the control range where the force is the
    control (a ``motor``; a ``general`` of fixed gain without bias, whose activation is the
    control or a filter of it, from 0), within the force range."""
    low, high = -math.inf, math.inf
    dynamics = keyword(robot.label, where, "dyntype", values.get("dyntype", "none"), DYNTYPES)
    general = (
        tag == "general"
        and values.get("gaintype", "fixed") == "fixed"
        and values.get("biastype", "none") == "none"
        and dynamics in ("none", "filter", "filterexact")
    )
    gain = number(robot.label, f"{where}: gainprm", (split_numbers(values.get("gainprm", "1")) or ["1"])[0]) if general else 1.0
    if tag == "motor" or general:
        if _limited(robot, where, values, "ctrl"):
            ctrl = _bounds(robot, f"{where}: ctrlrange", values.get("ctrlrange", "0 0"))
            low, high = sorted((gain * float(ctrl[0]), gain * float(ctrl[1])))
            if dynamics != "none":  # a filtered activation starts at 0
                low, high = min(low, 0.0), max(high, 0.0)
    else:
        robot.note("actuator gains and biases (servos: robodyn reads their force range only)", name)
    if _limited(robot, where, values, "force"):
        force = _bounds(robot, f"{where}: forcerange", values.get("forcerange", "0 0"))
        low, high = max(low, float(force[0])), min(high, float(force[1]))
    return low, high


def _bounds(robot: MjcfRobot, where: str, text: str) -> np.ndarray:
    """A range ``lower upper`` of two finite numbers.

    Raises:
        URDFError: If they are not, or if ``lower > upper`` (no clamp robodyn could state).
    """
    bounds = floats(robot.label, where, text, 2)
    if bounds[0] > bounds[1]:
        raise URDFError(robot.label, f"{where}: {text.strip()!r} has lower > upper")
    return bounds


def _limited(robot: MjcfRobot, where: str, values: dict[str, str], kind: str) -> bool:
    """MuJoCo's ``ctrllimited`` / ``forcelimited`` / ``actuatorfrclimited`` (``auto``: the range is given)."""
    attribute = {"ctrl": "ctrllimited", "force": "forcelimited", "actuatorfrc": "actuatorfrclimited"}[kind]
    limited = keyword(robot.label, where, attribute, values.get(attribute, "auto"), AUTO)
    if limited == "auto":
        return robot.compiler.autolimits and f"{kind}range" in values
    return limited == "true"


def joint_effort(robot: MjcfRobot, where: str, name: str, values: dict[str, str]) -> float:
    """A joint's effort limit in [N m] or [N]: its actuators' range within its
    ``actuatorfrcrange`` (inf when nothing bounds it).

    Args:
        robot: The MJCF robot being read (its settings, defaults, notes).
        where: Where in the file the joint is, for messages.
        name: The joint's name.
        values: The joint's attributes (its class's defaults under them).
    """
    low, high = robot.efforts.get(name, (-math.inf, math.inf))
    if _limited(robot, where, values, "actuatorfrc"):
        bound = _bounds(robot, f"{where}: actuatorfrcrange", values.get("actuatorfrcrange", "0 0"))
        low, high = max(low, float(bound[0])), min(high, float(bound[1]))
    if math.isfinite(low) and math.isfinite(high) and not math.isclose(-low, high):
        robot.remark(
            "actuator ranges are asymmetric; the URDF effort limit is the larger magnitude", f"{name} [{low:g}, {high:g}]"
        )
    return float(max(abs(low), abs(high)))


def read_equalities(root: ET.Element, robot: MjcfRobot) -> tuple[EqualityRecord, ...]:
    """The ``connect`` and ``weld`` equalities between bodies, in the links' frames (the
    robot's constraints, :attr:`robodyn.Robot.constraints`); any other equality (joint,
    tendon, distance, between sites) is noted as left out.

    Args:
        root: The ``<mujoco>`` element.
        robot: The MJCF robot being read (its settings, defaults, notes).
    """
    records = []
    for section in root.findall("equality"):
        for index, node in enumerate(section):
            name = node.get("name")
            values = _equality_attributes(robot, node)
            if node.tag not in ("connect", "weld") or "body1" not in values:
                robot.note("equality constraints other than body connect/weld", name or f"<{node.tag}> #{index + 1}")
                continue
            records.append(_equality(robot, node.tag, name, values))
    return tuple(records)


def _equality_attributes(robot: MjcfRobot, node: ET.Element) -> dict[str, str]:
    """An equality element's attributes with its class's ``<default><equality>`` under them."""
    attributes(robot, node, "main")  # refuses an undefined class
    values = dict(robot.defaults.get(node.get("class") or "main", {}).get("equality", {}))
    values.update(node.attrib)
    return values


def _equality(robot: MjcfRobot, kind: str, name: str | None, values: dict[str, str]) -> EqualityRecord:
    where = f"<{kind} {name or ''}>".replace(" >", ">")
    body1, body2 = values["body1"], values.get("body2")
    for body in (body1, body2):
        if body is not None and body not in robot.offsets:
            raise URDFError(robot.label, f"{where}: there is no body {body!r}")
    offset1 = robot.offsets[body1]
    offset2 = np.zeros(3) if body2 is None else robot.offsets[body2]
    anchor = floats(robot.label, f"{where}: anchor", values.get("anchor", "0 0 0"), 3)
    active = keyword(robot.label, where, "active", values.get("active", "true"), ("true", "false")) == "true"
    soft = tuple(key for key in ("solref", "solimp") if key in values)
    if kind == "connect":
        point = anchor - offset1
        return EqualityRecord(
            "connect", name, body1, body2, (float(point[0]), float(point[1]), float(point[2])), active=active, soft=soft
        )
    relpose = floats(robot.label, f"{where}: relpose", values.get("relpose", "0 1 0 0 0 0 0"), 7)
    pose = None
    if np.any(relpose[3:]):  # body1's link in body2's link: the same turn, moved by the links' offsets
        rotation = quaternion_matrix(robot.label, where, relpose[3:])
        position = relpose[:3] + rotation @ offset1 - offset2
        pose = (*(float(value) for value in position), *(float(value) for value in relpose[3:] / np.linalg.norm(relpose[3:])))
    point = anchor - offset2
    scale = number(robot.label, f"{where}: torquescale", values.get("torquescale", "1"))
    point3 = (float(point[0]), float(point[1]), float(point[2]))
    return EqualityRecord("weld", name, body1, body2, point3, pose, scale, active, soft)
