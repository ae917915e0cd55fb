"""A robot file's equality constraints (MJCF ``<equality connect/weld>``) as constraints.

``connect`` becomes a :class:`~robodyn.constraints.values.PointAnchor` (the anchor on the
first body held where it is, at the neutral configuration, on the second body or the
world); ``weld`` a :class:`~robodyn.constraints.values.FrameAnchor` (the first body's frame
held at ``relpose`` in the second's, or where it is at the neutral configuration).
MuJoCo's softness (``solref``, ``solimp``) and a weld's ``torquescale`` weight a soft
constraint's rows; robodyn's constraints are rigid, so they do not apply, and
:func:`equality_notes` says so (the softness in one line naming the equalities, a
``torquescale`` in one line each). An element inactive at the start
(``active="false"``) is no constraint of the robot, and is reported too.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from robodyn.common.rotations import matrix_rpy
from robodyn.common.text import quoted
from robodyn.constraints.values import Constraint, FrameAnchor, PointAnchor
from robodyn.urdf.equality import EqualityRecord


def _wxyz_matrix(w: float, x: float, y: float, z: float) -> np.ndarray:
    """Rotation matrix of a quaternion written w, x, y, z (normalised here)."""
    norm = float(np.sqrt(w * w + x * x + y * y + z * z))
    w, x, y, z = (c / norm for c in (w, x, y, z))
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def from_equality(record: EqualityRecord) -> Constraint | None:
    """The constraint of one equality record, or ``None`` when it is inactive at the start.

    Args:
        record: An MJCF ``connect`` or ``weld`` equality as read from the file.
    """
    if not record.active:
        return None
    if record.kind == "connect":
        return PointAnchor(record.body1, tuple(record.anchor), record.body2, None, name=record.name)  # type: ignore[arg-type]
    relpose = record.relpose
    origin2 = None
    if relpose is not None:
        rpy = matrix_rpy(_wxyz_matrix(*relpose[3:7]))
        origin2 = (*relpose[:3], *(float(angle) for angle in rpy))
    return FrameAnchor(record.body1, (0.0,) * 6, record.body2, origin2, name=record.name)  # type: ignore[arg-type]


def from_equalities(records: Sequence[EqualityRecord]) -> tuple[Constraint, ...]:
    """The constraints of a file's equality records (inactive ones left out: :func:`equality_notes`).

    Args:
        records: A file's equality records.
    """
    converted = (from_equality(record) for record in records)
    return tuple(constraint for constraint in converted if constraint is not None)


def equality_notes(records: Sequence[EqualityRecord]) -> list[str]:
    """One line for each part of the records robodyn does not model (inactive elements,
    a weld's ``torquescale`` other than 1), and one line naming every active equality
    whose file gives it a softness (``solref``, ``solimp``).

    Args:
        records: A file's equality records.
    """
    notes = []
    soft = []
    for record in records:
        label = f"<equality {record.kind}{' ' + quoted(record.name) if record.name else ''}>"
        if record.active and record.soft:
            soft.append(f"{record.kind} {quoted(record.name) if record.name else 'unnamed'} ({'/'.join(record.soft)})")
        if not record.active:
            notes.append(f'{label} is inactive at the start (active="false"): not a constraint of the robot')
        elif record.kind == "weld" and record.torquescale != 1.0:
            notes.append(f"{label}: torquescale {record.torquescale:g} weights a soft weld's rows; robodyn's weld is rigid")
    if soft:
        shown = ", ".join(soft[:8]) + (", ..." if len(soft) > 8 else "")
        notes.append(f"<equality> softness (solref, solimp) is not modelled, robodyn's constraints are rigid: {shown}")
    return notes


__all__ = ["equality_notes", "from_equalities", "from_equality"]
