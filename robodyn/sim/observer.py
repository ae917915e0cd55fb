"""External forces from data: the generalized-momentum observer (De Luca & Mattone).

With the momentum ``p = M(q) v``, the equations of motion and ``Ṁ = C + Cᵀ`` give
``ṗ = τ + Cᵀ v − G + τ_ext`` — no acceleration. The residual::

    r(t) = K_O (p(t) − p(0) − ∫₀ᵗ (τ + Cᵀ v − G + r) ds)

obeys ``ṙ = K_O (τ_ext − r)``: it follows the external torques through a first-order lag
of gain ``K_O`` [1/s] per joint (63 % of a step in ``1/K_O``). Both the offline estimate
(:func:`estimate_external_torques`, on a recorded trajectory) and the online
:class:`MomentumObserver` (one sample at a time, in a control loop) integrate
``Cᵀ v − G`` and ``r`` by the trapezoidal rule (the implicit ``r`` solved exactly per
step) and the motor torque as it was applied (:data:`TorqueMode`): ``"held"``, each
sample's torque acting unchanged until the next sample (a digital controller, MuJoCo,
``simulate(..., hold=True)``), or ``"sampled"``, samples of a torque that varies
continuously (``simulate`` without ``hold``). The wrong one leaves an error of about
``Δτ / 2`` per step in the estimate of a fast-changing torque.

From the residual: the wrench at a frame (:func:`external_wrench`, ``F = (Jᵀ)⁺ r``) and
collision detection (:func:`detect_collision`: when the first ``|r_i|`` crosses its
threshold, and the last joint whose residual is significant — a force on a link moves
only the joints before it, so that joint's child link is the one that was hit).
:func:`observe_file` does all of it for a trajectory file (``robodyn observe``) and returns
an :class:`ObservationRun`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Literal

import numpy as np

from robodyn.common.files import atomic_write_text
from robodyn.common.text import counted, printable
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError
from robodyn.trajectory import Trajectory
from robodyn.trajectory.io import csv_preamble, format_rows, read_extra

#: How the recorded motor torque acted between two samples.
TorqueMode = Literal["held", "sampled"]
TORQUE_MODES = ("held", "sampled")


def _gain(robot: Robot, gain: float | np.ndarray) -> np.ndarray:
    """``K_O`` as (nv,) positive finite values in [1/s]."""
    gains = np.broadcast_to(np.asarray(gain, dtype=float), (robot.nv,)) if np.ndim(gain) == 0 else np.asarray(gain, float)
    if gains.shape != (robot.nv,) or not (np.isfinite(gains).all() and (gains > 0).all()):
        raise InputError(
            "gain", f"a positive scalar or {robot.nv} positive values in [1/s]", counted(np.asarray(gain).size, "value")
        )
    return np.array(gains)


def _momentum_terms(robot: Robot, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``p = M v`` and ``β = Cᵀ v − G`` for one state (1-D) or stacked states (2-D)."""
    mass, coriolis, gravity = robot.mass_matrix(q), robot.coriolis_matrix(q, v), robot.gravity(q)
    momentum = np.einsum("...ij,...j->...i", mass, v)
    beta = np.einsum("...ji,...j->...i", coriolis, v) - gravity
    return momentum, beta


def _torque_step(dt: float | np.ndarray, before: np.ndarray, after: np.ndarray, torque: TorqueMode) -> np.ndarray:
    """``∫ τ`` over a step from the torques at its two ends."""
    return dt * before if torque == "held" else 0.5 * dt * (before + after)


def _check_mode(torque: str) -> None:
    if torque not in TORQUE_MODES:
        raise InputError("torque", f"one of {', '.join(TORQUE_MODES)}", repr(torque))


def _step(gain: np.ndarray, dt: float, offset: np.ndarray, integral: np.ndarray, r_previous: np.ndarray) -> np.ndarray:
    """The residual after a step: ``r = K (s − R_prev − dt/2 (r_prev + r))`` solved for ``r``,
    with ``s = p − p(0) − ∫β`` (``offset``) and ``R_prev = ∫r`` up to the previous sample."""
    return gain * (offset - integral - 0.5 * dt * r_previous) / (1.0 + 0.5 * dt * gain)


def estimate_external_torques(
    robot: Robot, trajectory: Trajectory, *, gain: float | np.ndarray, torque: TorqueMode = "held"
) -> np.ndarray:
    """The external joint torques a recorded motion reveals (momentum observer).

    Args:
        robot: The model of the robot (its ``M``, ``C``, ``G``).
        trajectory: Samples ``t`` (N,), ``q`` (N, nq), ``v`` (N, nv) and the applied
            torques ``tau`` (N, nv) (e.g. a :class:`~robodyn.Trajectory` from
            :func:`robodyn.simulate` or from a file).
        gain: ``K_O`` in [1/s], scalar or (nv,): the bandwidth of the estimate.
        torque: ``"held"`` (each sample's ``tau`` acts until the next sample) or
            ``"sampled"`` (``tau`` varies continuously between samples).

    Returns:
        The residual ``r``, shape (N, nv), in [N m] / [N]: ``r[0] = 0``, and after a few
        ``1/K_O`` the external torques (plus whatever the model gets wrong).

    Raises:
        InputError: A trajectory without torques, of fewer than two samples or with
            times that do not increase; a bad gain or torque mode.
        TrajectoryError: A trajectory of another robot.
    """
    if trajectory.tau is None:
        raise InputError("trajectory", "one with the applied torques tau", "no tau")
    trajectory.check(robot)
    gains = _gain(robot, gain)
    _check_mode(torque)
    t = np.asarray(trajectory.t, float)
    if t.ndim != 1 or len(t) < 2 or not (np.diff(t) > 0).all():
        raise InputError("trajectory.t", "at least two strictly increasing times", f"{len(t)} times")
    momentum, beta = _momentum_terms(robot, trajectory.q, trajectory.v)
    tau = np.asarray(trajectory.tau, float)
    steps = np.diff(t)[:, None]
    increments = 0.5 * steps * (beta[1:] + beta[:-1]) + _torque_step(steps, tau[:-1], tau[1:], torque)
    integral_beta = np.concatenate([np.zeros((1, robot.nv)), np.cumsum(increments, axis=0)])
    offset = momentum - momentum[0] - integral_beta
    residual = np.zeros_like(offset)
    integral = np.zeros(robot.nv)
    for k in range(1, len(t)):
        dt = float(t[k] - t[k - 1])
        residual[k] = _step(gains, dt, offset[k], integral, residual[k - 1])
        integral += 0.5 * dt * (residual[k - 1] + residual[k])
    return residual


@dataclass
class MomentumObserver:
    """The momentum observer run online, one sample at a time.

    Call :meth:`update` with each new sample (time, state, applied torque); it returns the
    current estimate of the external torques. Fed the samples of a trajectory it gives
    :func:`estimate_external_torques`'s rows. In :func:`robodyn.simulate`, wrap the
    controller with :meth:`wrap` and simulate with ``hold=True`` (the controller is then
    called once per step, at the state actually reached).

    Attributes:
        model: The observer's model of the robot.
        gain: ``K_O`` in [1/s], scalar or (nv,).
        torque: ``"held"`` (the torque given with a sample acts until the next one) or
            ``"sampled"``, as for :func:`estimate_external_torques`.
        times: Times of the samples seen, in [s].
        residuals: The estimate at each of them, each (nv,).
    """

    model: Robot
    gain: float | np.ndarray
    torque: TorqueMode = "held"
    times: list[float] = field(default_factory=list)
    residuals: list[np.ndarray] = field(default_factory=list)
    _gains: np.ndarray = field(init=False, repr=False)
    _start: np.ndarray | None = field(default=None, init=False, repr=False)
    _previous: tuple[float, np.ndarray, np.ndarray] | None = field(default=None, init=False, repr=False)
    _integral_beta: np.ndarray | None = field(default=None, init=False, repr=False)
    _integral: np.ndarray | None = field(default=None, init=False, repr=False)

    def __post_init__(self) -> None:
        self._gains = _gain(self.model, self.gain)
        _check_mode(self.torque)

    def update(self, t: float, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """Take one sample and return the estimate ``r`` (nv,) in [N m] / [N].

        Raises:
            InputError: A time not after the previous sample's (e.g. the intermediate
                calls of a Runge–Kutta step: simulate with ``hold=True``).
        """
        tau = np.asarray(tau, dtype=float)
        momentum, beta = _momentum_terms(self.model, q, v)
        if self._previous is None or self._start is None or self._integral_beta is None or self._integral is None:
            self._start, self._integral_beta, self._integral = momentum, np.zeros(self.model.nv), np.zeros(self.model.nv)
            residual = np.zeros(self.model.nv)
        else:
            last_t, last_beta, last_tau = self._previous
            if not t > last_t:
                raise InputError("t", f"after the previous sample's {last_t:.9g} s (simulate with hold=True)", f"{t:.9g} s")
            dt = t - last_t
            step = 0.5 * dt * (last_beta + beta) + _torque_step(dt, last_tau, tau, self.torque)
            self._integral_beta = self._integral_beta + step
            previous = self.residuals[-1]
            residual = _step(self._gains, dt, momentum - self._start - self._integral_beta, self._integral, previous)
            self._integral = self._integral + 0.5 * dt * (previous + residual)
        self._previous = (float(t), beta, tau)
        self.times.append(float(t))
        self.residuals.append(residual)
        return residual

    def wrap(self, controller: Callable[[float, np.ndarray, np.ndarray], np.ndarray]) -> Callable:
        """A controller that also feeds this observer each sample and the torque it applies."""

        def observed(t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
            tau = np.asarray(controller(t, q, v), dtype=float)
            self.update(t, q, v, tau)
            return tau

        return observed


def external_wrench(robot: Robot, q: np.ndarray, residual: np.ndarray, frame: str) -> np.ndarray:
    """The wrench at a frame's origin that explains external joint torques: ``(Jᵀ)⁺ r``.

    Exact when the torques come from a wrench at that frame and ``Jᵀ`` has full column
    rank (six joints or more before the frame, away from singularities); otherwise the
    least-squares wrench of least norm.

    Args:
        robot: The robot.
        q: Configuration(s), shape (nq,) or (N, nq).
        residual: External torques, shape (nv,) or (N, nv).
        frame: The frame whose wrench is wanted.

    Returns:
        Force in [N] then torque in [N m], world axes: shape (6,) or (N, 6).
    """
    jacobian = robot.frame_jacobian(q, robot.task_frame(frame, "an external wrench"))
    residual = np.asarray(residual, dtype=float)
    return np.einsum("...ij,...j->...i", np.linalg.pinv(np.swapaxes(jacobian, -1, -2), rcond=1e-10), residual)


@dataclass(frozen=True)
class Collision:
    """A detected contact.

    Attributes:
        time: First time a residual crossed its threshold, in [s].
        index: Index in ``v`` of the last joint whose residual was significant.
        dof: That degree of freedom's name (``robot.dofs``).
        peak: Largest ``|r_i|`` of each joint over the contact, shape (nv,).
    """

    time: float
    index: int
    dof: str
    peak: np.ndarray


def detect_collision(robot: Robot, t: np.ndarray, residual: np.ndarray, threshold: float | np.ndarray) -> Collision | None:
    """The first contact in an observer's residual, and which joint's link it hit.

    The contact starts when some ``|r_i|`` first exceeds its threshold and lasts while any
    does; the joint reported is the last one whose ``|r_i|`` exceeded its threshold during
    it (a wrench on a link produces torques at the joints before it only).

    Args:
        robot: The robot (for the joints' names).
        t: Times in [s], shape (N,).
        residual: The observer's estimate, shape (N, nv).
        threshold: In [N m] / [N], scalar or (nv,), positive.

    Returns:
        The contact, or ``None`` when no residual crosses its threshold.
    """
    residual = np.abs(np.asarray(residual, dtype=float))
    limits = np.broadcast_to(np.asarray(threshold, dtype=float), (robot.nv,))
    if not (np.isfinite(limits).all() and (limits > 0).all()):
        raise InputError("threshold", f"a positive scalar or {robot.nv} positive values in [N m] / [N]", repr(threshold))
    above = residual > limits
    hits = np.flatnonzero(above.any(axis=1))
    if hits.size == 0:
        return None
    start = int(hits[0])
    quiet = np.flatnonzero(~above[start:].any(axis=1))
    end = start + int(quiet[0]) if quiet.size else len(residual)
    peak = residual[start:end].max(axis=0)
    index = int(np.flatnonzero(peak > limits)[-1])
    return Collision(float(t[start]), index, robot.dofs[index].name, peak)


#: Column names of the wrench at a frame in ``robodyn observe``'s output: [N], then [N m].
WRENCH_COLUMNS = ("force[x]", "force[y]", "force[z]", "torque[x]", "torque[y]", "torque[z]")


@dataclass(frozen=True)
class ObservationRun:
    """The external torques a recorded motion reveals (``robodyn observe``), summarised.

    Attributes:
        robot: The robot's name; ``source``: the trajectory file read.
        gain: ``K_O`` in [1/s]; ``torque``: how the recorded torque acted (``held``/``sampled``).
        dof_names: One name a velocity coordinate (``robot.dofs``); ``units``: their torque units.
        t: Times in [s], shape (N,); ``residual``: the estimate, shape (N, nv).
        applied: The external torques the file says were applied (its ``tau_env``
            columns), shape (N, nv), or ``None``.
        frame: The frame of ``wrench`` (``None``: no wrench asked for); ``wrench``: force
            [N] and torque [N m] at its origin explaining the residual, shape (N, 6).
        threshold: The collision threshold in [N m] / [N] (``None``: no detection).
        collision: The first contact found (``None``: none or no threshold).
        out: The file written (``None``: none).
        plot: The figure written (set by the caller that draws it).
    """

    robot: str
    source: str
    gain: float
    torque: str
    dof_names: tuple[str, ...]
    units: tuple[str, ...]
    t: np.ndarray = field(repr=False, compare=False)
    residual: np.ndarray = field(repr=False, compare=False)
    applied: np.ndarray | None = field(default=None, repr=False, compare=False)
    frame: str | None = None
    wrench: np.ndarray | None = field(default=None, repr=False, compare=False)
    threshold: float | None = None
    collision: Collision | None = None
    out: str | None = None
    plot: str | None = None

    def table(self) -> tuple[list[str], np.ndarray]:
        """The output file's header (``t``, ``tau_ext[<dof>]``, the wrench's six) and rows."""
        header = ["t", *(f"tau_ext[{name}]" for name in self.dof_names)]
        parts = [self.t[:, None], self.residual]
        if self.wrench is not None:
            header += list(WRENCH_COLUMNS)
            parts.append(self.wrench)
        return header, np.hstack(parts)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready, units in the keys (torques in ``torque_units``)."""
        data: dict[str, Any] = {
            "robot": self.robot, "source": self.source, "gain_per_s": self.gain, "torque": self.torque,
            "samples": len(self.t), "duration_s": float(self.t[-1] - self.t[0]),
            "dof_names": list(self.dof_names), "torque_units": list(self.units),
            "peak_abs_tau_ext": np.abs(self.residual).max(axis=0).tolist(), "final_tau_ext": self.residual[-1].tolist(),
        }  # fmt: skip
        if self.applied is not None:
            data["final_tau_ext_error"] = float(np.abs(self.residual[-1] - self.applied[-1]).max())
        if self.frame is not None and self.wrench is not None:
            data |= {
                "frame": self.frame,
                "final_force_N": self.wrench[-1, :3].tolist(),
                "final_torque_Nm": self.wrench[-1, 3:].tolist(),
            }
        if self.threshold is not None:
            data["threshold"] = self.threshold
            data["collision"] = None if self.collision is None else {
                "time_s": self.collision.time, "dof": self.collision.dof, "index": self.collision.index,
                "peak_abs_tau_ext": self.collision.peak.tolist(),
            }  # fmt: skip
        return data | {"out": self.out, "plot": self.plot}

    def text(self) -> str:
        """Readable text: six significant digits, units."""

        def values(row: np.ndarray) -> str:
            return ", ".join(f"{printable(n)} {v:.4g} {u}" for n, v, u in zip(self.dof_names, row, self.units, strict=True))

        lines = [
            f"robot: {printable(self.robot)}",
            f"trajectory: {printable(self.source)} ({len(self.t)} samples, {float(self.t[-1] - self.t[0]):.6g} s)",
            f"observer: gain {self.gain:.6g} /s, torque {self.torque}",
            f"peak |tau_ext|: {values(np.abs(self.residual).max(axis=0))}",
            f"final tau_ext: {values(self.residual[-1])}",
        ]
        if self.applied is not None:
            lines.append(
                f"final |tau_ext - applied|: {float(np.abs(self.residual[-1] - self.applied[-1]).max()):.3g} N m / N (largest)"
            )
        if self.frame is not None and self.wrench is not None:
            force, moment = self.wrench[-1, :3], self.wrench[-1, 3:]
            lines.append(
                f"final wrench at {printable(self.frame)}: force {np.round(force, 6).tolist()} N, torque {np.round(moment, 6).tolist()} N m"
            )
        if self.threshold is not None:
            lines.append(
                f"collision: none above {self.threshold:.6g}" if self.collision is None
                else f"collision: at {self.collision.time:.6g} s, last significant joint {printable(self.collision.dof)} "
                f"(threshold {self.threshold:.6g})"
            )  # fmt: skip
        lines += [f"{kind}: {path}" for kind, path in (("out", self.out), ("plot", self.plot)) if path]
        return "\n".join(lines)


def observe_file(
    robot: Robot,
    path: str | Path,
    *,
    gain: float | np.ndarray,
    frame: str | None = None,
    threshold: float | None = None,
    torque: TorqueMode = "held",
    out: str | Path | None = None,
) -> ObservationRun:
    """Estimate the external torques of a recorded trajectory file, detect a contact, write CSV.

    Args:
        robot: The model (``M``, ``C``, ``G``) of the robot that moved.
        path: A trajectory file with ``tau`` columns (``.csv``, ``.npz``, ``.parquet``).
        gain: ``K_O`` in [1/s] (scalar or (nv,)).
        frame: Also the wrench at this frame's origin, ``(Jᵀ)⁺ r``.
        threshold: Collision threshold in [N m] / [N] (:func:`detect_collision`).
        torque: ``"held"`` or ``"sampled"`` (:func:`estimate_external_torques`).
        out: CSV file to write (atomically): ``t``, ``tau_ext[<dof>]`` and with ``frame``
            ``force[x|y|z]`` [N], ``torque[x|y|z]`` [N m].

    Raises:
        InputError: A bad gain, threshold, torque mode, or an ``out`` that is not ``.csv``.
        TrajectoryError: An unreadable file, or one of another robot.
        FrameError: An unknown frame or one no joint moves.
    """
    if out is not None and Path(out).suffix != ".csv":
        raise InputError("out", "a .csv file name", repr(str(out)))
    trajectory = Trajectory.load(path).for_robot(robot)
    residual = estimate_external_torques(robot, trajectory, gain=gain, torque=torque)
    applied = read_extra(Path(path), "tau_env")
    wrench = None if frame is None else external_wrench(robot, trajectory.q, residual, frame)
    collision = None if threshold is None else detect_collision(robot, trajectory.t, residual, threshold)
    run = ObservationRun(
        robot.name, str(path), float(np.max(np.asarray(gain, dtype=float))), torque,
        tuple(dof.name for dof in robot.dofs), tuple(dof.effort_unit for dof in robot.dofs),
        np.asarray(trajectory.t, dtype=float), residual, applied,
        None if frame is None else robot.task_frame(frame, "an external wrench"), wrench,
        None if threshold is None else float(threshold), collision,
    )  # fmt: skip
    if out is None:
        return run
    header, table = run.table()
    atomic_write_text(
        out, csv_preamble(robot.name, header).replace("trajectory of", "external torques of", 1) + format_rows(table)
    )
    return replace(run, out=str(out))
