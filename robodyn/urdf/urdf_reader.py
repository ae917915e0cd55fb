"""Reading a URDF's elements into values and problems (for :mod:`robodyn.urdf.validation`).

:class:`Reader` collects every problem (:class:`~robodyn.urdf.spec.Problem`) while it reads
numbers and attributes; :func:`read_inertial` and :func:`read_joint` read one ``<inertial>``
or ``<joint>`` element (origin, axis, limits, mimic, dynamics), checking each value on its
own. The checks of the whole model (one tree, mimic relations) are in
:mod:`robodyn.urdf.tree_checks`. This module does not import Pinocchio.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from typing import overload

import numpy as np

from robodyn.common.text import quoted
from robodyn.urdf.spec import Inertial, JointSpec, Mimic, Problem
from robodyn.urdf.xmltext import parse_number, split_numbers

#: Joint types robodyn knows. ``floating`` and ``planar`` are refused with a clear reason.
MOVING_JOINT_TYPES = ("revolute", "continuous", "prismatic")


KNOWN_JOINT_TYPES = (*MOVING_JOINT_TYPES, "fixed", "floating", "planar")


#: Largest magnitude accepted for a length, angle, mass, inertia or limit (SI units):
#: beyond it the dynamics overflow long before they mean anything.
MAX_MAGNITUDE = 1e12


_DEFAULTS: dict[str, tuple[float, ...]] = {}


class Reader:
    """Collects problems while reading numbers and attributes out of elements."""

    def __init__(self) -> None:
        self.problems: list[Problem] = []

    def error(self, element: str | None, rule: str) -> None:
        """Record an error.

        Args:
            element: The offending element, e.g. ``'joint "j1"'``, or ``None`` for the robot.
            rule: The rule it breaks, one sentence.
        """
        self.problems.append(Problem(element, rule))

    def warn(self, element: str | None, rule: str, *, loud: bool = False) -> None:
        """Record a warning.

        Args:
            element: The element it is about, or ``None`` for the robot.
            rule: What is suspicious, one sentence.
            loud: Shown when loading (and an error with ``strict=True``), not only by lint.
        """
        self.problems.append(Problem(element, rule, "warning", loud))

    def floats(self, where: str, node: ET.Element | None, attribute: str, default: str) -> np.ndarray:
        """An attribute's list of numbers, finite and within ``MAX_MAGNITUDE``.

        Args:
            where: The element named in messages.
            node: The element, or ``None`` when absent (then ``default``).
            attribute: The attribute's name.
            default: The numbers when the attribute is absent, as text; also their count.

        Returns:
            The numbers; ``default``'s, with an error recorded, when they are not valid.
        """
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
        """An attribute's number (infinities allowed, NaN refused).

        Args:
            where: The element named in messages.
            node: The element, or ``None`` when absent (then ``default``).
            attribute: The attribute's name.
            default: The value when the attribute is absent or invalid.
            bounded: Refuse finite values beyond ``MAX_MAGNITUDE``.

        Returns:
            The number; ``default``, with an error recorded, when it is not valid.
        """
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


def read_inertial(reader: Reader, where: str, node: ET.Element) -> Inertial | None:
    """One ``<inertial>`` element read, or ``None`` if it cannot be read.

    Args:
        reader: Collects the problems found.
        where: The element named in messages, e.g. ``'link "l1"'``.
        node: The ``<inertial>`` element.

    Returns:
        The link's :class:`~robodyn.urdf.spec.Inertial`, or ``None`` with the errors reported.
    """
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


def read_joint(reader: Reader, node: ET.Element, index: int) -> JointSpec | None:
    """One ``<joint>``, or ``None`` (with the errors reported) if it cannot be read.

    Args:
        reader: Collects the problems found.
        node: The ``<joint>`` element.
        index: Its position among the document's joints (names a joint without a name).
    """
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
    reader: Reader, where: str, node: ET.Element, joint_type: str
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


def _read_limits(reader: Reader, where: str, node: ET.Element, joint_type: str) -> tuple[float, float, float, float] | None:
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


def _read_mimic(reader: Reader, where: str, node: ET.Element) -> tuple[bool, Mimic | None]:
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


def _read_dynamics(reader: Reader, where: str, node: ET.Element, joint_type: str) -> tuple[float, float] | None:
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
