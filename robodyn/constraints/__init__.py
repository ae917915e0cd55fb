"""Constraints on a robot: loop closures, welds and contacts, as plain values (numpy only).

- :mod:`~robodyn.constraints.values`: :class:`PointAnchor`, :class:`FrameAnchor`,
  :class:`PointContact` (frozen dataclasses naming links by name; picklable, printable).
- :mod:`~robodyn.constraints.records`: a file's ``<equality connect/weld>`` as constraints.
- :mod:`~robodyn.constraints.algebra`: what the rows are (``Φ``, ``J``, ``J̇ v``, ``λ``)
  given the kinematics of a constraint's two ends, which an engine supplies: Pinocchio
  (:mod:`robodyn.dynamics.constrained`) or the reference (:mod:`robodyn.reference.constraints`).

This package sits below :mod:`robodyn.dynamics` and :mod:`robodyn.reference` and imports
neither, nor Pinocchio. See docs/constraints.md.
"""

from __future__ import annotations

from robodyn.constraints.records import equality_notes, from_equalities
from robodyn.constraints.values import (
    Constraint,
    FrameAnchor,
    PointAnchor,
    PointContact,
    as_constraints,
    check_frames,
    total_rows,
)

__all__ = [
    "Constraint",
    "FrameAnchor",
    "PointAnchor",
    "PointContact",
    "as_constraints",
    "check_frames",
    "equality_notes",
    "from_equalities",
    "total_rows",
]
