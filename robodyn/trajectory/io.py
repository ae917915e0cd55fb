"""Trajectory files on disk: CSV and NPZ written, CSV, NPZ and Parquet read, as tables.

Each reader gives ``(table, layout, robot)``: the samples as one array (one row a sample),
the :class:`~robodyn.trajectory.columns.Layout` of its columns and the robot's name;
:meth:`robodyn.Trajectory.load` makes the trajectory of them. The writers take what
:meth:`robodyn.Trajectory.save` hands them. The chunked readers of large datasets
(:mod:`robodyn.scale.datasets`) use the same header and column functions.
"""

from __future__ import annotations

import csv
import io
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any, TextIO

import numpy as np

from robodyn.common.files import atomic_write_bytes, atomic_write_text
from robodyn.exceptions import InputError, TrajectoryError
from robodyn.trajectory.columns import EXTRA_KINDS, KINDS, Layout, coordinate_names, extra_columns, parse_header, short_list

#: File name suffixes :func:`read_table` reads.
READ_SUFFIXES = (".csv", ".npz", ".parquet")
#: Arrays an NPZ trajectory may hold besides the columns' kinds.
_NPZ_NAMES = ("t", "q_names", "v_names", "joint_names", "robot")


def csv_preamble(robot: str, header: list[str]) -> str:
    """The comment line and the header line of a CSV trajectory.

    Args:
        robot: The robot's name (line breaks and ``;`` become spaces in the comment line).
        header: The column names.
    """
    name = robot.replace("\n", " ").replace("\r", " ").replace(";", " ")
    line = io.StringIO()
    csv.writer(line, lineterminator="\n").writerow(header)  # names with commas or quotes are quoted
    return f"# robodyn trajectory of {name}; SI units (s, rad or m, rad/s or m/s, N m or N)\n" + line.getvalue()


def format_rows(table: np.ndarray) -> str:
    """CSV rows, each number written so that it reads back exactly (``repr``).

    Args:
        table: The samples, shape (N, columns).
    """
    return "".join(",".join(map(repr, row)) + "\n" for row in table.tolist())


def write_csv(path: Path, robot: str, header: list[str], table: np.ndarray) -> None:
    """Write a CSV trajectory atomically.

    Args:
        path: The ``.csv`` file.
        robot: The robot's name (for the comment line).
        header: Column names, as many as ``table`` has columns.
        table: Samples, shape (N, len(header)).
    """
    atomic_write_text(path, csv_preamble(robot, header) + format_rows(table))


def write_npz(
    path: Path, arrays: dict[str, np.ndarray], *, q_names: list[str], v_names: list[str], joint_names: list[str], robot: str
) -> None:
    """Write an NPZ trajectory atomically: the arrays ``t``, ``q``, ``v``, ``a`` (``tau``)
    with the names of their coordinates.

    Args:
        path: The ``.npz`` file.
        arrays: Kind -> array: ``t`` (N,), ``q`` (N, nq), ``v``, ``a``, ``tau`` (N, nv).
        q_names: The nq configuration coordinate names.
        v_names: The nv velocity coordinate names.
        joint_names: ``Robot.joint_names``.
        robot: The robot's name.
    """
    buffer = io.BytesIO()
    np.savez(
        buffer,
        **arrays,  # type: ignore[arg-type]
        q_names=np.array(q_names),
        v_names=np.array(v_names),
        joint_names=np.array(joint_names),
        robot=np.array(robot),
    )
    atomic_write_bytes(path, buffer.getvalue())


def read_table(path: Path) -> tuple[np.ndarray, Layout, str]:
    """Read a trajectory file (``.csv``, ``.npz``; ``.parquet`` with pyarrow installed).

    Args:
        path: The file.

    Returns:
        ``(table, layout, robot)``: the samples (N, layout.width), their columns, the robot's
        name ("" when the file does not say).

    Raises:
        InputError: For another suffix.
        TrajectoryError: Naming the file and what is wrong with it.
    """
    source = str(path)
    if path.suffix not in READ_SUFFIXES:
        raise InputError("path", "a .csv, .npz or .parquet file name", repr(source))
    if not path.is_file():
        raise TrajectoryError(source, "no such file")
    try:
        if path.suffix == ".npz":
            return _read_npz(path)
        if path.suffix == ".parquet":
            return _read_parquet(path)
        return _read_csv(path)
    except (OSError, KeyError, ValueError, IndexError) as error:
        if isinstance(error, TrajectoryError | InputError):
            raise
        raise TrajectoryError(source, f"not a readable trajectory ({error})") from None


def read_csv_header(stream: TextIO, source: str) -> tuple[list[str], str, int]:
    """Read the comment and header lines of an open CSV file.

    Args:
        stream: The file, at its start.
        source: Its name, for errors.

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


def _read_csv(path: Path) -> tuple[np.ndarray, Layout, str]:
    source = str(path)
    with path.open(encoding="utf-8") as stream:
        names, robot, _ = read_csv_header(stream, source)
        try:
            with warnings.catch_warnings():  # numpy's "input contained no data": the error below says it
                warnings.simplefilter("ignore")
                table = np.loadtxt(stream, delimiter=",", ndmin=2)
        except ValueError as error:
            raise TrajectoryError(source, f"a row is not a list of numbers ({error})") from None
    if table.size == 0:
        raise TrajectoryError(source, "no data rows")
    return table, parse_header(names, source, width=table.shape[1]), robot


def npz_columns(shapes: dict[str, tuple[int, ...]], small: Callable[[str], Any], source: str) -> tuple[list[str], list[str], str]:
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
    unknown = [k for k in keys if k not in (*KINDS, *EXTRA_KINDS, *_NPZ_NAMES)]
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


def _read_npz(path: Path) -> tuple[np.ndarray, Layout, str]:
    source = str(path)
    with np.load(path, allow_pickle=False) as data:
        header, keys, robot = npz_columns({k: data[k].shape for k in data}, data.__getitem__, source)
        arrays = [np.asarray(data[k], dtype=float) for k in keys]
    lengths = {len(array) for array in arrays}
    if len(lengths) > 1:
        raise TrajectoryError(source, f"arrays of different lengths {sorted(lengths)}")
    table = np.column_stack([array.reshape(len(array), -1) for array in arrays])
    return table, parse_header(header, source), robot


def _read_parquet(path: Path) -> tuple[np.ndarray, Layout, str]:
    try:
        import pyarrow.parquet as pq
    except ImportError:
        raise TrajectoryError(
            str(path), "reading Parquet needs pyarrow (the 'robodyn[scale]' extra: pip install '.[scale]' in a clone of robodyn)"
        ) from None
    table = pq.read_table(path)
    header = table.column_names
    robot = (table.schema.metadata or {}).get(b"robot", b"").decode("utf-8", "replace")
    values = np.column_stack([table.column(name).to_numpy().astype(float) for name in header])
    return values, parse_header(header, str(path)), robot


def write_csv_with_columns(
    path: Path, trajectory: Any, extras: dict[str, np.ndarray], names: list[str], columns: list[np.ndarray]
) -> Path:
    """Write a trajectory's columns, then ``extras`` (named like ``v``, ``<kind>[<coordinate>]``),
    then further ``columns`` named ``names`` (a run's forces, multipliers, flags), atomically, as
    CSV: the one place the three are laid side by side.

    Args:
        path: The ``.csv`` file.
        trajectory: A :class:`robodyn.Trajectory` of N samples.
        extras: Kind -> values, each shape (N, nv).
        names: The further columns' header names, one a column.
        columns: The further columns, each shape (N,) or (N, k); ``k`` columns in all
            equal ``len(names)``.

    Returns:
        The path written.
    """
    _, v_names = trajectory.coordinate_names
    header = trajectory.header() + [f"{kind}[{name}]" for kind in extras for name in v_names] + list(names)
    write_csv(path, trajectory.robot, header, np.column_stack([trajectory.table(), *extras.values(), *columns]))
    return path


def write_with_extras(path: Path, trajectory: Any, extras: dict[str, np.ndarray]) -> Path:
    """Write a trajectory with extra columns (:data:`~robodyn.trajectory.columns.EXTRA_KINDS`
    named like ``v``, e.g. ``tau_ext[<joint>]``), atomically, to ``.csv`` or ``.npz``.

    Args:
        path: The file.
        trajectory: A :class:`robodyn.Trajectory`.
        extras: Kind -> values, each shape (N, nv), in [N m] / [N].

    Returns:
        The path written.

    Raises:
        InputError: For another suffix, an unknown kind or a wrong shape.
    """
    path = Path(path)
    shape = trajectory.v.shape
    for kind, values in extras.items():
        if kind not in EXTRA_KINDS or kind == "M" or np.shape(values) != shape:
            raise InputError("extras", f"kinds of {EXTRA_KINDS} but M, each of shape {shape}", f"{kind!r}: {np.shape(values)}")
    if path.suffix not in (".csv", ".npz"):
        raise InputError("path", "a .csv or .npz file name", repr(str(path)))
    if not extras:
        return trajectory.save(path)
    q_names, v_names = trajectory.coordinate_names
    if path.suffix == ".csv":
        return write_csv_with_columns(path, trajectory, extras, [], [])
    arrays = {"t": trajectory.t, "q": trajectory.q, "v": trajectory.v, "a": trajectory.a}
    arrays |= {} if trajectory.tau is None else {"tau": trajectory.tau}
    write_npz(path, arrays | extras, q_names=q_names, v_names=v_names, joint_names=trajectory.joint_names, robot=trajectory.robot)
    return path


def read_extra(path: Path, kind: str) -> np.ndarray | None:
    """The extra columns of one kind a trajectory file holds (``tau_ext``, ``tau_env``, ``G``).

    Args:
        path: The trajectory file (``.csv`` or ``.npz``).
        kind: ``"tau_ext"``, ``"tau_env"`` or ``"G"``.

    Returns:
        Shape (N, nv) in the file's ``v`` order, or ``None`` when the file has none.
    """
    path = Path(path)
    table, layout, _ = read_table(path)
    if path.suffix == ".npz":
        with np.load(path, allow_pickle=False) as data:
            return np.asarray(data[kind], dtype=float) if kind in data else None
    return extra_columns(table, layout, kind)


__all__ = [
    "csv_preamble",
    "format_rows",
    "npz_columns",
    "read_csv_header",
    "read_extra",
    "read_table",
    "write_csv",
    "write_csv_with_columns",
    "write_npz",
    "write_with_extras",
]
