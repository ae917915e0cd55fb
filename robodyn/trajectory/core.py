"""The :class:`Trajectory` type: a sampled motion, one row a sample, in SI units.

Its file format (columns, containers, what is derived when absent) is described in
:mod:`robodyn.trajectory` and ``docs/trajectory-format.md``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from robodyn.dynamics.dofs import BASE_Q_NAMES, BASE_V_NAMES
from robodyn.exceptions import InputError, TrajectoryError
from robodyn.trajectory.columns import Layout, check_table, coordinate_names, coordinate_names_to_joints, short_list
from robodyn.trajectory.derivatives import derive_velocities
from robodyn.trajectory.io import read_table, write_csv, write_npz

if TYPE_CHECKING:
    from robodyn.dynamics.robot import Robot


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
        base_q, base_v = (list(BASE_Q_NAMES), list(BASE_V_NAMES)) if self.floating_base else ([], [])
        return base_q + joints, base_v + joints

    def check(self, robot: Robot) -> None:
        """Refuse a trajectory of another robot (one sentence naming the columns).

        Args:
            robot: A :class:`robodyn.Robot`.

        Raises:
            TrajectoryError: If the sizes or the joint names differ from the robot's.
        """
        expected_q = list(robot.configuration_names)
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

        Args:
            robot: The robot whose joints the trajectory's columns name.

        Raises:
            TrajectoryError: If the joints are not the robot's.
        """
        expected_q, expected_v = list(robot.configuration_names), [dof.name for dof in robot.dofs]
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

        Args:
            path: The ``.csv`` or ``.npz`` file to write.

        Returns:
            The path written.
        """
        path = Path(path)
        if path.suffix == ".npz":
            arrays = {"t": self.t, "q": self.q, "v": self.v, "a": self.a}
            if self.tau is not None:
                arrays["tau"] = self.tau
            q_names, v_names = self.coordinate_names
            write_npz(path, arrays, q_names=q_names, v_names=v_names, joint_names=self.joint_names, robot=self.robot)
        elif path.suffix == ".csv":
            write_csv(path, self.robot, self.header(), self.table())
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
        table, layout, robot = read_table(path)
        return cls.from_table(table, layout, str(path), robot=robot)


__all__ = ["Trajectory"]
