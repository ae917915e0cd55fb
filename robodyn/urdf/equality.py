"""Equality constraints a robot file declares (MJCF ``<equality connect/weld>``), as plain data.

The description layer only reads them; :mod:`robodyn.constraints` turns each record into a
constraint of the robot (a point anchor for ``connect``, a frame anchor for ``weld``).
Body names are the names of the links robodyn wrote for those bodies (an MJCF body keeps its
name); ``None`` is the world. This module does not import Pinocchio.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class EqualityRecord:
    """One ``<equality>`` element of a robot file.

    Attributes:
        kind: ``"connect"`` (a point of ``body1`` held on a point of ``body2``) or
            ``"weld"`` (``body1``'s frame held at a fixed pose relative to ``body2``'s).
        name: The element's ``name``, or ``None``.
        body1: The link of the first body.
        body2: The link of the second body, or ``None`` for the world.
        anchor: ``connect``: the point in ``body1``'s frame, in [m] (MuJoCo's ``anchor``;
            the point on ``body2`` is where it sits at the reference configuration).
            ``weld``: the point in ``body2``'s frame the weld is about (MuJoCo's ``anchor``).
        relpose: ``weld`` only: ``body1``'s pose in ``body2``'s frame as position (3) and
            quaternion **w x y z** (4), or ``None`` when the file leaves it to the
            reference configuration.
        torquescale: ``weld`` only: MuJoCo's ratio of rotational to translational rows.
        active: Whether the constraint is active at the start (MuJoCo's ``active``).
        soft: The softness attributes the file gives it (``solref``, ``solimp``, its own
            or its ``<default><equality>`` class's), which a rigid constraint does not model.
    """

    kind: str
    name: str | None
    body1: str
    body2: str | None
    anchor: tuple[float, float, float] = (0.0, 0.0, 0.0)
    relpose: tuple[float, ...] | None = None
    torquescale: float = 1.0
    active: bool = True
    soft: tuple[str, ...] = ()
