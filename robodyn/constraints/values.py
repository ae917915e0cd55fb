"""Constraints as plain values: point anchors, frame anchors (welds) and point contacts.

Each constraint names its frames by **link name** (checked when it is bound to a robot:
:func:`check_frames`), states how many rows it adds (:attr:`rows`), and is a frozen
dataclass of numbers and names only: picklable, printable, hashable, with no robot inside.
What its rows mean (``Φ(q)``, ``J``, ``J̇ q̇``, the multipliers ``λ``) is
:mod:`robodyn.constraints.algebra`.

Conventions: points in [m] in the named link's frame (or the world's); orientations as
URDF roll-pitch-yaw in [rad]; multipliers in world axes (forces in [N], torques in [N m]).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

from robodyn.common.text import printable, quoted
from robodyn.exceptions import InputError

#: How many link names a refusal lists before it says how many more there are.
_LISTED = 30


def _numbers(value: Any, argument: str, size: int, unit: str) -> tuple[float, ...]:
    """``value`` as ``size`` finite floats, or an :class:`InputError` naming ``argument``
    (text and booleans are not numbers: ``"123"`` is not ``(1, 2, 3)``)."""
    try:
        if isinstance(value, str | bytes) or any(isinstance(x, bool | str | bytes) for x in value):
            raise TypeError(value)
        numbers = tuple(float(x) for x in value)
    except (TypeError, ValueError):
        raise InputError(argument, f"{size} finite numbers in {unit}", printable(repr(value))[:80]) from None
    if len(numbers) != size or not all(math.isfinite(x) for x in numbers):
        raise InputError(argument, f"{size} finite numbers in {unit}", printable(repr(value))[:80])
    return numbers


def _name(value: Any, argument: str, *, optional: bool = False) -> str | None:
    """A frame or constraint name: a non-empty string (or ``None`` where allowed)."""
    if value is None and optional:
        return None
    if not isinstance(value, str) or not value:
        raise InputError(argument, "a link name (a non-empty string)" + (" or None" if optional else ""), repr(value)[:80])
    return value


def _where(frame: str | None, point: Sequence[float] | None) -> str:
    """``point (x, y, z) of link 'name'`` / ``of the world`` / ``where it is at the neutral configuration``."""
    of = f"link {quoted(frame)}" if frame is not None else "the world"
    if point is None:
        return f"{of} (where it is at the neutral configuration)"
    return f"({', '.join(f'{x:.6g}' for x in point)}) of {of}"


@dataclass(frozen=True)
class PointAnchor:
    """A point of one link held on a point of another link or of the world (3 rows).

    A loop closure of a linkage, or a ball joint of a parallel robot. The rows are
    ``Φ = p1(q) − p2(q)`` in world axes, in [m]; the multiplier ``λ`` (3,) is the force in
    [N], world axes, that the constraint applies to ``frame1`` at ``point1`` (``frame2``
    gets ``−λ``).

    Attributes:
        frame1: The link carrying the first point.
        point1: The point in ``frame1``'s frame, in [m].
        frame2: The link carrying the second point, or ``None`` for the world.
        point2: The second point in ``frame2``'s frame (or world coordinates), in [m], or
            ``None``: where ``point1`` is at the robot's neutral configuration (MuJoCo's
            ``<equality connect>`` convention).
        name: A name for reports, or ``None``.
    """

    frame1: str
    point1: tuple[float, float, float] = (0.0, 0.0, 0.0)
    frame2: str | None = None
    point2: tuple[float, float, float] | None = None
    name: str | None = None
    kind: ClassVar[str] = "point anchor"

    def __post_init__(self) -> None:
        object.__setattr__(self, "frame1", _name(self.frame1, "frame1"))
        object.__setattr__(self, "frame2", _name(self.frame2, "frame2", optional=True))
        object.__setattr__(self, "point1", _numbers(self.point1, "point1", 3, "[m]"))
        if self.point2 is not None:
            object.__setattr__(self, "point2", _numbers(self.point2, "point2", 3, "[m]"))

    @property
    def rows(self) -> int:
        """Rows the constraint adds: 3."""
        return 3

    @property
    def frames(self) -> tuple[tuple[str, str | None], ...]:
        """``(field, link name)`` of the links it names (``None``: the world)."""
        return (("frame1", self.frame1), ("frame2", self.frame2))

    def __str__(self) -> str:
        return (
            f"{self.kind}{' ' + quoted(self.name) if self.name else ''} (3 rows): point {_where(self.frame1, self.point1)} "
            f"held on {_where(self.frame2, self.point2)}"
        )


@dataclass(frozen=True)
class FrameAnchor:
    """A frame of one link held at a pose relative to a frame of another link or of the world: a weld (6 rows).

    The rows are the position error ``p1 − p2`` [m] then the orientation error
    ``log(R1 R2ᵀ)`` [rad], world axes; ``J`` maps ``v`` to the relative linear and angular
    velocity, ``(v1 − v2, ω1 − ω2)`` (the orientation rows of ``Φ`` have that derivative
    at ``Φ = 0``). The multiplier ``λ`` (6,) is the force [N] and torque [N m], world
    axes, that the constraint applies to ``frame1`` at its anchored frame's origin.

    Attributes:
        frame1: The link carrying the first frame.
        origin1: The first frame in ``frame1``'s frame: x, y, z [m], roll, pitch, yaw [rad].
        frame2: The link carrying the second frame, or ``None`` for the world.
        origin2: The second frame in ``frame2``'s frame (or the world's), as ``origin1``;
            ``None``: where the first frame is at the robot's neutral configuration.
        name: A name for reports, or ``None``.
    """

    frame1: str
    origin1: tuple[float, float, float, float, float, float] = (0.0,) * 6
    frame2: str | None = None
    origin2: tuple[float, float, float, float, float, float] | None = None
    name: str | None = None
    kind: ClassVar[str] = "frame anchor"

    def __post_init__(self) -> None:
        object.__setattr__(self, "frame1", _name(self.frame1, "frame1"))
        object.__setattr__(self, "frame2", _name(self.frame2, "frame2", optional=True))
        object.__setattr__(self, "origin1", _numbers(self.origin1, "origin1", 6, "[m] and [rad]"))
        if self.origin2 is not None:
            object.__setattr__(self, "origin2", _numbers(self.origin2, "origin2", 6, "[m] and [rad]"))

    @property
    def rows(self) -> int:
        """Rows the constraint adds: 6."""
        return 6

    @property
    def frames(self) -> tuple[tuple[str, str | None], ...]:
        """``(field, link name)`` of the links it names (``None``: the world)."""
        return (("frame1", self.frame1), ("frame2", self.frame2))

    def __str__(self) -> str:
        return (
            f"{self.kind}{' ' + quoted(self.name) if self.name else ''} (6 rows, a weld): frame "
            f"{_where(self.frame1, self.origin1)} held on {_where(self.frame2, self.origin2)}"
        )


@dataclass(frozen=True)
class PointContact:
    """A point of a link on a plane of the world, with Coulomb friction ``μ``.

    A contact is unilateral (it can push, not pull, and slips outside its friction cone);
    at the dynamics layer an **active** contact is treated as a bilateral constraint, and
    nothing checks the sign of its normal force or its cone (that is the simulation's job):

    - ``friction > 0``: the point sticks: 3 rows (its world velocity is zero), ``λ`` (3,)
      the contact force in [N], world axes; the normal force is ``normal · λ``.
    - ``friction == 0``: the point slides on the plane without friction: 1 row (its
      velocity along the normal is zero), ``λ`` (1,) the normal force in [N].

    ``Φ`` is the gap ``normal · (p − plane_point)`` in [m] (for 3 rows, that gap along the
    normal and zero tangential rows: a sticking contact holds a velocity, not a place).

    Attributes:
        frame: The link carrying the point.
        point: The point in ``frame``'s frame, in [m].
        normal: The plane's normal in world axes (normalised), pointing out of the surface.
        friction: Coulomb's ``μ`` (≥ 0).
        plane_point: A point of the plane in world coordinates, in [m].
        name: A name for reports, or ``None``.
    """

    frame: str
    point: tuple[float, float, float] = (0.0, 0.0, 0.0)
    normal: tuple[float, float, float] = (0.0, 0.0, 1.0)
    friction: float = 1.0
    plane_point: tuple[float, float, float] = (0.0, 0.0, 0.0)
    name: str | None = None
    kind: ClassVar[str] = "point contact"

    def __post_init__(self) -> None:
        object.__setattr__(self, "frame", _name(self.frame, "frame"))
        object.__setattr__(self, "point", _numbers(self.point, "point", 3, "[m]"))
        object.__setattr__(self, "plane_point", _numbers(self.plane_point, "plane_point", 3, "[m]"))
        normal = _numbers(self.normal, "normal", 3, "world axes")
        length = math.sqrt(sum(x * x for x in normal))
        if not length > 1e-12:
            raise InputError("normal", "a non-zero vector", repr(normal))
        object.__setattr__(self, "normal", tuple(x / length for x in normal))
        mu = _numbers((self.friction,), "friction", 1, "[1]")[0]
        if mu < 0:
            raise InputError("friction", "a finite number >= 0 (Coulomb's μ)", repr(self.friction))
        object.__setattr__(self, "friction", mu)

    @property
    def rows(self) -> int:
        """Rows the constraint adds: 3 when it sticks (``friction > 0``), 1 when it slides."""
        return 3 if self.friction > 0 else 1

    @property
    def frames(self) -> tuple[tuple[str, str | None], ...]:
        """``(field, link name)`` of the link it names."""
        return (("frame", self.frame),)

    def __str__(self) -> str:
        how = "sticking, bilateral at this layer" if self.friction > 0 else "frictionless sliding"
        normal = ", ".join(f"{x:.6g}" for x in self.normal)
        return (
            f"{self.kind}{' ' + quoted(self.name) if self.name else ''} ({self.rows} row{'s' if self.rows > 1 else ''}, "
            f"{how}, μ = {self.friction:.6g}): point {_where(self.frame, self.point)} on the plane through "
            f"({', '.join(f'{x:.6g}' for x in self.plane_point)}) with normal ({normal})"
        )


#: A constraint of any kind.
Constraint = PointAnchor | FrameAnchor | PointContact
_KINDS = (PointAnchor, FrameAnchor, PointContact)


def as_constraints(value: object, argument: str = "constraints") -> tuple[Constraint, ...]:
    """``None``, one constraint or an iterable of them, as a tuple.

    Args:
        value: ``None``, a :class:`PointAnchor`, :class:`FrameAnchor`, :class:`PointContact`
            or an iterable of them.
        argument: The parameter's name, for the error.

    Raises:
        InputError: For anything that is not a constraint (naming its index).
    """
    if value is None:
        return ()
    if isinstance(value, _KINDS):
        return (value,)
    if isinstance(value, (str, bytes)) or not isinstance(value, Iterable):
        raise InputError(argument, "a PointAnchor, FrameAnchor, PointContact or a list of them", repr(value)[:80])
    items = tuple(value)
    for index, item in enumerate(items):
        if not isinstance(item, _KINDS):
            raise InputError(f"{argument}[{index}]", "a PointAnchor, FrameAnchor or PointContact", repr(item)[:80])
    return items


def check_frames(constraints: Sequence[Constraint], links: Sequence[str], robot: str) -> None:
    """Refuse a constraint naming a link the robot does not have, in one line listing the valid ones.

    Args:
        constraints: The constraints.
        links: The robot's link names.
        robot: The robot's name, for the error.

    Raises:
        InputError: Naming the constraint's index and field, the robot and its links.
    """
    valid = set(links)
    for index, constraint in enumerate(constraints):
        for field, frame in constraint.frames:
            if frame is not None and frame not in valid:
                listed = ", ".join(quoted(link) for link in list(links)[:_LISTED])
                more = f" and {len(links) - _LISTED} more" if len(links) > _LISTED else ""
                raise InputError(
                    f"constraints[{index}].{field}", f"a link of robot {quoted(robot)} ({listed}{more})", quoted(frame)
                )


def total_rows(constraints: Sequence[Constraint]) -> int:
    """Rows of a set of constraints (the length of ``λ`` and of ``Φ``).

    Args:
        constraints: The constraints.
    """
    return sum(constraint.rows for constraint in constraints)


__all__ = ["Constraint", "FrameAnchor", "PointAnchor", "PointContact", "as_constraints", "check_frames", "total_rows"]
