"""CSV rows in chunks: pyarrow's C++ reader and writer when pyarrow is installed (about 10-20×
faster than Python's), numpy and ``repr`` otherwise. Both read every number back exactly
(shortest round-trip formatting) and both stream with bounded memory."""

from __future__ import annotations

import importlib.util
import re
from collections.abc import Iterator
from itertools import islice
from pathlib import Path

import numpy as np

from robodyn.exceptions import TrajectoryError
from robodyn.trajectory import format_rows, read_csv_header

#: Whether pyarrow's CSV module is used (tests turn it off to cover the numpy path).
USE_ARROW = importlib.util.find_spec("pyarrow") is not None


def csv_tables(path: Path, source: str, *, width: int, rows: int, header_lines: int) -> Iterator[np.ndarray]:
    """The data rows of a CSV trajectory as float arrays of ``rows`` rows (the last fewer).

    Args:
        path: The CSV file.
        source: The file's name, for the error.
        width: Numbers a row.
        rows: Rows a table.
        header_lines: Lines before the data (skipped).

    Raises:
        TrajectoryError: For rows that are not ``width`` numbers, naming the rows.
    """
    yield from (_arrow_tables if USE_ARROW else _numpy_tables)(path, source, width, rows, header_lines)


def _numpy_tables(path: Path, source: str, width: int, rows: int, header_lines: int) -> Iterator[np.ndarray]:
    first_row = 1
    with path.open(encoding="utf-8") as stream:
        read_csv_header(stream, source)
        while lines := list(islice(stream, rows)):
            span = (first_row, first_row + len(lines) - 1)
            try:
                table = np.loadtxt(lines, delimiter=",", ndmin=2)
            except ValueError as error:
                raise TrajectoryError(source, f"a row is not {width} numbers ({error})", span) from None
            if table.shape[1] != width:
                raise TrajectoryError(source, f"rows have {table.shape[1]} values for {width} columns", span)
            first_row += len(table)
            yield table


def _arrow_tables(path: Path, source: str, width: int, rows: int, header_lines: int) -> Iterator[np.ndarray]:
    import pyarrow as pa
    import pyarrow.csv as pc

    names = [f"c{i}" for i in range(width)]

    def refuse(error: Exception, first: int):
        reason = str(error).replace("CSV parse error: ", "").replace("\n", " ")
        line = re.search(r"Row #(\d+)", reason)
        span = (int(line.group(1)) - header_lines,) * 2 if line else (first, first + rows - 1)
        return TrajectoryError(source, f"a row is not {width} numbers ({reason})", span)

    try:
        reader = pc.open_csv(
            pa.OSFile(str(path)),  # a plain file: a path would be memory-mapped (RSS and address space grow with the file)
            read_options=pc.ReadOptions(skip_rows=header_lines, column_names=names, block_size=1 << 20, use_threads=False),
            convert_options=pc.ConvertOptions(column_types=dict.fromkeys(names, pa.float64())),
        )
    except pa.ArrowInvalid as error:
        raise refuse(error, 1) from None
    pending: list[np.ndarray] = []
    held, first_row = 0, 1
    while True:
        try:
            batch = reader.read_next_batch()
        except StopIteration:
            break
        except pa.ArrowInvalid as error:  # the rows after those read so far
            reason = str(error).replace("CSV parse error: ", "").replace("\n", " ")
            raise TrajectoryError(
                source, f"a row is not {width} numbers ({reason})", (first_row + held, first_row + held + rows - 1)
            ) from None
        # nulls (empty fields, "nan") become NaN, refused with their row by the checks after
        pending.append(np.column_stack([column.to_numpy(zero_copy_only=False) for column in batch.columns]).astype(float))
        held += batch.num_rows
        while held >= rows:
            table = np.concatenate(pending)
            yield table[:rows]
            first_row += rows
            rest = table[rows:]
            pending, held = ([rest] if len(rest) else []), len(rest)
    if held:
        yield np.concatenate(pending)


def write_rows(stream, table: np.ndarray) -> None:
    """Append rows to a CSV file opened in binary mode.

    Args:
        stream: The file, opened for binary appending.
        table: The rows, shape (n, columns).
    """
    if USE_ARROW:
        import pyarrow as pa
        import pyarrow.csv as pc

        columns = [pa.array(table[:, i]) for i in range(table.shape[1])]
        pc.write_csv(
            pa.Table.from_arrays(columns, names=[f"c{i}" for i in range(table.shape[1])]),
            stream,
            pc.WriteOptions(include_header=False),
        )
        return
    for start in range(0, len(table), 4096):
        stream.write(format_rows(table[start : start + 4096]).encode("ascii"))
