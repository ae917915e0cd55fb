"""The trajectory file format: one sample a row, SI units, CSV, NPZ (or Parquet for datasets).

Columns, named the same in every container (full description: ``docs/trajectory-format.md``):

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
"""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from robodyn.common.files import atomic_write_bytes, atomic_write_text
from robodyn.exceptions import InputError, TrajectoryError

if TYPE_CHECKING:
    from robodyn.dynamics.robot import Robot
from robodyn.sim.trajectory_columns import (
    BASE_Q,
    BASE_V,
    EXTRA_KINDS,
    KINDS,
    ROOT_JOINT,
    Layout,
    check_table,
    coordinate_names,
    derive_velocities,
    parse_header,
    short_list,
)


def coordinate_names_to_joints(v_names: list[str], floating_base: bool) -> list[str]:
    """``Robot.joint_names`` from velocity coordinate names (inverse of :func:`coordinate_names`)."""
    return [ROOT_JOINT, *v_names[len(BASE_V) :]] if floating_base else list(v_names)


@dataclass
class Trajectory:
    """A sampled motion, one row a sample.

    Attributes:
        t: Times in [s], shape (N,).
        q: Configurations, shape (N, nq).
        v: Velocities, shape (N, nv).
        a: Accelerations, shape (N, nv) (at the start of each step; last row repeats).
        tau: Joint torques, shape (N, nv), or ``None`` when the file had none.
        joint_names: ``Robot.joint_names`` of the robot (a floating base's root joint first).
        robot: Name of the robot ("" when unknown).
        source: The file it was read from ("" when made in memory), for messages.
    """

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    tau: np.ndarray | None = None
    joint_names: list[str] = field(default_factory=list)
    robot: str = ""
    source: str = ""

    def __len__(self) -> int:
        return len(self.t)

    @property
    def floating_base(self) -> bool:
        """Whether the first seven coordinates of ``q`` are a base pose."""
        return self.q.shape[1] == self.v.shape[1] + 1

    @property
    def coordinate_names(self) -> tuple[list[str], list[str]]:
        """Names of the q and v coordinates (the file's column names without the kind)."""
        nv = self.v.shape[1]
        names = list(self.joint_names)
        if len(names) == nv - (5 if self.floating_base else 0) and names:
            return coordinate_names(names, self.floating_base)
        joints = [str(i) for i in range(nv - (6 if self.floating_base else 0))]  # unnamed: numbered
        return (list(BASE_Q) if self.floating_base else []) + joints, (list(BASE_V) if self.floating_base else []) + joints

    def check(self, robot: Robot) -> None:
        """Refuse a trajectory of another robot (one sentence naming the columns).

        Args:
            robot: A :class:`robodyn.Robot`.

        Raises:
            TrajectoryError: If the sizes or the joint names differ from the robot's.
        """
        expected_q, _ = coordinate_names(robot.joint_names, robot.floating_base)
        have_q, _ = self.coordinate_names
        where = self.source or "the trajectory"
        of = f" of {self.robot!r}" if self.robot else ""
        if self.q.shape[1] != robot.nq or self.v.shape[1] != robot.nv:
            raise TrajectoryError(
                where,
                f"a trajectory{of} with {self.q.shape[1]} q and {self.v.shape[1]} v columns does not fit robot "
                f"{robot.name!r} (nq = {robot.nq}, nv = {robot.nv}: {short_list([f'q[{n}]' for n in expected_q])})",
            )
        if self.joint_names and have_q != expected_q:
            missing = [f"q[{n}]" for n in expected_q if n not in have_q]
            extra = [f"q[{n}]" for n in have_q if n not in expected_q]
            detail = (
                f"missing {short_list(missing)}; extra {short_list(extra)}"
                if missing
                else "its joints are in another order (Trajectory.for_robot reorders them)"
            )
            raise TrajectoryError(where, f"a trajectory{of} does not fit robot {robot.name!r}: {detail}")

    def for_robot(self, robot: Robot) -> Trajectory:
        """This trajectory with its columns in the robot's joint order (checked as :meth:`check`).

        Raises:
            TrajectoryError: If the joints are not the robot's.
        """
        expected_q, expected_v = coordinate_names(robot.joint_names, robot.floating_base)
        have_q, have_v = self.coordinate_names
        if not self.joint_names or have_q == expected_q or sorted(have_q) != sorted(expected_q):
            self.check(robot)
            return self
        rows_q = [have_q.index(name) for name in expected_q]
        rows_v = [have_v.index(name) for name in expected_v]
        tau = None if self.tau is None else self.tau[:, rows_v]
        joints = coordinate_names_to_joints(expected_v, robot.floating_base)
        return Trajectory(self.t, self.q[:, rows_q], self.v[:, rows_v], self.a[:, rows_v], tau, joints, self.robot, self.source)

    # ----------------------------------------------------------------------------------
    # Tables
    # ----------------------------------------------------------------------------------
    def header(self) -> list[str]:
        """The column names, as the CSV header writes them."""
        q_names, v_names = self.coordinate_names
        kinds = ("v", "a") if self.tau is None else ("v", "a", "tau")
        return ["t"] + [f"q[{n}]" for n in q_names] + [f"{kind}[{n}]" for kind in kinds for n in v_names]

    def table(self) -> np.ndarray:
        """The samples as one array, one row a sample, columns as :meth:`header`."""
        parts = [self.t, self.q, self.v, self.a] + ([] if self.tau is None else [self.tau])
        return np.column_stack(parts)

    @classmethod
    def from_table(
        cls, table: np.ndarray, layout: Layout, source: str, *, robot: str = "", first_row: int = 1, check: bool = True
    ) -> Trajectory:
        """A trajectory from rows of values laid out as ``layout`` (v and a derived if absent)."""
        table = np.asarray(table, dtype=float)
        if table.ndim != 2 or table.shape[1] != layout.width:
            raise TrajectoryError(source, f"rows have {table.shape[-1]} values, the header names {layout.width} columns")
        if check:
            check_table(table, layout, source, first_row=first_row)
        columns = {kind: None if index is None else table[:, index] for kind, index in layout.columns.items()}
        t, q = table[:, layout.time], table[:, layout.columns["q"]]
        v = columns["v"]
        if v is None:
            v = derive_velocities(t, q, floating_base=layout.floating_base)
        a = columns["a"] if columns["a"] is not None else derive_velocities(t, v, floating_base=False)
        return cls(t, q, v, a, columns["tau"], layout.joint_names, robot, source)

    # ----------------------------------------------------------------------------------
    # Files
    # ----------------------------------------------------------------------------------
    def save(self, path: str | Path) -> Path:
        """Write to ``.csv`` or ``.npz`` (by extension), atomically.

        Returns:
            The path written.
        """
        path = Path(path)
        if path.suffix == ".npz":
            buffer = io.BytesIO()
            q_names, v_names = self.coordinate_names
            arrays = {"t": self.t, "q": self.q, "v": self.v, "a": self.a}
            if self.tau is not None:
                arrays["tau"] = self.tau
            np.savez(
                buffer,
                **arrays,  # type: ignore[arg-type]
                q_names=np.array(q_names),
                v_names=np.array(v_names),
                joint_names=np.array(self.joint_names),
                robot=np.array(self.robot),
            )
            atomic_write_bytes(path, buffer.getvalue())
        elif path.suffix == ".csv":
            atomic_write_text(path, csv_preamble(self.robot, self.header()) + format_rows(self.table()))
        else:
            raise InputError("path", "a .csv or .npz file name", repr(str(path)))
        return path

    @classmethod
    def load(cls, path: str | Path) -> Trajectory:
        """Read a trajectory file (``.csv``, ``.npz``; ``.parquet`` with pyarrow installed).

        Raises:
            TrajectoryError: Naming the file and what is wrong with it (missing, unknown or
                extra columns, NaN/inf or non-increasing time with the row).
        """
        path = Path(path)
        source = str(path)
        if path.suffix not in (".csv", ".npz", ".parquet"):
            raise InputError("path", "a .csv, .npz or .parquet file name", repr(source))
        if not path.is_file():
            raise TrajectoryError(source, "no such file")
        try:
            if path.suffix == ".npz":
                return _load_npz(path)
            if path.suffix == ".parquet":
                return _load_parquet(path)
            return _load_csv(path)
        except (OSError, KeyError, ValueError, IndexError) as error:
            if isinstance(error, TrajectoryError | InputError):
                raise
            raise TrajectoryError(source, f"not a readable trajectory ({error})") from None


def csv_preamble(robot: str, header: list[str]) -> str:
    """The comment line and the header line of a CSV trajectory."""
    name = robot.replace("\n", " ").replace("\r", " ").replace(";", " ")
    line = io.StringIO()
    csv.writer(line, lineterminator="\n").writerow(header)  # names with commas or quotes are quoted
    return f"# robodyn trajectory of {name}; SI units (s, rad or m, rad/s or m/s, N m or N)\n" + line.getvalue()


def format_rows(table: np.ndarray) -> str:
    """CSV rows, each number written so that it reads back exactly (``repr``)."""
    return "".join(",".join(map(repr, row)) + "\n" for row in table.tolist())


def read_csv_header(stream, source: str) -> tuple[list[str], str, int]:
    """Read the comment and header lines of an open CSV file.

    Returns:
        The column names, the robot name ("" if no comment line) and the number of lines read.
    """
    first = stream.readline()
    robot, lines = "", 1
    if first.startswith("#"):
        robot = first.removeprefix("# robodyn trajectory of ").split(";")[0].strip() if "robodyn trajectory of" in first else ""
        first, lines = stream.readline(), 2
    if not first.strip():
        raise TrajectoryError(source, "empty file (expected a header line t,q[<joint>],...)")
    while first.count('"') % 2:  # a quoted name with a line break in it
        more = stream.readline()
        if not more:
            break
        first, lines = first + more, lines + 1
    names = [name.strip() for name in next(csv.reader([first.rstrip("\r\n")]))]
    if all(_is_number(name) for name in names):
        raise TrajectoryError(
            source,
            f"no header line: the first row has {len(names)} numbers; name the columns t,q[<joint>],... "
            "(the first column is the time t)",
        )
    return names, robot, lines


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _load_csv(path: Path) -> Trajectory:
    source = str(path)
    with path.open(encoding="utf-8") as stream:
        names, robot, _ = read_csv_header(stream, source)
        try:
            table = np.loadtxt(stream, delimiter=",", ndmin=2)
        except ValueError as error:
            raise TrajectoryError(source, f"a row is not a list of numbers ({error})") from None
    if table.size == 0:
        raise TrajectoryError(source, "no data rows")
    layout = parse_header(names, source, width=table.shape[1])
    return Trajectory.from_table(table, layout, source, robot=robot)


def npz_columns(shapes: dict[str, tuple[int, ...]], small, source: str) -> tuple[list[str], list[str], str]:
    """The header of an NPZ trajectory, the arrays whose columns make the table, the robot.

    Args:
        shapes: Shape of every array of the file, by name (without loading them).
        small: ``small(name)`` loads one of the small arrays (names, robot).
        source: The file, for messages.

    Returns:
        ``(header, keys, robot)``: stacking the arrays ``keys`` (as columns) gives a table
        with the columns ``header``.
    """
    keys = list(shapes)
    robot = str(small("robot")) if "robot" in keys else ""
    if "q" not in keys or len(shapes["q"]) != 2:  # one array a column
        columns = [k for k in keys if k not in ("robot", "joint_names")]
        return columns, columns, robot
    if "t" not in keys:
        raise TrajectoryError(source, "no array 't' (time in [s])")
    unknown = [k for k in keys if k not in (*KINDS, *EXTRA_KINDS, "t", "q_names", "v_names", "joint_names", "robot")]
    if unknown:
        raise TrajectoryError(source, f"unknown arrays {short_list(unknown)}")
    nq = shapes["q"][1]
    if "q_names" in keys:
        q_names = [str(n) for n in small("q_names")]
        v_names = [str(n) for n in small("v_names")] if "v_names" in keys else q_names
    else:  # robodyn 0.1: joint_names only
        joints = [str(n) for n in small("joint_names")] if "joint_names" in keys else []
        floating = bool(joints) and nq == len(joints) + 6
        q_names, v_names = coordinate_names(joints, floating) if joints else ([str(i) for i in range(nq)],) * 2
    header, stacked = ["t"], ["t"]
    for kind in KINDS:
        if kind in keys:
            names = q_names if kind == "q" else v_names
            if len(shapes[kind]) != 2 or shapes[kind][1] != len(names):
                raise TrajectoryError(source, f"array {kind!r} has shape {shapes[kind]} for {len(names)} names")
            header += [f"{kind}[{n}]" for n in names]
            stacked.append(kind)
    return header, stacked, robot


def _load_npz(path: Path) -> Trajectory:
    source = str(path)
    with np.load(path, allow_pickle=False) as data:
        header, keys, robot = npz_columns({k: data[k].shape for k in data}, data.__getitem__, source)
        arrays = [np.asarray(data[k], dtype=float) for k in keys]
    lengths = {len(array) for array in arrays}
    if len(lengths) > 1:
        raise TrajectoryError(source, f"arrays of different lengths {sorted(lengths)}")
    table = np.column_stack([array.reshape(len(array), -1) for array in arrays])
    return Trajectory.from_table(table, parse_header(header, source), source, robot=robot)


def _load_parquet(path: Path) -> Trajectory:
    try:
        import pyarrow.parquet as pq
    except ImportError:
        raise TrajectoryError(str(path), "reading Parquet needs pyarrow (pip install 'robodyn[scale]')") from None
    table = pq.read_table(path)
    header = table.column_names
    robot = (table.schema.metadata or {}).get(b"robot", b"").decode("utf-8", "replace")
    values = np.column_stack([table.column(name).to_numpy().astype(float) for name in header])
    return Trajectory.from_table(values, parse_header(header, str(path)), str(path), robot=robot)


__all__ = [
    "BASE_Q",
    "BASE_V",
    "ROOT_JOINT",
    "Layout",
    "Trajectory",
    "check_table",
    "coordinate_names",
    "derive_velocities",
    "parse_header",
]
