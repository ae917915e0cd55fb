"""The ground (a plane with Coulomb friction) and the robot's points that touch it.

A :class:`Ground` is the plane ``n · (x − c) = 0`` through ``c = (0, 0, height)`` with the
unit normal ``n`` (up by default; a tilted plane by its normal, :meth:`Ground.tilted`) and
the friction coefficient ``μ``. A :class:`ContactPoint` is a point of a robot's link, with
a radius: a sphere of that radius touches the plane at its centre minus ``radius · n``.

Where the points come from (:func:`contact_points`):

- **named frames** (``contacts=["FL_FOOT", ...]``): the frame's origin, radius 0;
- **the URDF's collision geometry** (``contacts="collision"``): each ``<sphere>`` is one
  point (its centre, its radius), each ``<box>`` its 8 corners, each ``<capsule>`` (the
  MJCF reader writes them) the two spheres of its radius at its ends (an approximation:
  its side between them never touches, said in one line; the MJCF reader writes a capsule
  as its cylinder in a collision named ``mjcf:capsule``); cylinders, ellipsoids and
  meshes (and the MJCF reader's ``<mjcf_collision type>`` markers) are not modelled and are reported in one line each (:attr:`Contacts.skipped`).
  With no sphere or box at all, the links named ``*foot`` (solo12's feet are meshes),
  said in one line.
"""

from __future__ import annotations

import functools
import itertools
import math
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass, field
from numbers import Real

import numpy as np

from robodyn.common.rotations import rpy_matrix
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import FrameError, InputError


@dataclass(frozen=True)
class Ground:
    """A plane with Coulomb friction.

    Attributes:
        height: Height of the plane along world ``z`` at ``x = y = 0``, in [m].
        normal: Its unit normal, pointing out of the ground (normalised on construction).
        friction: Coulomb coefficient ``μ ≥ 0`` (``0``: frictionless).
        origin: Where it comes from, for a run's summary (``""``: given as is).
    """

    height: float = 0.0
    normal: tuple[float, float, float] = (0.0, 0.0, 1.0)
    friction: float = 1.0
    origin: str = field(default="", compare=False)

    def __post_init__(self) -> None:
        if not (_real(self.height) and math.isfinite(self.height)):
            raise InputError("height", "a finite height in [m]", repr(self.height)[:80])
        friction = self.friction
        if isinstance(friction, bool) or not (isinstance(friction, int | float) and math.isfinite(friction) and friction >= 0):
            raise InputError("friction", "a finite coefficient μ ≥ 0", repr(self.friction))
        normal = _three(self.normal)
        size = 0.0 if normal is None else float(np.linalg.norm(normal))
        if normal is None or size < 1e-9:
            raise InputError("normal", "a non-zero finite 3-vector", repr(self.normal)[:80])
        object.__setattr__(self, "normal", tuple(float(x) for x in normal / size))
        object.__setattr__(self, "height", float(self.height))
        object.__setattr__(self, "friction", float(self.friction))

    @classmethod
    def tilted(cls, angle: float, *, friction: float = 1.0, height: float = 0.0) -> Ground:
        """A plane tilted by ``angle`` [rad] about world ``y``: it descends along ``+x``
        (its normal is ``(sin θ, 0, cos θ)``)."""
        return cls(height, (math.sin(angle), 0.0, math.cos(angle)), friction)

    @property
    def point(self) -> np.ndarray:
        """A point of the plane, ``(0, 0, height)``, in [m]."""
        return np.array([0.0, 0.0, self.height])

    def frame(self) -> np.ndarray:
        """The contact axes as rows ``(t₁, t₂, n)``: two tangents and the normal, shape (3, 3)."""
        return self._axes.copy()

    @functools.cached_property
    def _axes(self) -> np.ndarray:
        n = np.array(self.normal)
        seed = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
        t1 = seed - (seed @ n) * n
        t1 /= np.linalg.norm(t1)
        return np.array([t1, np.cross(n, t1), n])

    def gap(self, point: np.ndarray) -> np.ndarray:
        """Signed distance of points (…, 3) above the plane, in [m] (negative: penetration).

        Args:
            point: World positions in [m], shape (3,) or (…, 3).

        Returns:
            The distances along the plane's normal, shape () or (…,), in [m].
        """
        return (np.asarray(point, dtype=float) - self.point) @ np.array(self.normal)


@dataclass(frozen=True)
class ContactPoint:
    """A point of a link that may touch the ground.

    Attributes:
        name: Its name (the frame's, or ``<link>.sphere<i>`` / ``<link>.box<i>.corner<j>``).
        link: The Pinocchio frame (a link or a named frame) it is attached to.
        position: The point (a sphere's centre) in that frame, in [m].
        radius: A sphere's radius in [m] (0: a point).
    """

    name: str
    link: str
    position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    radius: float = 0.0

    def __post_init__(self) -> None:
        for argument in ("name", "link"):
            if not (isinstance(getattr(self, argument), str) and getattr(self, argument)):
                raise InputError(argument, "a non-empty name", repr(getattr(self, argument))[:80])
        position = _three(self.position)
        if position is None:
            raise InputError("position", "3 finite coordinates in [m]", repr(self.position)[:80])
        radius = self.radius
        if isinstance(radius, bool) or not (isinstance(radius, int | float) and math.isfinite(radius) and radius >= 0):
            raise InputError("radius", "a finite radius ≥ 0 in [m]", repr(radius))
        object.__setattr__(self, "position", _triple(position))
        object.__setattr__(self, "radius", float(radius))


def _real(value: object) -> bool:
    """Whether ``value`` is a real number (a boolean is not, nor is text)."""
    return isinstance(value, Real) and not isinstance(value, bool | np.bool_)


def _three(value: object) -> np.ndarray | None:
    """``value`` as 3 finite floats, or ``None``: text and booleans are not numbers
    (``"123"`` and ``("1", "2", "3")`` are not ``(1, 2, 3)``)."""
    try:
        items = np.asarray(value, dtype=object).reshape(-1) if not isinstance(value, str | bytes) else None
    except ValueError:  # a ragged sequence
        return None
    if items is None or len(items) != 3 or not all(_real(x) for x in items):
        return None
    values = np.array([float(x) for x in items])
    return values if np.isfinite(values).all() else None


@dataclass(frozen=True)
class Contacts:
    """The contact points of a robot and what of its collision geometry they leave out.

    Attributes:
        points: The points, in order.
        skipped: What is not modelled, one line a kind (cylinders, meshes, …).
    """

    points: tuple[ContactPoint, ...]
    skipped: tuple[str, ...] = field(default=())

    @property
    def names(self) -> list[str]:
        """The points' names."""
        return [point.name for point in self.points]


def _numbers(text: str | None, count: int, default: float) -> np.ndarray:
    values = [float(x) for x in (text or "").split()] or [default] * count
    if len(values) != count or not all(math.isfinite(x) for x in values):
        raise InputError("collision geometry", f"{count} finite numbers", repr(text))
    return np.array(values)


def _triple(values: np.ndarray) -> tuple[float, float, float]:
    return float(values[0]), float(values[1]), float(values[2])


def _shape_points(
    link: str, index: int, shape: ET.Element, offset: np.ndarray, rotation: np.ndarray
) -> list[ContactPoint] | None:
    """The contact points of one collision shape in its link's frame (``None``: not modelled)."""
    if shape.tag == "sphere":
        radius = float(_numbers(shape.get("radius"), 1, 0.0)[0])
        return [ContactPoint(f"{link}.sphere{index}", link, _triple(offset), radius)]
    if shape.tag == "capsule":  # the spheres at its ends, along its z axis (see collision_points)
        radius = float(_numbers(shape.get("radius"), 1, 0.0)[0])
        half_length = 0.5 * float(_numbers(shape.get("length"), 1, 0.0)[0])
        ends = [offset + rotation @ np.array([0.0, 0.0, sign * half_length]) for sign in (-1.0, 1.0)]
        return [ContactPoint(f"{link}.capsule{index}.end{end}", link, _triple(where), radius) for end, where in enumerate(ends)]
    if shape.tag == "box":
        half = 0.5 * _numbers(shape.get("size"), 3, 0.0)
        corners = [offset + rotation @ (half * np.array(signs)) for signs in itertools.product((-1.0, 1.0), repeat=3)]
        return [ContactPoint(f"{link}.box{index}.corner{corner}", link, _triple(where)) for corner, where in enumerate(corners)]
    return None


def collision_points(robot: Robot) -> Contacts:
    """Contact points from the URDF's ``<collision>`` spheres and boxes (module docstring).

    Args:
        robot: The loaded robot (its URDF text is read).
    """
    root = ET.fromstring(robot.urdf)
    points: list[ContactPoint] = []
    skipped: dict[str, list[str]] = {}  # kind -> the links with one
    capsules: list[str] = []
    for link in root.findall("link"):
        name = link.get("name") or ""
        for index, element in enumerate(link.findall("collision")):
            origin = element.find("origin")
            offset = _numbers(None if origin is None else origin.get("xyz"), 3, 0.0)
            rotation = rpy_matrix(_numbers(None if origin is None else origin.get("rpy"), 3, 0.0))
            geometry = element.find("geometry")
            shape = None if geometry is None or not len(geometry) else geometry[0]
            if shape is not None and shape.tag == "cylinder" and element.get("name") == "mjcf:capsule":
                shape = ET.Element("capsule", shape.attrib)  # the MJCF reader's capsule
            made = None if shape is None else _shape_points(name, index, shape, offset, rotation)
            if made is not None:
                points.extend(made)
                if shape is not None and shape.tag == "capsule":
                    capsules.append(name)
            else:
                skipped.setdefault("no geometry" if shape is None else str(shape.tag), []).append(name)
        for marker in link.findall("mjcf_collision"):  # an MJCF geom with no URDF shape
            skipped.setdefault(str(marker.get("type")), []).append(name)
    lines = []
    for kind, links in skipped.items():
        named = list(dict.fromkeys(links))  # each link once, in order
        shown = ", ".join(repr(link) for link in named[:3]) + (", …" if len(named) > 3 else "")
        lines.append(
            f"collision geometry not modelled as contacts (spheres, boxes and capsules are): {kind} × {len(links)} ({shown})"
        )
    if capsules:
        lines.append(f"capsules × {len(capsules)}: approximated by the spheres at their two ends (their sides do not touch)")
    return Contacts(tuple(points), tuple(lines))


def _moving(robot: Robot, found: Contacts) -> Contacts:
    """The points some joint moves; those fixed to the world are left out, one line each."""
    frames, model = robot.frame_ids, robot.model
    kept = [point for point in found.points if model.frames[frames[point.link]].parentJoint != 0]
    fixed = sorted({point.link for point in found.points} - {point.link for point in kept})
    lines = [f"link {link!r} is fixed to the world: its collision geometry is not a contact" for link in fixed]
    return Contacts(tuple(kept), (*found.skipped, *lines))


def _feet(robot: Robot, found: Contacts) -> Contacts:
    """Without a collision sphere or box, the links named ``*foot`` (solo12's meshes), said."""
    if found.points:
        return found
    feet = [name for name in robot.spec.links if name.lower().endswith("foot")]
    feet = [name for name in feet if name in robot.frame_ids and robot.model.frames[robot.frame_ids[name]].parentJoint != 0]
    if not feet:
        return found
    line = f"contacts: the links named *foot ({len(feet)}), the collision geometry has no sphere or box"
    return Contacts(tuple(ContactPoint(name, name) for name in feet), (*found.skipped, line))


def resolve_ground(robot: Robot, ground: Ground | str | None) -> Ground | None:
    """The ground a run stands on: ``ground`` itself, or for ``"file"`` the plane the
    robot's file states (MJCF: ``<worldbody>``'s plane geom,
    :attr:`~robodyn.urdf.sources.URDFSource.ground`).

    Args:
        robot: The robot.
        ground: A :class:`Ground`, ``"file"`` or ``None`` (no ground).

    Raises:
        InputError: For ``"file"`` when the file states no plane, or another value.
    """
    if ground is None or isinstance(ground, Ground):
        return ground
    if not (isinstance(ground, str) and ground == "file"):
        raise InputError("ground", 'a Ground, "file" (the plane the robot\'s file states) or None', repr(ground)[:80])
    stated = robot.source.ground
    if stated is None:
        raise InputError("ground", "a Ground: the robot's file states no ground plane", '"file"')
    height, normal, friction = stated
    return Ground(height, normal, friction, "the file's plane")


def asked_ground(robot: Robot, *, height: float | None = None, friction: float | None = None) -> Ground:
    """The ground asked by a height and a friction coefficient (``robodyn simulate --ground``).

    Args:
        robot: The robot.
        height: A flat plane's height in [m]; ``None``: the plane the robot's file states
            (:func:`resolve_ground` of ``"file"``), or a flat plane at height 0 when it
            states none (the ground's ``origin`` says which).
        friction: The coefficient ``μ``, overriding the file's; ``None``: the file's, else 1.

    Raises:
        InputError: For a height or friction that is not finite (a negative friction).
    """
    stated = robot.source.ground
    if height is None and stated is not None:
        found = Ground(*stated, "the file's plane")
        return found if friction is None else Ground(found.height, found.normal, friction, "the file's plane, μ given")
    if height is None:
        return Ground(0.0, friction=1.0 if friction is None else friction, origin="flat at height 0: the file states no plane")
    if friction is None and stated is not None:  # a plane at the height given keeps the file's μ
        return Ground(height, friction=stated[2], origin="flat at the height given, the file's plane's μ")
    return Ground(height, friction=1.0 if friction is None else friction, origin="")


def contact_points(robot: Robot, contacts: str | Sequence[str | ContactPoint]) -> Contacts:
    """The robot's contact points: ``"collision"`` (its collision spheres and boxes) or a
    list of frame names and :class:`ContactPoint` values.

    Args:
        robot: The loaded robot.
        contacts: ``"collision"`` (the URDF's collision spheres, boxes and capsules of moving
            links; without any, the links named ``*foot``), one frame name, or a sequence of
            frame names (a point at the frame's origin) and :class:`ContactPoint` values.

    Raises:
        FrameError: For a frame the robot does not have (with close names).
        InputError: For no points at all, an empty name or a duplicated name.
    """
    if isinstance(contacts, str) and contacts == "collision":
        found = _feet(robot, _moving(robot, collision_points(robot)))
    else:
        if isinstance(contacts, str):
            contacts = [contacts]
        frames = robot.frame_ids
        chosen = []
        for item in contacts:
            if not isinstance(item, ContactPoint) and not str(item):
                raise InputError("contacts", "frame names, none empty", repr(list(map(str, contacts)))[:80])
            point = item if isinstance(item, ContactPoint) else ContactPoint(str(item), str(item))
            if point.link not in frames:
                close = [name for name in frames if point.link.lower() in name.lower()][:5]
                raise FrameError(point.link, robot.name, close)
            robot.task_frame(point.link, "a contact point")  # StaticFrameError: fixed to the world
            chosen.append(point)
        found = Contacts(tuple(chosen))
    if not found.points:
        received = f"no collision sphere or box ({len(found.skipped)} other collision elements)" if found.skipped else "none"
        raise InputError("contacts", "at least one contact point: name the frames that touch the ground", received)
    names = found.names
    duplicated = sorted({name for name in names if names.count(name) > 1})
    if duplicated:
        raise InputError("contacts", "contact points with distinct names", f"{duplicated[0]!r} twice")
    return found


__all__ = ["ContactPoint", "Contacts", "Ground", "asked_ground", "collision_points", "contact_points", "resolve_ground"]
