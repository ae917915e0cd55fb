"""What a run pressing a surface gives its summary, CSV, plot and recording.

:class:`SurfaceRun` holds the commanded and the measured normal force of a frame on a
surface (:func:`robodyn.sim.hybrid_run.run_hybrid`): it writes them as CSV columns beside
the trajectory's (``f[<contact>].x/.y/.z`` measured, ``f_cmd[<contact>].x/.y/.z``
commanded, both the force on the robot in world axes in [N]: :mod:`robodyn.trajectory.columns`),
gives the recording its force arrow and the figure its force panel (:class:`~robodyn.sim.drawings.PlotPanel`).
:class:`ForceOutcome` is the summary's part: commanded vs measured, final and peak error.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from robodyn.common.text import printable
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError
from robodyn.sim.drawings import PlotPanel
from robodyn.sim.limits import limit_violations
from robodyn.sim.plan import ExternalWrench
from robodyn.sim.report import SimulationSummary, vector_text
from robodyn.trajectory import Trajectory
from robodyn.trajectory.columns import commanded_header, contact_header
from robodyn.trajectory.io import write_csv

#: A final motion error along the surface at or above this is warned about, in [m].
MISSED = 1e-3

#: Options of the other controllers and their values that mean "not set".
_UNSET: dict[str, tuple[Any, ...]] = {
    "controller": ("hybrid",),
    "integrator": (None, "rk4"),
    "engine": ("auto", "pinocchio"),
    "control_period": (None,),
    "stiffness": (None,),
    "damping": (None,),
    "force_at": ((), []),
    "observer_gain": (None,),
    "actuated": (None,),
    "reference": (None,),
    "ground": (None,),
    "contacts": ("collision",),
}


def refuse_options(others: dict[str, Any], limits: str) -> None:
    """Refuse what a hybrid run does not take, naming the parameter.

    Args:
        others: The other controllers' options, by name.
        limits: ``"warn"`` or ``"ignore"`` (``"enforce"`` cannot stop a constrained joint).

    Raises:
        InputError: For an option set, or an unknown one.
    """
    for name, value in others.items():
        if name not in _UNSET:
            raise InputError(name, "no such option of the hybrid controller", repr(value)[:80])
        if not any(value is unset or (value == unset and type(value) is type(unset)) for unset in _UNSET[name]):
            allowed = " or ".join(repr(unset) for unset in _UNSET[name] if unset not in ((), []))
            raise InputError(
                name, f"{allowed or 'not given'} for the hybrid controller (its constrained plant)", repr(value)[:80]
            )
    if limits not in ("warn", "ignore"):
        raise InputError("limits", "'warn' or 'ignore' for the hybrid controller (its constrained plant)", repr(limits))


@dataclass(frozen=True)
class SurfaceRun:
    """A frame pressing a surface: the commanded and the measured normal force at every sample.

    Attributes:
        trajectory: The motion.
        name: The contact's name (``surface``) in the CSV columns.
        frame: The frame whose origin touches the surface.
        normal: The surface's normal, world axes (3,).
        measured: The normal force the surface exerts (the constraint's ``λ``), (N,) [N].
        commanded: The normal force commanded, (N,) [N].
    """

    trajectory: Trajectory
    name: str
    frame: str
    normal: np.ndarray
    measured: np.ndarray
    commanded: np.ndarray

    def force_arrows(self) -> tuple[ExternalWrench, ...]:
        """The measured force on the robot (``λ n``) as an arrow at the frame's origin."""
        t, forces = self.trajectory.t, np.outer(self.measured, self.normal)

        def held(time_s: float) -> np.ndarray:
            return forces[int(np.clip(np.searchsorted(t, time_s, side="right") - 1, 0, len(t) - 1))]

        return (ExternalWrench(self.frame, held),)

    def panels(self) -> tuple[PlotPanel, ...]:
        """The figure's force panel: commanded vs measured normal force in [N]."""
        t = self.trajectory.t
        return (
            PlotPanel(
                "normal force [N]",
                (("commanded force", t, self.commanded, "dashed"), ("measured force", t, self.measured, "solid")),
            ),
        )

    def save(self, path: str | Path, extras: dict[str, np.ndarray] | None = None) -> Path:
        """Write the trajectory's columns, then ``f[<name>].x/.y/.z`` (measured),
        ``f_cmd[<name>].x/.y/.z`` (commanded) in [N] and ``contact[<name>]`` (1: pushing).

        Args:
            path: The ``.csv`` file.
            extras: Must be empty (a hybrid run has no observer and no pushes).

        Raises:
            InputError: Naming ``out`` for a file name that does not end in ``.csv``, or extras.
        """
        path = Path(path)
        if path.suffix != ".csv" or extras:
            raise InputError("out", "a .csv file for a hybrid run (its contact forces are columns)", repr(str(path)))
        measured, commanded = np.outer(self.measured, self.normal), np.outer(self.commanded, self.normal)
        header = self.trajectory.header() + contact_header([self.name])[:3] + commanded_header([self.name])
        header += contact_header([self.name])[3:]
        table = np.column_stack([self.trajectory.table(), measured, commanded, (self.measured > 0).astype(float)])
        write_csv(path, self.trajectory.robot, header, table)
        return path


@dataclass(frozen=True)
class ForceOutcome:
    """Commanded vs measured normal force of a run on a surface, and its motion along it.

    Attributes:
        commanded: The final commanded normal force in [N].
        measured: The final measured normal force in [N].
        final_error: ``|measured − commanded|`` at the end, in [N].
        peak_error: Its largest value over the run, in [N]; ``peak_time`` when, in [s].
        smallest: The smallest measured normal force in [N] (< 0: the surface pulled).
        motion_error: The final ``|Ω e|`` along the surface in [m]; ``motion_peak`` its largest.
        start_moved: How far the start was projected onto the surface, ``max |δq|``.
        surface: What touches what: the frame and the surface's normal, one line.
        notes: What the run does not model, one line each.
    """

    commanded: float
    measured: float
    final_error: float
    peak_error: float
    peak_time: float
    smallest: float
    motion_error: float
    motion_peak: float
    start_moved: float
    surface: str = ""
    notes: tuple[str, ...] = field(default=())

    @classmethod
    def of(cls, run: SurfaceRun, errors: np.ndarray, moved: float, notes: tuple[str, ...]) -> ForceOutcome:
        """The outcome of ``run`` whose motion errors along the surface are ``errors`` (N, 3) [m]."""
        difference = np.abs(run.measured - run.commanded)
        peak, along = int(np.argmax(difference)), np.linalg.norm(errors, axis=1)
        return cls(
            float(run.commanded[-1]), float(run.measured[-1]), float(difference[-1]), float(difference[peak]),
            float(run.trajectory.t[peak]), float(run.measured.min()), float(along[-1]), float(along.max()), moved,
            f"surface: the origin of {run.frame} slides on it without friction, normal {vector_text(run.normal, 6)}", notes,
        )  # fmt: skip

    def lines(self) -> list[str]:
        """The summary's lines."""
        lines = [
            self.surface,
            f"contact force (normal, on the robot): commanded {self.commanded:.6g} N, measured {self.measured:.6g} N at the end",
            f"contact force error: final {self.final_error:.3g} N ({self.final_error / max(self.commanded, 1e-300):.3g} "
            f"relative), peak {self.peak_error:.3g} N at t = {self.peak_time:.6g} s",
            f"motion along the surface: final error {self.motion_error:.3g} m, peak {self.motion_peak:.3g} m",
            f"start: moved by {self.start_moved:.3g} (max |dq|, rad / m) to put the frame on the surface",
        ]
        if self.smallest < 0:
            lines.append(f"the surface pulled (smallest normal force {self.smallest:.3g} N): a real contact would have separated")
        return [printable(line) for line in (*lines, *self.notes)]

    def warnings(self, robot: str) -> list[str]:
        """Lines worth a warning: the motion missed its path by :data:`MISSED` or more, or the
        surface pulled.

        Args:
            robot: The robot's name.
        """
        lines = []
        if self.motion_error >= MISSED:
            lines.append(
                f"{robot}: the motion along the surface missed its path by {self.motion_error:.3g} m at the end "
                "(out of reach, or a longer duration?)"
            )
        if self.smallest < 0:
            lines.append(f"{robot}: the surface pulled the frame ({self.smallest:.3g} N): a real contact would have separated")
        return [printable(line) for line in lines]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready, units in the keys."""
        return {
            "force_commanded_N": self.commanded,
            "force_measured_N": self.measured,
            "force_final_error_N": self.final_error,
            "force_peak_error_N": self.peak_error,
            "force_smallest_N": self.smallest,
            "motion_final_error_m": self.motion_error,
            "motion_peak_error_m": self.motion_peak,
            "start_moved": self.start_moved,
            "surface": self.surface,
            "surface_notes": list(self.notes),
        }


def timed(call: Callable[[], Any]) -> tuple[Any, float]:
    """``call()`` and its wall-clock time in [s].

    Args:
        call: What to time.
    """
    started = time.perf_counter()
    return call(), time.perf_counter() - started


def summary_of(
    robot: Robot, trajectory: Trajectory, outcome: ForceOutcome, run: SurfaceRun, *, limits: str, loop_time: float, dt: float
) -> SimulationSummary:
    """The :class:`SimulationSummary` of a hybrid run (its ``forces`` and ``contact``).

    Args:
        robot: The plant.
        trajectory: The motion.
        outcome: Commanded vs measured force.
        run: The forces at every sample.
        limits: ``"warn"`` or ``"ignore"``.
        loop_time: Wall-clock time of the simulation in [s].
        dt: The step in [s].
    """
    assert trajectory.tau is not None  # the constrained simulation records the torques
    energy = np.atleast_1d(robot.kinetic_energy(trajectory.q, trajectory.v)) + np.atleast_1d(robot.potential_energy(trajectory.q))
    duration = float(trajectory.t[-1] - trajectory.t[0])
    return SimulationSummary(
        robot=robot.name, controller="hybrid", integrator="rk4", limits=limits, engine="pinocchio", duration=duration,
        dt=dt, steps=len(trajectory) - 1, real_time_factor=duration / loop_time if loop_time > 0 else None,
        joint_names=tuple(robot.joint_names), dof_names=tuple(dof.name for dof in robot.dofs),
        final_q=tuple(trajectory.q[-1].tolist()), peak_abs_torque=tuple(np.abs(trajectory.tau).max(axis=0).tolist()),
        torque_units=tuple(dof.effort_unit for dof in robot.dofs), energy_change=float(energy[-1] - energy[0]),
        violations=() if limits == "ignore" else tuple(limit_violations(robot, trajectory)),
        engine_reason="the surface is a constraint: RK4 and projection in Python over Pinocchio",
        loop_time=loop_time, contact=run, forces=outcome,
    )  # fmt: skip


__all__ = ["ForceOutcome", "SurfaceRun", "refuse_options", "summary_of", "timed"]
