"""Inverse dynamics over a whole trajectory file, a chunk at a time, locally or on Dask.

:func:`torques_file` reads a trajectory file in chunks (:class:`~robodyn.scale.datasets.Dataset`),
computes ``tau = M(q) a + C(q, v) v + G(q)`` for every sample (optionally ``G(q)`` and the
upper triangle of ``M(q)``) and writes the same trajectory format with ``tau[<joint>]``
columns (``G[<joint>]``, ``M[<row>,<col>]``), atomically. Memory is bounded by a few chunks.
With a ``dask.distributed`` client the chunks are computed on its workers (at most two
chunks a worker in flight, results written in file order); a worker that dies is replaced
and its chunk re-run by Dask.
"""

from __future__ import annotations

import os
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from robodyn.common.text import printable
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError, RobodynError, TrajectoryError
from robodyn.scale.cluster import check_scheduler, connect
from robodyn.scale.datasets import DEFAULT_ROWS, Dataset, DatasetWriter


@dataclass(frozen=True)
class TorquesRun:
    """What :func:`torques_file` computed: peak and RMS effort of each degree of freedom.

    Attributes:
        robot: The robot's name.
        trajectory: The file read.
        samples: Rows computed; ``chunks``: in how many chunks.
        names: One name a velocity coordinate (``robot.dofs``: ``base.x`` … for a base).
        units: Unit of each one's effort (``"N m"`` or ``"N"``).
        peak: Largest ``|tau|`` of each, in ``units``; ``rms``: root mean square of tau.
        out: The file written, if any.
    """

    robot: str
    trajectory: str
    samples: int
    chunks: int
    names: tuple[str, ...]
    units: tuple[str, ...]
    peak: tuple[float, ...]
    rms: tuple[float, ...]
    out: str | None = None

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (the ``robodyn torques --json`` output): by name, in ``units``."""
        data: dict[str, Any] = {
            "robot": self.robot,
            "trajectory": self.trajectory,
            "samples": self.samples,
            "chunks": self.chunks,
            "peak_abs_torque": dict(zip(self.names, self.peak, strict=True)),
            "rms_torque": dict(zip(self.names, self.rms, strict=True)),
        }
        return data if self.out is None else data | {"out": self.out}

    def __getitem__(self, key: str) -> Any:
        """A key of :meth:`to_dict` (for code that reads the run as the JSON dict)."""
        return self.to_dict()[key]

    def text(self) -> str:
        """Readable text: peak and RMS effort of each degree of freedom, with its unit."""
        lines = [
            f"robot: {printable(self.robot)}",
            f"trajectory: {printable(self.trajectory)}",
            f"samples: {self.samples} ({self.chunks} chunks)",
            "joint: peak |tau|, rms tau",
        ]
        lines += [
            f"  {printable(name)}: {peak:.6g} {unit}, {rms:.6g} {unit}"
            for name, unit, peak, rms in zip(self.names, self.units, self.peak, self.rms, strict=True)
        ]
        return "\n".join(lines + ([f"wrote {self.out}"] if self.out is not None else []))


def chunk_dynamics(
    robot: Robot, q: np.ndarray, v: np.ndarray, a: np.ndarray, *, source: str, first_row: int, gravity: bool, mass_matrix: bool
) -> dict[str, np.ndarray]:
    """``tau`` (and ``G``, ``M``) of one chunk; a refusal names the file and the first bad row.

    Args:
        robot: The robot.
        q: Configurations, shape (n, nq), in [rad] / [m].
        v: Velocities, shape (n, nv), in [rad/s] / [m/s].
        a: Accelerations, shape (n, nv), in [rad/s²] / [m/s²].
        source: The input file's name, for the error.
        first_row: The chunk's first row in the file (1-based), for the error.
        gravity: Also compute ``G``.
        mass_matrix: Also compute ``M``.

    Returns:
        ``{"tau": (n, nv), "G": (n, nv), "M": (n, nv, nv)}`` (G and M when asked).

    Raises:
        TrajectoryError: Naming ``source`` and the row (1-based) whose state was refused.
    """
    try:
        result = {"tau": robot.inverse_dynamics(q, v, a)}
        if gravity:
            result["G"] = robot.gravity(q)
        if mass_matrix:
            result["M"] = robot.mass_matrix(q)
        return result
    except RobodynError as error:
        for offset in range(len(q)):  # locate the first state the robot refuses
            try:
                robot.inverse_dynamics(q[offset], v[offset], a[offset])
            except RobodynError as row_error:
                row = first_row + offset
                raise TrajectoryError(source, str(row_error).rstrip("."), (row, row)) from None
        raise TrajectoryError(source, str(error).rstrip("."), (first_row, first_row + len(q) - 1)) from None


def output_header(robot: Robot, *, gravity: bool, mass_matrix: bool) -> tuple[list[str], dict]:
    """Columns of the output file and, for NPZ, which columns make which array.

    Args:
        robot: The robot.
        gravity: The output has ``G`` columns.
        mass_matrix: The output has ``M`` columns.
    """
    q_names, v_names = list(robot.configuration_names), [dof.name for dof in robot.dofs]
    nq, nv = len(q_names), len(v_names)
    header = ["t"] + [f"q[{n}]" for n in q_names] + [f"{kind}[{n}]" for kind in ("v", "a", "tau") for n in v_names]
    start = 1 + nq + 3 * nv
    arrays = {
        "t": (np.array([0]), ()),
        "q": (np.arange(1, 1 + nq), (nq,)),
        "v": (np.arange(1 + nq, 1 + nq + nv), (nv,)),
        "a": (np.arange(1 + nq + nv, 1 + nq + 2 * nv), (nv,)),
        "tau": (np.arange(1 + nq + 2 * nv, start), (nv,)),
    }
    if gravity:
        header += [f"G[{n}]" for n in v_names]
        arrays["G"] = (np.arange(start, start + nv), (nv,))
        start += nv
    if mass_matrix:
        rows, columns = np.triu_indices(nv)
        header += [f"M[{v_names[i]},{v_names[j]}]" for i, j in zip(rows, columns, strict=True)]
        full = np.empty((nv, nv), dtype=int)  # NPZ: the full symmetric matrix, from the triangle's columns
        full[rows, columns] = full[columns, rows] = start + np.arange(len(rows))
        arrays["M"] = (full.ravel(), (nv, nv))
    return header, arrays


def torques_file(
    robot: Robot,
    source: str | os.PathLike,
    out: str | os.PathLike | None = None,
    *,
    gravity: bool = False,
    mass_matrix: bool = False,
    rows: int = DEFAULT_ROWS,
    client=None,
    progress: Callable[[int, int], None] | None = None,
) -> TorquesRun:
    """Inverse dynamics of every sample of a trajectory file.

    Args:
        robot: The robot (the file's joints must be its joints; column order is free).
        source: A trajectory file (``.csv``, ``.npz``, ``.parquet``); ``v`` and ``a`` are
            derived from ``q`` when absent.
        out: Output file (same formats), or ``None`` for the summary only.
        gravity: Also write ``G(q)`` (``G[<joint>]`` columns).
        mass_matrix: Also write ``M(q)`` (upper triangle ``M[<row>,<col>]``; NPZ: (N, nv, nv)).
        rows: Rows a chunk.
        client: A ``dask.distributed.Client`` to compute on, or ``None`` for this process.
        progress: ``progress(done_rows, total_rows)`` after each chunk.

    Returns:
        The run: samples, chunks, peak and RMS torque per degree of freedom, the output path.

    Raises:
        TrajectoryError: For a file of another robot, or bad data (naming file and rows);
            no output file is left then.
        InputError: Naming ``trajectory``, for states whose torques overflow (no output
            file is left then either).
    """
    if out is not None and Path(out).resolve() == Path(source).resolve():
        raise InputError("out", "a file other than the trajectory read", repr(str(out)))
    dataset = Dataset(source, rows=rows)
    names = dataset.layout.joint_names
    expected = robot.joint_names
    if sorted(names) != sorted(expected) or len(dataset.layout.q_names) != robot.nq:
        probe = _probe(dataset)
        probe.check(robot)  # raises, naming the columns
    header, arrays = output_header(robot, gravity=gravity, mass_matrix=mass_matrix)
    writer = DatasetWriter(out, header, robot=dataset.robot or robot.name, arrays=arrays) if out else None
    try:
        peak, rms, done, chunks = _accumulate(
            robot, dataset, client, writer, gravity=gravity, mass_matrix=mass_matrix, progress=progress
        )
        if not (np.isfinite(peak).all() and np.isfinite(rms).all()):
            raise InputError("trajectory", "states whose torques are finite", "an overflow")
        written = None if writer is None else writer.close(small=_names(robot))
    except BaseException:
        if writer is not None:
            writer.discard()
        raise
    return TorquesRun(
        robot.name, str(source), done, chunks, tuple(dof.name for dof in robot.dofs),
        tuple(dof.effort_unit for dof in robot.dofs), tuple(peak.tolist()), tuple(rms.tolist()),
        None if written is None else str(written),
    )  # fmt: skip


def torques_run(
    robot: Robot, source: str | os.PathLike, out: str | os.PathLike | None = None, *, scheduler: str | None = None, **options: Any
) -> TorquesRun:
    """:func:`torques_file` here, or on the Dask scheduler ``scheduler`` (an address or
    ``local:N``, :func:`robodyn.scale.cluster.connect`); ``options`` as for it.

    Args:
        scheduler: ``local:N`` or a Dask scheduler's address (``None``: run here).
    """
    if not scheduler:
        return torques_file(robot, source, out, **options)
    check_scheduler(scheduler)
    with connect(scheduler) as client:
        return torques_file(robot, source, out, client=client, **options)


def _accumulate(
    robot: Robot,
    dataset: Dataset,
    client,
    writer: DatasetWriter | None,
    *,
    gravity: bool,
    mass_matrix: bool,
    progress: Callable[[int, int], None] | None,
) -> tuple[np.ndarray, np.ndarray, int, int]:
    """Compute every chunk (writing it when ``writer`` is given): peak |tau|, RMS tau, rows, chunks."""
    nv, total = robot.nv, len(dataset)  # for progress (a CSV's lines, counted)
    peak, squares, done, chunks = np.zeros(nv), np.zeros(nv), 0, 0
    for chunk, result in _results(robot, dataset, client, gravity=gravity, mass_matrix=mass_matrix):
        trajectory = chunk.trajectory
        tau = result["tau"]
        peak = np.maximum(peak, np.abs(tau).max(axis=0))
        with np.errstate(over="ignore"):  # an overflow is refused by the caller, naming the file
            squares += np.square(tau).sum(axis=0)
        if writer is not None:
            parts = [trajectory.t, trajectory.q, trajectory.v, trajectory.a, tau]
            if gravity:
                parts.append(result["G"])
            if mass_matrix:
                iu = np.triu_indices(nv)
                parts.append(result["M"][:, iu[0], iu[1]])
            writer.write(np.column_stack(parts))
        done += len(tau)
        chunks += 1
        if progress is not None:
            progress(done, total)
    return peak, np.sqrt(squares / max(done, 1)), done, chunks


def _names(robot: Robot) -> dict[str, np.ndarray]:
    return {
        "q_names": np.array(robot.configuration_names),
        "v_names": np.array([dof.name for dof in robot.dofs]),
        "joint_names": np.array(robot.joint_names),
        "robot": np.array(robot.name),
    }


def _probe(dataset: Dataset):
    """The first chunk (for the error message of a file of another robot)."""
    return next(iter(dataset.chunks())).trajectory


def _results(robot: Robot, dataset: Dataset, client, *, gravity: bool, mass_matrix: bool):
    """(chunk, result) in file order, computed here or on the client's workers."""
    options: dict[str, Any] = {"gravity": gravity, "mass_matrix": mass_matrix, "source": dataset.source}
    if client is None:
        for chunk in dataset.chunks():
            trajectory = chunk.trajectory.for_robot(robot)
            chunk.trajectory = trajectory
            yield chunk, chunk_dynamics(robot, trajectory.q, trajectory.v, trajectory.a, first_row=chunk.first_row, **options)
        return
    # The robot travels with each task (it pickles by its source and options and is built once
    # per worker process): scattered data has no lineage, so a worker killed mid-run could
    # take the only copy the scheduler knew of with it and cancel every later chunk.
    window = 2 * max(1, len(client.nthreads()))
    pending: deque = deque()
    try:
        for chunk in dataset.chunks():
            trajectory = chunk.trajectory.for_robot(robot)
            chunk.trajectory = trajectory
            future = client.submit(
                chunk_dynamics,
                robot,
                trajectory.q,
                trajectory.v,
                trajectory.a,
                first_row=chunk.first_row,
                pure=False,
                **options,
            )
            pending.append((chunk, future))
            if len(pending) >= window:
                chunk, future = pending.popleft()
                yield chunk, future.result()
        while pending:
            chunk, future = pending.popleft()
            yield chunk, future.result()
    finally:
        for _, future in pending:
            future.cancel()


__all__ = ["TorquesRun", "chunk_dynamics", "output_header", "torques_file", "torques_run"]
