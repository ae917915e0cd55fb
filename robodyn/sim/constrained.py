"""Simulation under bilateral constraints: RK4 on the constrained dynamics, then projection.

Integrating ``v̇`` from :meth:`robodyn.Robot.constrained_forward_dynamics` keeps
``Φ̈ = 0`` but not ``Φ = 0``: rounding and the integrator's truncation make a closed loop
drift open. The stabilisation here is **projection after every step** (no Baumgarte
gains to tune):

1. positions: Newton steps ``δq = −M⁻¹ Jᵀ (J M⁻¹ Jᵀ)⁺ Φ(q)`` (along
   :meth:`~robodyn.Robot.integrate`) until ``max |Φ| ≤`` :data:`POSITION_TOLERANCE`
   (at most :data:`PROJECTION_ITERATIONS`; one or two suffice after a step);
2. velocities: ``v ← v − M⁻¹ Jᵀ (J M⁻¹ Jᵀ)⁺ J v``, the ``M``-orthogonal projection onto
   ``J v = 0``: it removes only the kinetic energy of the motion that breaks the
   constraints, so a passive mechanism's energy is conserved to the integrator's order.

The pseudo-inverse is the dynamics layer's (redundant rows dropped, as in its KKT solve).
The initial state is projected the same way first (:attr:`ConstrainedSimulation.initial_correction`
says how far it moved). Contacts are bilateral here (``PointContact``: sticking, or
sliding without friction when ``μ = 0``); nothing checks the sign of their force.

:func:`constrained_rk4_step` is one step (a pure function); :func:`simulate_constrained`
runs a whole motion into a :class:`~robodyn.trajectory.Trajectory` plus the multipliers.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from robodyn.common.text import quoted
from robodyn.constraints.algebra import row_labels
from robodyn.dynamics import constrained
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError, SimulationError
from robodyn.trajectory import Trajectory
from robodyn.trajectory.columns import constraint_header
from robodyn.trajectory.io import write_csv_with_columns

#: Largest ``|Φ|`` left by the position projection, in [m] / [rad].
POSITION_TOLERANCE = 1e-12
#: Most Newton steps of one position projection.
PROJECTION_ITERATIONS = 20
#: Most steps of one simulation (10 s at 0.1 ms).
MAX_STEPS = 100_000

#: Torques: a constant array (nv,) or a function ``tau(t, q, v) -> (nv,)``.
Torques = np.ndarray | Callable[[float, np.ndarray, np.ndarray], np.ndarray] | None


@dataclass(frozen=True)
class ConstrainedSimulation:
    """A motion under constraints.

    Attributes:
        trajectory: Times, ``q``, ``v``, ``a`` (constrained accelerations at each sample),
            ``tau``, as any simulation's (:class:`robodyn.trajectory.Trajectory`).
        multipliers: ``λ`` at each sample, shape (N, m): forces [N] / torques [N m], world
            axes (:mod:`robodyn.constraints.algebra`).
        residual: ``max |Φ(q)|`` at each sample, shape (N,), in [m] / [rad].
        initial_correction: How far the projection moved the initial ``q``: ``max |δq|``.
        labels: ``(constraint, component, unit)`` of each column of ``multipliers``
            (:func:`robodyn.constraints.algebra.row_labels`).
    """

    trajectory: Trajectory
    multipliers: np.ndarray
    residual: np.ndarray
    initial_correction: float
    labels: tuple[tuple[str, str, str], ...] = ()

    def peak_forces(self) -> list[tuple[str, float, float | None]]:
        """Each constraint's peak force over the run: ``(name, max |f| in [N], max |m| in
        [N m] or None)`` (``f``: the force rows of ``λ``, a sliding contact's normal force;
        ``m``: a weld's torque rows)."""
        peaks: dict[str, tuple[list[int], list[int]]] = {}
        for column, (name, component, _) in enumerate(self.labels):
            forces, torques = peaks.setdefault(name, ([], []))
            (torques if component.startswith("m") else forces).append(column)
        lam = self.multipliers.reshape(len(self.trajectory.t), -1)
        return [
            (
                name,
                float(np.linalg.norm(lam[:, forces], axis=1).max(initial=0.0)),
                float(np.linalg.norm(lam[:, torques], axis=1).max(initial=0.0)) if torques else None,
            )
            for name, (forces, torques) in peaks.items()
        ]

    def summary_lines(self) -> list[str]:
        """The run's constraint summary: the largest residual ``max |Φ|`` over the run, and
        each constraint's peak force (names as given: escape them to print)."""
        unit = "m / rad" if any(component.startswith("m") for _, component, _ in self.labels) else "m"
        lines = [
            f"constraints: max |Φ| over the run {float(self.residual.max(initial=0.0)):.3g} {unit} "
            f"(RK4, projected after every step; the initial q moved {self.initial_correction:.3g})"
        ]
        for name, force, torque in self.peak_forces():
            torque_text = "" if torque is None else f", |m| {torque:.6g} N m"
            lines.append(f"peak constraint force {quoted(name)}: |λ| {force:.6g} N{torque_text}")
        return lines

    def to_dict(self) -> dict[str, object]:
        """The summary's numbers, units in the keys."""
        return {
            "constraint_residual_max_m": float(self.residual.max(initial=0.0)),
            "constraint_peak_force_N": {name: force for name, force, _ in self.peak_forces()},
            "constraint_peak_torque_Nm": {name: torque for name, _, torque in self.peak_forces() if torque is not None},
        }

    def save(self, path: str | Path, extras: dict[str, np.ndarray] | None = None) -> Path:
        """Write the motion and its multipliers as a CSV trajectory: the trajectory's
        columns, ``extras`` (kind -> (N, nv), named like ``v``), then one column a row of
        ``λ``, ``lambda[<constraint>].<component>`` in [N] / [N m]
        (:func:`robodyn.trajectory.columns.constraint_header`), which trajectory readers skip.

        Args:
            path: The ``.csv`` file.
            extras: Extra columns by kind (e.g. ``tau_env``), each (N, nv).

        Raises:
            InputError: For a file name that does not end in ``.csv``.
        """
        path = Path(path)
        if path.suffix != ".csv":
            raise InputError("out", "a .csv file for a run with constraints (its multipliers are columns)", repr(str(path)))
        multipliers = self.multipliers.reshape(len(self.trajectory.t), -1)
        return write_csv_with_columns(path, self.trajectory, extras or {}, constraint_header(self.labels), [multipliers])


def _correction(robot: Robot, bounds, q: np.ndarray, rows: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``M⁻¹ Jᵀ (J M⁻¹ Jᵀ)⁺ rows`` at ``q`` (the smallest ``M``-norm ``δ`` with ``J δ = rows``)."""
    _, jacobian, _ = constrained.state_rows(robot, bounds, q, v)
    return constrained.solve_kkt(robot.mass_matrix(q), np.zeros(robot.nv), jacobian, -rows, robot.name)[0]


def project(robot: Robot, q: np.ndarray, v: np.ndarray, bounds) -> tuple[np.ndarray, np.ndarray]:
    """``(q, v)`` projected onto ``Φ(q) = 0`` and ``J(q) v = 0`` (the module docstring).

    Args:
        robot: The simulated robot.
        q: Configuration, shape (nq,), in [rad] / [m].
        v: Velocity, shape (nv,), in [rad/s] / [m/s].
        bounds: Its constraints bound to its frames (:func:`robodyn.dynamics.constrained.bound`).

    Raises:
        InputError: If the positions cannot be brought within :data:`POSITION_TOLERANCE`
            (constraints that no configuration near ``q`` satisfies).
    """
    zeros = np.zeros(robot.nv)
    for _ in range(PROJECTION_ITERATIONS):
        residual = constrained.state_rows(robot, bounds, q, zeros)[0]
        if not len(residual) or np.abs(residual).max() <= POSITION_TOLERANCE:
            break
        q = pin.integrate(robot.model, q, -_correction(robot, bounds, q, residual, zeros))
    else:
        raise InputError(
            "constraints",
            "constraints a configuration near q satisfies",
            f"|Φ| = {np.abs(residual).max():.3g} after {PROJECTION_ITERATIONS} projection steps",
        )
    _, jacobian, _ = constrained.state_rows(robot, bounds, q, zeros)
    return q, v - _correction(robot, bounds, q, jacobian @ v, zeros)


def _torque(tau: Torques, t: float, q: np.ndarray, v: np.ndarray, nv: int) -> np.ndarray:
    if tau is None:
        return np.zeros(nv)
    if callable(tau):
        value = np.asarray(tau(t, q, v), dtype=float)
        if value.shape != (nv,) or not np.isfinite(value).all():
            raise InputError("tau(t, q, v)", f"{nv} finite values", f"shape {value.shape}")
        return value
    return tau


def constrained_rk4_step(
    robot: Robot, q: np.ndarray, v: np.ndarray, tau: Torques, dt: float, constraints: object = None, *, t: float = 0.0
) -> tuple[np.ndarray, np.ndarray]:
    """One classical Runge–Kutta step of the constrained dynamics, then :func:`project`.

    Args:
        robot: The robot.
        q, v: The state at time ``t``, shapes (nq,), (nv,).
        tau: Torques (constant (nv,) or ``tau(t, q, v)``), or ``None`` for none.
        dt: Step in [s].
        constraints: As for :meth:`robodyn.Robot.constrained_forward_dynamics`.
        t: Time of the state, in [s] (for a torque function).

    Returns:
        ``(q, v)`` at ``t + dt``, on the constraints.
    """
    bounds = constrained.bound(robot, constraints)
    (q, v), batch = robot.validate(q=q, v=v)
    if batch:
        raise InputError("q", "one state (1-D arrays): a step is of one state", f"shape {q.shape}")
    if tau is not None and not callable(tau):
        (tau,), _ = robot.validate(tau=tau)
    return _step(robot, bounds, q, v, tau, dt, t)


def _step(robot: Robot, bounds, q: np.ndarray, v: np.ndarray, tau: Torques, dt: float, t: float) -> tuple[np.ndarray, np.ndarray]:
    """:func:`constrained_rk4_step` of a checked state and torques and bound constraints."""
    model = robot.model

    def rate(time: float, qi: np.ndarray, vi: np.ndarray) -> np.ndarray:
        return constrained.forward_dynamics_unchecked(robot, bounds, qi, vi, _torque(tau, time, qi, vi, robot.nv))[0]

    def integrate(qi: np.ndarray, dq: np.ndarray) -> np.ndarray:
        return pin.integrate(model, qi, dq)  # a floating base's pose on SE(3), unit quaternion kept

    a1 = rate(t, q, v)
    q2, v2 = integrate(q, 0.5 * dt * v), v + 0.5 * dt * a1
    a2 = rate(t + 0.5 * dt, q2, v2)
    q3, v3 = integrate(q, 0.5 * dt * v2), v + 0.5 * dt * a2
    a3 = rate(t + 0.5 * dt, q3, v3)
    q4, v4 = integrate(q, dt * v3), v + dt * a3
    a4 = rate(t + dt, q4, v4)
    q_next = integrate(q, dt / 6.0 * (v + 2.0 * v2 + 2.0 * v3 + v4))
    v_next = v + dt / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
    return project(robot, q_next, v_next, bounds)


def simulate_constrained(
    robot: Robot,
    q0: np.ndarray,
    v0: np.ndarray | None = None,
    *,
    constraints: object = None,
    duration: float,
    dt: float = 1e-3,
    tau: Torques = None,
) -> ConstrainedSimulation:
    """Simulate a robot under bilateral constraints (RK4 and projection: module docstring).

    Args:
        robot: The robot.
        q0: Initial configuration (nq,): projected onto ``Φ = 0`` first.
        v0: Initial velocity (nv,), default zero: projected onto ``J v = 0`` first.
        constraints: As for :meth:`robodyn.Robot.constrained_forward_dynamics` (``None``:
            the robot's own).
        duration: Simulated time in [s].
        dt: Step in [s].
        tau: Torques: constant (nv,), ``tau(t, q, v)``, or ``None`` for none (passive).

    Returns:
        The motion, its multipliers and its constraint residual at every sample.

    Raises:
        InputError: For a non-positive ``dt`` or ``duration``, too many steps, or states
            and torques of the wrong size.
        SimulationError: If the state stops being finite.
    """
    if not (math.isfinite(dt) and dt > 0):
        raise InputError("dt", "a finite step > 0 in [s]", repr(dt))
    if not (math.isfinite(duration) and duration > 0):
        raise InputError("duration", "a finite time > 0 in [s]", repr(duration))
    steps = round(duration / dt)
    if steps > MAX_STEPS:
        raise InputError("duration", f"at most {MAX_STEPS} steps of dt", f"{steps} steps")
    if np.ndim(q0) != 1:
        raise InputError("q0", "one configuration (a 1-D array)", f"shape {np.shape(q0)}")
    (q, v), _ = robot.validate(q=q0, v=np.zeros(robot.nv) if v0 is None else v0)
    if not callable(tau) and tau is not None:
        (tau,), _ = robot.validate(tau=tau)
    bounds = constrained.bound(robot, constraints)
    start = q
    q, v = project(robot, q, v, bounds)
    times = np.arange(steps + 1) * dt
    samples = _run(robot, bounds, q, v, tau, times)
    trajectory = Trajectory(times, samples["q"], samples["v"], samples["a"], samples["tau"], list(robot.joint_names), robot.name)
    labels = tuple(row_labels([b.constraint for b in bounds]))
    lam = samples["lambda"].reshape(len(times), len(labels))
    return ConstrainedSimulation(trajectory, lam, samples["residual"], float(np.abs(q - start).max()), labels)


def _run(robot: Robot, bounds, q: np.ndarray, v: np.ndarray, tau: Torques, times: np.ndarray) -> dict:
    """The samples of a motion from a projected state: ``q``, ``v``, ``a``, ``tau``,
    ``lambda`` (stacked) and ``residual`` (``max |Φ|``) at each time."""
    samples: dict[str, list] = {key: [] for key in ("q", "v", "a", "tau", "lambda", "residual")}
    dt = float(times[1] - times[0]) if len(times) > 1 else 0.0
    for step, t in enumerate(times):
        torque = _torque(tau, float(t), q, v, robot.nv)
        a, lam = constrained.forward_dynamics_unchecked(robot, bounds, q, v, torque)
        residual = float(np.abs(constrained.state_rows(robot, bounds, q, v)[0]).max(initial=0.0))
        for key, value in zip(samples, (q, v, a, torque, lam, residual), strict=True):
            samples[key].append(value)
        if step == len(times) - 1:
            break
        q, v = _step(robot, bounds, q, v, tau, dt, float(t))
        if not (np.isfinite(q).all() and np.isfinite(v).all()):
            raise SimulationError(float(t), step, robot.dofs[int(np.argmax(~np.isfinite(v)))].joint)
    return {key: np.array(values) for key, values in samples.items()}


__all__ = ["POSITION_TOLERANCE", "ConstrainedSimulation", "constrained_rk4_step", "project", "simulate_constrained"]
