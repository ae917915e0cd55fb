"""The trajectory file format: one sample a row, SI units, CSV or NPZ.

CSV: an optional first comment line ``# robodyn trajectory of <robot>; SI units ...``, then a
header ``t,q[<joint>],...,v[<joint>],...,a[<joint>],...,tau[<joint>],...`` and one row a
sample. NPZ: arrays ``t``, ``q``, ``v``, ``a``, ``tau``, ``joint_names``, ``robot``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from robodyn.common.files import atomic_write_bytes, atomic_write_text
from robodyn.exceptions import InputError, RobodynError


@dataclass
class Trajectory:
    """A sampled motion, one row a sample.

    Attributes:
        t: Times in [s], shape (N,).
        q: Configurations, shape (N, nq).
        v: Velocities, shape (N, nv).
        a: Accelerations, shape (N, nv) (at the start of each step; last row repeats).
        tau: Applied joint torques, shape (N, nv).
        joint_names: Names of the velocity coordinates' joints (``Robot.joint_names``).
        robot: Name of the robot.
    """

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    tau: np.ndarray
    joint_names: list[str] = field(default_factory=list)
    robot: str = ""

    def __len__(self) -> int:
        return len(self.t)

    def save(self, path: str | Path) -> Path:
        """Write to ``.npz`` or ``.csv`` (by extension), atomically.

        The CSV has a header ``t,q[name],...,v[name],...,a[...],tau[...]`` and a first
        comment line naming the robot.
        """
        path = Path(path)
        if path.suffix == ".npz":
            import io

            buffer = io.BytesIO()
            np.savez(
                buffer,
                t=self.t,
                q=self.q,
                v=self.v,
                a=self.a,
                tau=self.tau,
                joint_names=np.array(self.joint_names),
                robot=np.array(self.robot),
            )
            atomic_write_bytes(path, buffer.getvalue())
        elif path.suffix == ".csv":
            atomic_write_text(path, self._csv())
        else:
            raise InputError("path", "a .csv or .npz file name", repr(str(path)))
        return path

    def _csv(self) -> str:
        q_names = [f"q{i}" for i in range(self.q.shape[1])]
        if self.q.shape[1] == len(self.joint_names):
            q_names = [f"q[{name}]" for name in self.joint_names]
        header = ["t", *q_names] + [f"{kind}[{name}]" for kind in ("v", "a", "tau") for name in self.joint_names]
        table = np.column_stack([self.t, self.q, self.v, self.a, self.tau])
        lines = [f"# robodyn trajectory of {self.robot}; SI units (s, rad or m, rad/s or m/s, N m or N)", ",".join(header)]
        lines += [",".join(repr(float(x)) for x in row) for row in table]
        return "\n".join(lines) + "\n"

    @classmethod
    def load(cls, path: str | Path) -> Trajectory:
        """Read a trajectory written by :meth:`save`.

        Raises:
            RobodynError: If the file is missing or not a robodyn trajectory.
        """
        path = Path(path)
        try:
            if path.suffix == ".npz":
                with np.load(path, allow_pickle=False) as data:
                    return cls(
                        data["t"],
                        data["q"],
                        data["v"],
                        data["a"],
                        data["tau"],
                        [str(n) for n in data["joint_names"]],
                        str(data["robot"]),
                    )
            if path.suffix == ".csv":
                return cls._from_csv(path)
        except (OSError, KeyError, ValueError, IndexError) as error:
            raise RobodynError(f"{path}: not a readable robodyn trajectory ({error}).") from None
        raise InputError("path", "a .csv or .npz file name", repr(str(path)))

    @classmethod
    def _from_csv(cls, path: Path) -> Trajectory:
        lines = path.read_text(encoding="utf-8").splitlines()
        commented = bool(lines) and lines[0].startswith("#")
        robot = lines[0].removeprefix("# robodyn trajectory of ").split(";")[0] if commented else ""
        header = lines[int(commented)].split(",")
        table = np.loadtxt(path, delimiter=",", skiprows=int(commented) + 1, ndmin=2)
        names = [h[2:-1] for h in header if h.startswith("v[")]
        nv = len(names)
        nq = len(header) - 1 - 3 * nv
        q_end = 1 + nq
        return cls(
            table[:, 0],
            table[:, 1:q_end],
            table[:, q_end : q_end + nv],
            table[:, q_end + nv : q_end + 2 * nv],
            table[:, q_end + 2 * nv :],
            names,
            robot,
        )
