"""What a simulation experiment came to: :class:`SimulationSummary`, its JSON and its text.

:func:`robodyn.sim.experiment.run_simulation` returns one; ``robodyn simulate`` prints its
:meth:`~SimulationSummary.text` or :meth:`~SimulationSummary.to_dict` as JSON. Every number
carries its unit (in the key's name, or a companion list such as ``torque_units``).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from robodyn.common.text import printable
from robodyn.dynamics.dofs import BASE_V_NAMES
from robodyn.sim.limits import LimitViolation, warning_text


@dataclass(frozen=True)
class TaskOutcome:
    """Where a task-space run left its frame.

    Attributes:
        frame: The controlled frame.
        target: The target position in [m], shape (3,).
        final_position: The frame's final position in [m], shape (3,).
        final_error: Distance between the two in [m].
        reached: Whether ``final_error`` is below :data:`robodyn.sim.experiment.REACHED`.
    """

    frame: str
    target: tuple[float, ...]
    final_position: tuple[float, ...]
    final_error: float
    reached: bool

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready, units in the keys."""
        return {
            "frame": self.frame,
            "target_m": list(self.target),
            "final_position_m": list(self.final_position),
            "final_error_m": self.final_error,
            "target_reached": self.reached,
        }


@dataclass(frozen=True)
class SimulationSummary:
    """A simulation run under a named controller, summarised (SI units).

    Attributes:
        robot: The robot's name.
        controller, integrator, limits, engine: The run's settings.
        duration: Simulated time in [s]; ``dt``: the step in [s]; ``steps``: how many.
        real_time_factor: Simulated over wall-clock time (``None`` if too fast to time).
        joint_names: The robot's joints; ``dof_names``: one name a velocity coordinate
            (``robot.dofs``: ``base.x`` … ``base.rz`` for a floating base).
        final_q: The last configuration, shape (nq,).
        peak_abs_torque: Largest |tau| of each coordinate, in ``torque_units`` (N m or N).
        energy_change: Total energy at the end minus at the start, in [J].
        task: Where a task-space run left its frame (``None`` for other controllers).
        final_joint_error: Largest |q − target| at the end (pd, computed torque), rad or m.
        violations: Every limit the run broke (none with ``limits="ignore"``).
        files: Files written for the run, by kind (``trajectory``, ``plot``, ``recording``,
            ``poster``), in the order written.
    """

    robot: str
    controller: str
    integrator: str
    limits: str
    engine: str
    duration: float
    dt: float
    steps: int
    real_time_factor: float | None
    joint_names: tuple[str, ...]
    dof_names: tuple[str, ...]
    final_q: tuple[float, ...]
    peak_abs_torque: tuple[float, ...]
    torque_units: tuple[str, ...]
    energy_change: float
    task: TaskOutcome | None = None
    final_joint_error: float | None = None
    violations: tuple[LimitViolation, ...] = ()
    files: tuple[tuple[str, str], ...] = field(default=())

    def with_file(self, kind: str, path: str) -> SimulationSummary:
        """The same summary also naming a file written for the run."""
        return replace(self, files=(*self.files, (kind, str(path))))

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (the ``robodyn simulate --json`` output), units in the keys."""
        data: dict[str, Any] = {
            "robot": self.robot,
            "controller": self.controller,
            "integrator": self.integrator,
            "limits": self.limits,
            "engine": self.engine,
            "duration_s": self.duration,
            "dt_s": self.dt,
            "steps": self.steps,
            "real_time_factor": self.real_time_factor,
            "joint_names": list(self.joint_names),
            "dof_names": list(self.dof_names),
            "final_q": list(self.final_q),
            "peak_abs_torque": list(self.peak_abs_torque),
            "torque_units": list(self.torque_units),
            "energy_change_J": self.energy_change,
        }
        if self.task is not None:
            data |= self.task.to_dict()
        if self.final_joint_error is not None:
            data["final_joint_error"] = self.final_joint_error
        data["limit_violations"] = [violation.as_dict() for violation in self.violations]
        return data | dict(self.files)

    def __getitem__(self, key: str) -> Any:
        """A key of :meth:`to_dict` (for code that reads the summary as the JSON dict)."""
        return self.to_dict()[key]

    def __contains__(self, key: object) -> bool:
        return key in self.to_dict()

    def warnings(self) -> list[str]:
        """Lines worth a warning: the limits broken (one line for all)."""
        return [warning_text(self.robot, list(self.violations))] if self.violations else []

    def text(self) -> str:
        """Readable text: six significant digits and units; one line a limit violation."""
        names = [printable(name) for name in self.dof_names]
        lines = [
            f"robot: {printable(self.robot)}",
            f"controller: {self.controller} (integrator {self.integrator}, limits {self.limits})",
            f"simulated: {_number(self.duration)} s in {self.steps} steps of {_number(self.dt)} s"
            + (f", {_number(self.real_time_factor, 3)}× real time" if self.real_time_factor else ""),
        ]
        if self.task is not None:
            lines += [
                f"frame: {printable(self.task.frame)}",
                f"target: {vector_text(self.task.target, 6)} m",
                f"final position: {vector_text(self.task.final_position, 6)} m",
                f"final error: {_number(self.task.final_error, 3)} m ({'reached' if self.task.reached else 'NOT reached'})",
            ]
        if self.final_joint_error is not None:
            lines.append(f"final joint error: {_number(self.final_joint_error, 3)} (largest |q - target|, rad or m)")
        floating = tuple(self.dof_names[: len(BASE_V_NAMES)]) == BASE_V_NAMES
        q_units = "base position in m, quaternion x y z w, then joints in rad / m" if floating else "rad / m"
        lines.append(f"final q: {vector_text(self.final_q, 6)} ({q_units})")
        peaks = [
            f"{name} {_number(peak, 4)} {unit}"
            for name, peak, unit in zip(names, self.peak_abs_torque, self.torque_units, strict=False)
        ]
        lines.append(f"peak |torque|: {', '.join(peaks)}")
        lines.append(f"energy change: {_number(self.energy_change, 4)} J")
        if self.limits == "ignore":
            lines.append('limits: not checked (mode "ignore")')
        elif not self.violations:
            lines.append("limits: every position, velocity and effort limit kept")
        lines += [f"limit violation: {violation.text()}" for violation in self.violations]
        lines += [f"{kind}: {path}" for kind, path in self.files]
        return "\n".join(lines)


def vector_text(values: Any, precision: int) -> str:
    """``[v0, v1, ...]`` with ``precision`` significant digits."""
    return "[" + ", ".join(f"{value:.{precision}g}" for value in np.asarray(values, dtype=float)) + "]"


def _number(value: object, digits: int = 6) -> str:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return str(value)
    return "unlimited" if not np.isfinite(value) else f"{value:.{digits}g}"
