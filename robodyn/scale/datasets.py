"""Trajectory files larger than memory: read and written in chunks of rows.

A :class:`Dataset` reads a trajectory file (CSV, NPZ, Parquet; the columns of
:mod:`robodyn.trajectory`) a chunk of rows at a time, with the same checks as
:meth:`Trajectory.load` (columns named, NaN/inf and non-increasing time refused with the
row) and the same derived ``v`` and ``a`` when the file has only positions: each chunk is
differentiated with three rows of the chunks before and after it, so the result equals the
whole file's, row for row. Memory is bounded by the chunk size, not the file size.

:class:`DatasetWriter` writes chunks to a temporary file beside the target and renames it
at the end; a run that fails leaves no partial output (and keeps the file that was there).
"""

from __future__ import annotations

import contextlib
import io
import os
import shutil
import tempfile
import zipfile
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from robodyn.exceptions import InputError, TrajectoryError
from robodyn.scale.csvio import csv_tables, write_rows
from robodyn.trajectory import (
    Layout,
    Trajectory,
    check_table,
    csv_preamble,
    npz_columns,
    parse_header,
    read_csv_header,
)

#: Rows a chunk by default (panda: about 15 MB of float64 a chunk).
DEFAULT_ROWS = 65_536
#: Rows of context each side for derived v and a (a one-sided a at the last row reaches 3 rows back).
_CONTEXT = 3
SUFFIXES = (".csv", ".npz", ".parquet")


@dataclass
class Chunk:
    """Rows ``first_row`` ... of a file (1-based data rows), as a trajectory."""

    first_row: int
    trajectory: Trajectory

    @property
    def last_row(self) -> int:
        return self.first_row + len(self.trajectory) - 1


class Dataset:
    """A trajectory file read a chunk of rows at a time.

    Args:
        path: A ``.csv``, ``.npz`` or ``.parquet`` file.
        rows: Rows a chunk (≥ 3).

    Raises:
        TrajectoryError: For a missing file or a header that is not a trajectory's.
    """

    def __init__(self, path: str | os.PathLike, *, rows: int = DEFAULT_ROWS) -> None:
        self.path = Path(path)
        self.source = str(path)
        if self.path.suffix not in SUFFIXES:
            raise InputError("trajectory", "a .csv, .npz or .parquet file", repr(self.source))
        if isinstance(rows, bool) or not isinstance(rows, int) or rows < 3:
            raise InputError("rows", "a whole number ≥ 3", repr(rows))
        if not self.path.is_file():
            raise TrajectoryError(self.source, "no such file")
        self.rows = rows
        self.robot = ""
        self._length: int | None = None
        opener = {".csv": self._open_csv, ".npz": self._open_npz, ".parquet": self._open_parquet}[self.path.suffix]
        try:
            self.layout: Layout = opener()
        except (OSError, ValueError, KeyError, zipfile.BadZipFile) as error:
            if isinstance(error, TrajectoryError):
                raise
            raise TrajectoryError(self.source, f"not a readable trajectory ({error})") from None

    def __len__(self) -> int:
        """Number of samples (data rows); a CSV is counted once, without parsing it."""
        if self._length is None:
            self._length = self._count_csv()
        return self._length

    # ----------------------------------------------------------------------------------
    # Headers
    # ----------------------------------------------------------------------------------
    def _open_csv(self) -> Layout:
        with self.path.open(encoding="utf-8") as stream:
            names, self.robot, self._header_lines = read_csv_header(stream, self.source)
            first = stream.readline()
        if not first.strip():
            raise TrajectoryError(self.source, "no data rows")
        return parse_header(names, self.source, width=len(first.split(",")))

    def _count_csv(self) -> int:
        lines = 0
        with self.path.open("rb") as stream:
            last = b"\n"
            for block in iter(lambda: stream.read(1 << 20), b""):
                lines += block.count(b"\n")
                last = block[-1:]
        lines += last != b"\n"
        return lines - self._header_lines

    def _open_npz(self) -> Layout:
        self._members: dict[str, tuple[tuple[int, ...], bool, np.dtype]] = {}
        with zipfile.ZipFile(self.path) as archive:
            for info in archive.infolist():
                if info.filename.endswith(".npy"):
                    with archive.open(info) as member:
                        version = np.lib.format.read_magic(member)
                        read = np.lib.format.read_array_header_1_0 if version == (1, 0) else np.lib.format.read_array_header_2_0
                        self._members[info.filename[:-4]] = read(member)
        with np.load(self.path, allow_pickle=False) as data:
            shapes = {name: shape for name, (shape, _, _) in self._members.items()}
            header, self._keys, self.robot = npz_columns(shapes, data.__getitem__, self.source)
        lengths = {self._members[key][0][0] if self._members[key][0] else 0 for key in self._keys}
        if len(lengths) != 1:
            raise TrajectoryError(self.source, f"arrays of different lengths {sorted(lengths)}")
        self._length = lengths.pop()
        return parse_header(header, self.source)

    def _open_parquet(self) -> Layout:
        try:
            import pyarrow.parquet as pq
        except ImportError:
            raise TrajectoryError(
                self.source,
                "reading Parquet needs pyarrow (the 'robodyn[scale]' extra: pip install '.[scale]' in a clone of robodyn)",
            ) from None
        self._parquet = pq.ParquetFile(self.path)
        metadata = self._parquet.schema_arrow.metadata or {}
        self.robot = metadata.get(b"robot", b"").decode("utf-8", "replace")
        self._length = self._parquet.metadata.num_rows
        return parse_header(self._parquet.schema_arrow.names, self.source)

    # ----------------------------------------------------------------------------------
    # Raw tables, then checked chunks
    # ----------------------------------------------------------------------------------
    def tables(self) -> Iterator[np.ndarray]:
        """The file's rows as float arrays of at most :attr:`rows` rows, columns as the header."""
        reader = {".csv": self._csv_tables, ".npz": self._npz_tables, ".parquet": self._parquet_tables}[self.path.suffix]
        yield from reader()

    def _csv_tables(self) -> Iterator[np.ndarray]:
        yield from csv_tables(self.path, self.source, width=self.layout.width, rows=self.rows, header_lines=self._header_lines)

    def _npz_tables(self) -> Iterator[np.ndarray]:
        with zipfile.ZipFile(self.path) as archive, contextlib.ExitStack() as stack:
            readers = []
            for key in self._keys:
                shape, fortran, dtype = self._members[key]
                member = stack.enter_context(archive.open(key + ".npy"))
                version = np.lib.format.read_magic(member)
                (np.lib.format.read_array_header_1_0 if version == (1, 0) else np.lib.format.read_array_header_2_0)(member)
                readers.append(_NpyRows(member, shape, fortran, dtype, self.path, key))
            length = self._length or 0
            for start in range(0, length, self.rows):
                count = min(self.rows, length - start)
                yield np.column_stack([reader.read(start, count) for reader in readers])

    def _parquet_tables(self) -> Iterator[np.ndarray]:
        # One row group at a time (iter_batches reads ahead: its memory grows with the file).
        for group in range(self._parquet.num_row_groups):
            table = self._parquet.read_row_group(group, use_threads=False)
            for start in range(0, table.num_rows, self.rows):
                batch = table.slice(start, self.rows)
                yield np.column_stack([np.asarray(column.to_numpy(), dtype=float) for column in batch.columns])
            del table

    def chunks(self) -> Iterator[Chunk]:
        """Checked chunks as trajectories (``v``, ``a`` derived as for the whole file when absent).

        Raises:
            TrajectoryError: Naming the file and the rows at fault.
        """
        derive = self.layout.columns["v"] is None or self.layout.columns["a"] is None
        none = np.zeros((0, self.layout.width))
        before, pending, pending_first, next_first, last_time = none, None, 1, 1, None
        for table in self.tables():
            check_table(table, self.layout, self.source, first_row=next_first, previous_time=last_time)
            last_time, next_first = float(table[-1, self.layout.time]), next_first + len(table)
            if pending is not None:
                yield self._chunk(before, pending, table[:_CONTEXT] if derive else none, pending_first)
                before = pending[-_CONTEXT:] if derive else none
                pending_first += len(pending)
            pending = table
        if pending is not None:
            yield self._chunk(before, pending, none, pending_first)

    def _chunk(self, before: np.ndarray, rows: np.ndarray, after: np.ndarray, first_row: int) -> Chunk:
        window = np.concatenate([before, rows, after]) if len(before) or len(after) else rows
        if len(window) < 3 and (self.layout.columns["v"] is None or self.layout.columns["a"] is None):
            raise TrajectoryError(self.source, "at least 3 samples are needed to derive v and a from q")
        whole = Trajectory.from_table(window, self.layout, self.source, robot=self.robot, check=False)
        part = slice(len(before), len(before) + len(rows))
        tau = None if whole.tau is None else whole.tau[part]
        piece = Trajectory(
            whole.t[part], whole.q[part], whole.v[part], whole.a[part], tau, whole.joint_names, self.robot, self.source
        )
        return Chunk(first_row, piece)


class _NpyRows:
    """Rows of one ``.npy`` member of an NPZ, read sequentially without loading the rest."""

    def __init__(self, member, shape, fortran: bool, dtype: np.dtype, path: Path, key: str) -> None:
        self.member, self.shape, self.fortran, self.dtype, self.path, self.key = member, shape, fortran, dtype, path, key
        self.columns = int(np.prod(shape[1:])) if len(shape) > 1 else 1
        self.whole: np.ndarray | None = None

    def read(self, start: int, count: int) -> np.ndarray:
        if self.fortran and self.columns > 1:  # column-major: not streamable, read whole (once)
            if self.whole is None:
                with np.load(self.path, allow_pickle=False) as data:
                    self.whole = np.asarray(data[self.key], dtype=float).reshape(self.shape[0], -1)
            return self.whole[start : start + count]
        size = count * self.columns * self.dtype.itemsize
        data = self.member.read(size)
        if len(data) != size:
            raise TrajectoryError(str(self.path), f"array {self.key!r} is truncated", rows=(start + 1, start + count))
        return np.frombuffer(data, dtype=self.dtype).astype(float).reshape(count, self.columns)


class DatasetWriter:
    """Writes a trajectory file chunk by chunk, atomically (temporary file, then rename).

    Args:
        path: Target ``.csv``, ``.npz`` or ``.parquet`` file.
        header: Column names (``t``, ``q[...]``, ..., ``tau[...]``, ``G[...]``, ``M[...]``).
        length: Total rows expected, if known (checked at the end; ``None``: any).
        robot: Robot name for the file's comment / metadata.
        arrays: For ``.npz``: array name -> (column slice of the rows, shape of one row).
    """

    def __init__(
        self, path, header: list[str], *, length: int | None = None, robot: str = "", arrays: dict | None = None
    ) -> None:
        self.path = Path(path)
        if self.path.suffix not in SUFFIXES:
            raise InputError("out", "a .csv, .npz or .parquet file", repr(str(path)))
        self.header, self.length, self.robot, self.arrays = header, length, robot, arrays or {}
        self.path.parent.mkdir(parents=True, exist_ok=True)
        handle, name = tempfile.mkstemp(prefix=f".{self.path.name}.", suffix=".part", dir=self.path.parent)
        os.close(handle)
        self._temporary = Path(name)
        self._parts: list[Path] = [self._temporary]
        self._written = 0
        if self.path.suffix == ".csv":
            self._stream = self._temporary.open("wb")
            self._stream.write(csv_preamble(robot, header).encode("utf-8"))
        elif self.path.suffix == ".npz":
            self._npy = {}
            for key in self.arrays:
                part = self._temporary.with_name(self._temporary.name + f".{key}.npy")
                self._parts.append(part)
                self._npy[key] = part.open("wb")  # raw rows; the .npy header is written at the end
        else:
            import pyarrow as pa
            import pyarrow.parquet as pq

            schema = pa.schema([(name, pa.float64()) for name in header], metadata={"robot": robot})
            self._parquet = pq.ParquetWriter(self._temporary, schema)
            self._schema = schema

    def write(self, table: np.ndarray) -> None:
        """Append rows (shape (n, len(header))).

        Args:
            table: The rows, shape (n, len(header)).
        """
        if self.path.suffix == ".csv":
            write_rows(self._stream, table)
        elif self.path.suffix == ".npz":
            for key, (columns, shape) in self.arrays.items():
                self._npy[key].write(np.ascontiguousarray(table[:, columns], dtype="<f8").reshape(len(table), *shape).tobytes())
        else:
            import pyarrow as pa

            self._parquet.write_table(
                pa.Table.from_arrays([pa.array(table[:, i]) for i in range(table.shape[1])], schema=self._schema)
            )
        self._written += len(table)

    def close(self, *, small: dict[str, np.ndarray] | None = None) -> Path:
        """Finish the file and put it in place; ``small`` adds arrays to an NPZ (names).

        Args:
            small: Arrays by name added to an NPZ file (``None``: none).
        """
        try:
            if self.length is not None and self._written != self.length:
                raise TrajectoryError(str(self.path), f"wrote {self._written} rows of {self.length}")
            if self.path.suffix == ".csv":
                self._stream.close()
            elif self.path.suffix == ".npz":
                for stream in self._npy.values():
                    stream.close()
                with zipfile.ZipFile(self._temporary, "w", zipfile.ZIP_STORED, allowZip64=True) as archive:
                    for (key, (_, shape)), part in zip(self.arrays.items(), self._parts[1:], strict=True):
                        with part.open("rb") as raw, archive.open(_entry(key), "w", force_zip64=True) as member:
                            header = {"descr": "<f8", "fortran_order": False, "shape": (self._written, *shape)}
                            np.lib.format.write_array_header_1_0(member, header)
                            shutil.copyfileobj(raw, member, 1 << 20)
                    for key, value in (small or {}).items():
                        buffer = io.BytesIO()
                        np.lib.format.write_array(buffer, np.asarray(value), allow_pickle=False)
                        archive.writestr(_entry(key), buffer.getvalue())
            else:
                self._parquet.close()
            os.chmod(self._temporary, 0o666 & ~_umask())
            os.replace(self._temporary, self.path)
        finally:
            self.discard()
        return self.path

    def discard(self) -> None:
        """Remove the temporary files (the target is untouched)."""
        for stream in [getattr(self, "_stream", None), *getattr(self, "_npy", {}).values()]:
            if stream is not None:
                stream.close()
        if getattr(self, "_parquet", None) is not None:
            with contextlib.suppress(Exception):
                self._parquet.close()
        for part in self._parts:
            part.unlink(missing_ok=True)


def _entry(key: str) -> zipfile.ZipInfo:
    """A zip entry with a fixed date: the same data give the same file, byte for byte."""
    return zipfile.ZipInfo(key + ".npy", date_time=(1980, 1, 1, 0, 0, 0))


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def write_parquet(path: str | os.PathLike, trajectory: Trajectory) -> Path:
    """Write a whole trajectory as Parquet (the columns of the CSV header), atomically.

    Args:
        path: The ``.parquet`` file to write.
        trajectory: The trajectory.
    """
    writer = DatasetWriter(path, trajectory.header(), length=len(trajectory), robot=trajectory.robot)
    try:
        writer.write(trajectory.table())
    except BaseException:
        writer.discard()
        raise
    return writer.close()
