"""Trajectories: the :class:`Trajectory` type and its file format, one sample a row, SI units,
in CSV, NPZ (or Parquet for datasets).

Columns, named the same in every container (full description: ``docs/trajectory-format.md``;
the names in brackets are ``Robot.configuration_names`` and ``Robot.dofs``' names):

- ``t``: time in [s], strictly increasing (required);
- ``q[<joint>]``: joint position in [rad] or [m] (required); a floating base has seven
  coordinates first, ``q[base.x]``, ``q[base.y]``, ``q[base.z]`` (position in the world
  frame, [m]) and ``q[base.qx]``, ``q[base.qy]``, ``q[base.qz]``, ``q[base.qw]`` (unit
  quaternion);
- ``v[<joint>]``: velocity in [rad/s] or [m/s]; a floating base has six first,
  ``v[base.x]``, ``v[base.y]``, ``v[base.z]`` (linear, in the base frame, [m/s]) and
  ``v[base.rx]``, ``v[base.ry]``, ``v[base.rz]`` (angular, in the base frame, [rad/s]);
- ``a[<joint>]``: acceleration (same names as ``v``), optional;
- ``tau[<joint>]``: joint torque in [N m] / force in [N] (same names as ``v``), optional.

Column order does not matter (columns are matched by name); a kind that is present has
every coordinate. Without ``v`` columns, ``v`` is derived from ``q`` and without ``a``
columns, ``a`` from ``v`` (:func:`derive_velocities`: second-order finite differences,
``np.gradient(..., edge_order=2)``; a floating base's angular velocity from the quaternion's
derivative).

CSV: an optional first comment line ``# robodyn trajectory of <robot>; ...``, a header
line, one row a sample. NPZ: either the arrays ``t`` (N,), ``q`` (N, nq), ``v``, ``a``,
``tau`` (N, nv) with ``q_names`` / ``v_names`` (the names in brackets), ``joint_names`` and
``robot`` (what :meth:`Trajectory.save` writes), or one 1-D array a column named as in the
CSV header. Files written by robodyn 0.1 (floating-base q columns ``q0`` ... ``q<nq-1>``)
are still read.

Modules, one concern each: :mod:`~robodyn.trajectory.core` (the type),
:mod:`~robodyn.trajectory.columns` (names, layout, checks),
:mod:`~robodyn.trajectory.io` (files as tables) and
:mod:`~robodyn.trajectory.derivatives` (finite differences).
"""

from robodyn.trajectory.columns import (
    EXTRA_KINDS,
    KINDS,
    ROOT_JOINT,
    Layout,
    check_table,
    coordinate_names,
    coordinate_names_to_joints,
    parse_header,
    short_list,
)
from robodyn.trajectory.core import Trajectory
from robodyn.trajectory.derivatives import derive_velocities
from robodyn.trajectory.io import csv_preamble, format_rows, npz_columns, read_csv_header, read_table, write_csv, write_npz

__all__ = [
    "EXTRA_KINDS",
    "KINDS",
    "ROOT_JOINT",
    "Layout",
    "Trajectory",
    "check_table",
    "coordinate_names",
    "coordinate_names_to_joints",
    "csv_preamble",
    "derive_velocities",
    "format_rows",
    "npz_columns",
    "parse_header",
    "read_csv_header",
    "read_table",
    "short_list",
    "write_csv",
    "write_npz",
]
