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
from robodyn.sim.number_text import number_text, seconds_text
from robodyn.sim.number_text import vector_text as vector_text  # robodyn.sim.surface_run imports it here


@dataclass(frozen=True)
class Push:
    """A push during a run: a constant force at a frame's origin from a time on.

    Attributes:
        time: When it starts, in [s].
        force: The force in [N], world axes, shape (3,).
        frame: Where it acts; ``None`` for the controlled frame (the end effector).
    """

    time: float
    force: tuple[float, float, float]
    frame: str | None = None

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready, units in the keys."""
        return {"time_s": self.time, "force_N": list(self.force), "frame": self.frame}


@dataclass(frozen=True)
class TaskOutcome:
    """Where a task-space, operational-space or impedance run left its frame.

    Attributes:
        frame: The controlled frame.
        target: The target position in [m], shape (3,).
        final_position: The frame's final position in [m], shape (3,).
        final_error: Distance between the two in [m].
        reached: Whether ``final_error`` (and ``orientation_error``) are below
            :data:`robodyn.sim.experiment.REACHED` (in [m], and [rad]).
        target_rpy: The target attitude as roll, pitch, yaw in [rad] (``None``: position only).
        orientation_error: The final attitude error ``|log(Rᵀ R_d)|`` in [rad].
        deflection: Impedance under a push: the frame's final displacement from its rest
            position in [m], shape (3,); ``expected_deflection``: ``K⁻¹ F`` in [m];
            ``deflection_error``: ``|δ − K⁻¹ F| / |K⁻¹ F|``.
    """

    frame: str
    target: tuple[float, ...]
    final_position: tuple[float, ...]
    final_error: float
    reached: bool
    target_rpy: tuple[float, ...] | None = None
    orientation_error: float | None = None
    deflection: tuple[float, ...] | None = None
    expected_deflection: tuple[float, ...] | None = None
    deflection_error: float | None = None

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready, units in the keys."""
        data: dict[str, Any] = {
            "frame": self.frame,
            "target_m": list(self.target),
            "final_position_m": list(self.final_position),
            "final_error_m": self.final_error,
            "target_reached": self.reached,
        }
        if self.target_rpy is not None:
            data |= {"target_rpy_rad": list(self.target_rpy), "final_orientation_error_rad": self.orientation_error}
        if self.deflection is not None and self.expected_deflection is not None:
            data |= {
                "deflection_m": list(self.deflection),
                "expected_deflection_m": list(self.expected_deflection),
                "deflection_error": self.deflection_error,
            }
        return data

    def _state(self) -> str:
        if self.reached:
            return "reached"
        return "NOT reached" if self.deflection is None else "held off by the push"

    def lines(self) -> list[str]:
        """The outcome as lines of text."""
        lines = [f"frame: {printable(self.frame)}", f"target: {vector_text(self.target, 6)} m"]
        if self.target_rpy is not None:
            lines.append(f"target roll, pitch, yaw: {vector_text(self.target_rpy, 6)} rad")
        lines += [
            f"final position: {vector_text(self.final_position, 6)} m",
            f"final error: {number_text(self.final_error, 3)} m ({self._state()})",
        ]
        if self.orientation_error is not None:
            lines.append(f"final orientation error: {number_text(self.orientation_error, 3)} rad")
        if self.deflection is not None and self.expected_deflection is not None:
            lines += [
                f"deflection: {vector_text(self.deflection, 6)} m",
                f"K^-1 F: {vector_text(self.expected_deflection, 6)} m "
                f"(deflection off by {number_text(100 * (self.deflection_error or 0.0), 3)} %)",
            ]
        return lines


@dataclass(frozen=True)
class ObserverOutcome:
    """What the momentum observer run along a simulation estimated.

    Attributes:
        gain: ``K_O`` in [1/s].
        final_estimate: The residual at the end, per velocity coordinate, in [N m] / [N].
        final_applied: The external torques applied at the end (``J(q)ᵀ F`` of the pushes).
        final_error: Largest ``|r − τ_env|`` at the end, in [N m] / [N].
        residual: The estimate at every sample, shape (N, nv) (written as ``tau_ext``).
        applied: The applied external torques at every sample, shape (N, nv) (``tau_env``).
    """

    gain: float
    final_estimate: tuple[float, ...]
    final_applied: tuple[float, ...]
    final_error: float
    residual: np.ndarray = field(repr=False, compare=False)
    applied: np.ndarray = field(repr=False, compare=False)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready, units in the keys (torques in ``torque_units``)."""
        return {
            "observer_gain_per_s": self.gain,
            "final_tau_ext_estimate": list(self.final_estimate),
            "final_tau_ext_applied": list(self.final_applied),
            "final_tau_ext_error": self.final_error,
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
        peak_abs_torque: Largest ``|tau|`` of each coordinate, in ``torque_units`` (N m or N).
        energy_change: Total energy at the end minus at the start, in [J].
        task: Where a task-space run left its frame (``None`` for other controllers).
        final_joint_error: Largest ``|q − target|`` at the end (pd, computed torque), rad or m.
        pushes: The pushes applied during the run.
        observer: What a momentum observer run along estimated (``None`` without one).
        violations: Every limit the run broke (none with ``limits="ignore"``).
        files: Files written for the run, by kind (``trajectory``, ``plot``, ``recording``,
            ``poster``), in the order written.
        engine_reason: Why ``engine`` ran (``engine="auto"``: why it was chosen).
        control_period: The period in [s] at which the controller was sampled and its
            torque held (zero-order hold); ``None``: evaluated at every integrator stage.
        controller_in_c: Whether the controller ran in C.
        loop_time: Wall-clock time of the integration loop alone in [s]
            (``real_time_factor`` is ``duration / loop_time``).
        compile_time: Wall-clock time choosing the engine and compiling, or loading the
            cached, kernels in [s] (importing the code generator included).
        startup_time: Wall-clock time from the process's start to the run in [s]
            (interpreter, imports, loading the robot; ``robodyn simulate`` fills it in).
        ground: The contact summary of a run on the ground (peak normal force, slip,
            penetration, what is not modelled), or for a floating robot with neither a ground
            nor constraints holding it ``"no ground: the base falls freely"``.
        contact: A run on the ground: its :class:`~robodyn.sim.contact_run.ContactSimulation`
            (forces, gaps; not in :meth:`to_dict`), else ``None``.
        constrained: A run with constraints: its
            :class:`~robodyn.sim.constrained.ConstrainedSimulation` (the residual, each
            constraint's peak force; its multipliers for the files), else ``None``.
        com_error: stand: the final centre of mass's distance to its target in [m].
        force_difference: stand: the largest ``|f_QP − f_simulated|`` of a contact over the run, in [N].
        support_margin: stand: how far the final centre of mass lies inside the support polygon, in [m].
        forces: hybrid: commanded vs measured contact force (:class:`robodyn.sim.surface_run.ForceOutcome`).
        panels, drawings: Extra figure panels and recording drawings of the run (not in :meth:`to_dict`).
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
    pushes: tuple[Push, ...] = ()
    observer: ObserverOutcome | None = None
    violations: tuple[LimitViolation, ...] = ()
    files: tuple[tuple[str, str], ...] = field(default=())
    engine_reason: str = ""
    control_period: float | None = None
    controller_in_c: bool = False
    loop_time: float | None = None
    compile_time: float = 0.0
    startup_time: float | None = None
    ground: tuple[str, ...] = ()
    contact: Any = field(default=None, repr=False, compare=False)  # the ContactSimulation, for the files
    constrained: Any = field(default=None, repr=False, compare=False)  # the ConstrainedSimulation
    com_error: float | None = None
    force_difference: float | None = None
    support_margin: float | None = None
    forces: Any = None
    panels: tuple = field(default=(), repr=False, compare=False)
    drawings: tuple = field(default=(), repr=False, compare=False)

    def with_startup(self, seconds: float | None) -> SimulationSummary:
        """The same summary with the start-up time in [s] (process start to the run).

        Args:
            seconds: The start-up time in [s] (``None``: not measured).
        """
        return replace(self, startup_time=seconds)

    def with_file(self, kind: str, path: str) -> SimulationSummary:
        """The same summary also naming a file written for the run.

        Args:
            kind: What the file holds (e.g. ``"trajectory"``).
            path: The file's path.
        """
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
        data |= self._timing_dict()
        if self.task is not None:
            data |= self.task.to_dict()
        if self.final_joint_error is not None:
            data["final_joint_error"] = self.final_joint_error
        if self.pushes:
            data["pushes"] = [push.to_dict() for push in self.pushes]
        if self.observer is not None:
            data |= self.observer.to_dict()
        data["limit_violations"] = [violation.as_dict() for violation in self.violations]
        if self.ground:
            data["ground"] = list(self.ground)
        if self.constrained is not None:
            data |= self.constrained.to_dict()
        for key, unit in (("com_error", "m"), ("force_difference", "N"), ("support_margin", "m")):
            if getattr(self, key) is not None:
                data[f"{key}_{unit}"] = getattr(self, key)
        return data | (self.forces.to_dict() if self.forces is not None else {}) | dict(self.files)

    def _timing_dict(self) -> dict[str, Any]:
        """The engine's reason, the controller's sampling and the times, units in the keys."""
        return {
            "engine_reason": self.engine_reason,
            "controller_sampling": self._sampling(),
            "control_period_s": self.control_period,
            "controller_in_c": self.controller_in_c,
            "loop_time_s": self.loop_time,
            "compile_time_s": self.compile_time,
            "startup_time_s": self.startup_time,
        }

    def _sampling(self) -> str:
        if self.controller == "passive":
            return "none (passive)"
        if self.control_period is None:
            return "every integrator stage"
        return f"sampled every {number_text(self.control_period)} s and held (zero-order hold)"

    def _timing_lines(self) -> list[str]:
        """Which engine ran and why, how the controller was sampled, where the time went."""
        where = " in C" if self.controller_in_c else (" in Python" if self.controller != "passive" else "")
        lines = [f"engine: {self.engine}" + (f" ({self.engine_reason})" if self.engine_reason else "")]
        if self.controller != "passive":
            lines.append(f"controller evaluated: {self._sampling()}{where}")
        times = [] if self.loop_time is None else [f"loop {seconds_text(self.loop_time)}"]
        if self.compile_time and self.engine == "compiled":
            times.append(f"engine choice and compile {seconds_text(self.compile_time)} (imports included; kernels cached)")
        elif self.compile_time:
            times.append(f"engine choice {seconds_text(self.compile_time)}")
        if self.startup_time is not None:
            times.append(f"start-up {seconds_text(self.startup_time)} (interpreter, imports, loading)")
        return lines + ([f"wall-clock time: {', '.join(times)}"] if times else [])

    def __getitem__(self, key: str) -> Any:
        """A key of :meth:`to_dict` (for code that reads the summary as the JSON dict)."""
        return self.to_dict()[key]

    def __contains__(self, key: object) -> bool:
        return key in self.to_dict()

    def warnings(self) -> list[str]:
        """Lines worth a warning: the limits broken (one line for all); a hybrid run's misses."""
        limits = [warning_text(self.robot, list(self.violations))] if self.violations else []
        return limits + (self.forces.warnings(self.robot) if self.forces is not None else [])

    def text(self) -> str:
        """Readable text: six significant digits and units; one line a limit violation."""
        names = [printable(name) for name in self.dof_names]
        lines = [
            f"robot: {printable(self.robot)}",
            f"controller: {self.controller} (integrator {self.integrator}, limits {self.limits})",
            f"simulated: {number_text(self.duration)} s in {self.steps} steps of {number_text(self.dt)} s"
            + (f", {number_text(self.real_time_factor, 3)}× real time (loop only)" if self.real_time_factor else ""),
        ]
        lines += self._timing_lines()
        lines += [
            f"push: {vector_text(push.force, 6)} N at {printable(push.frame or '(the end effector)')} from {number_text(push.time)} s"
            for push in self.pushes
        ]
        if self.task is not None:
            lines += self.task.lines()
        if self.final_joint_error is not None:
            lines.append(f"final joint error: {number_text(self.final_joint_error, 3)} (largest |q - target|, rad or m)")
        floating = tuple(self.dof_names[: len(BASE_V_NAMES)]) == BASE_V_NAMES
        q_units = "base position in m, quaternion x y z w, then joints in rad / m" if floating else "rad / m"
        lines.append(f"final q: {vector_text(self.final_q, 6)} ({q_units})")
        peaks = [
            f"{name} {number_text(peak, 4)} {unit}"
            for name, peak, unit in zip(names, self.peak_abs_torque, self.torque_units, strict=False)
        ]
        lines.append(f"peak |torque|: {', '.join(peaks)}")
        lines.append(f"energy change: {number_text(self.energy_change, 4)} J")
        lines += [printable(line) for line in self.ground]
        lines += [printable(line) for line in (self.constrained.summary_lines() if self.constrained is not None else ())]
        lines += self.forces.lines() if self.forces is not None else []
        if self.com_error is not None:
            lines.append(f"centre of mass: final error {number_text(self.com_error, 3)} m")
        if self.force_difference is not None:
            lines.append(f"contact forces: commanded vs measured, largest difference {number_text(self.force_difference, 3)} N")
        if self.support_margin is not None:
            lines.append(f"support margin: {number_text(self.support_margin, 4)} m (centre of mass inside the feet's polygon)")
        if self.observer is not None:
            lines += [
                f"observer (gain {number_text(self.observer.gain)} /s): final tau_ext {vector_text(self.observer.final_estimate, 4)}",
                f"  applied {vector_text(self.observer.final_applied, 4)} (largest difference "
                f"{number_text(self.observer.final_error, 3)} N m / N)",
            ]
        if self.limits == "ignore":
            lines.append('limits: not checked (mode "ignore")')
        elif not self.violations:
            lines.append("limits: every position, velocity and effort limit kept")
        lines += [f"limit violation: {violation.text()}" for violation in self.violations]
        lines += [f"{kind}: {path}" for kind, path in self.files]
        return "\n".join(lines)


def seconds_since_process_start() -> float | None:
    """Wall-clock time since this process started in [s] (Linux ``/proc``; ``None`` elsewhere)."""
    import os

    try:
        with open("/proc/self/stat", encoding="ascii") as stat:
            fields = stat.read().rsplit(")", 1)[1].split()
        with open("/proc/uptime", encoding="ascii") as uptime:
            now = float(uptime.read().split()[0])
        return max(0.0, now - int(fields[19]) / os.sysconf("SC_CLK_TCK"))
    except (OSError, ValueError, IndexError):
        return None
