"""A robot on the ground: :func:`simulate_contact` runs :func:`robodyn.sim.contact.contact_step`.

Each sample ``i`` holds the state at ``t_i`` and the contact forces of the step from
``t_i`` to ``t_i + dt`` (so ``a`` at a sample is that step's ``(v⁺ − v) / dt``); the
last sample's forces come from one more step, not kept. Joint damping of the file is
applied (``−D v`` added to the torques, explicit); joint Coulomb friction is not, and is
reported in :attr:`ContactSimulation.notes`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from robodyn.common.text import printable
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError, SimulationError
from robodyn.sim.contact import ACTIVE_FORCE, ContactSettings, contact_step
from robodyn.sim.contact_checks import buried_line
from robodyn.sim.contact_limits import LimitRows
from robodyn.sim.ground import ContactPoint, Contacts, Ground, contact_points
from robodyn.sim.limits import check_mode
from robodyn.sim.plan import ExternalWrench
from robodyn.trajectory import Trajectory
from robodyn.trajectory.columns import contact_header
from robodyn.trajectory.io import write_csv_with_columns

#: Most steps of one run (100 s at 1 ms).
MAX_STEPS = 100_000

#: A controller ``tau(t, q, v) -> (nv,)``, a constant (nv,), or ``None`` (passive).
Controller = Callable[[float, np.ndarray, np.ndarray], np.ndarray] | np.ndarray | None


@dataclass(frozen=True)
class ContactSimulation:
    """A motion on the ground.

    Attributes:
        trajectory: Times, ``q``, ``v``, ``a``, ``tau`` (:class:`robodyn.trajectory.Trajectory`).
        contacts: The contact points' names, in the order of the arrays below.
        forces: Each contact's force on the robot, world axes, shape (N, k, 3), in [N].
        gaps: Each point's height above the plane, shape (N, k), in [m] (< 0: penetration).
        slip: Each point's tangential speed after the step, shape (N, k), in [m/s].
        ground: The plane.
        iterations: ADMM iterations of each step, shape (N,) (0: the previous modes held).
        converged: Whether each step's impulses solve the contact problem to the solver's
            tolerance (polished, or ADMM converged), shape (N,).
        notes: What the run does not model, one line each.
        frames: The frame each contact point belongs to, in the order of ``contacts``.
        limit_torques: With enforced limits, the torques the joints' position limits
            apply (:mod:`robodyn.sim.contact_limits`), shape (N, nv), in [N m] or [N];
            ``None``: limits not enforced.
    """

    trajectory: Trajectory
    contacts: list[str]
    forces: np.ndarray
    gaps: np.ndarray
    slip: np.ndarray
    ground: Ground
    iterations: np.ndarray
    converged: np.ndarray
    notes: tuple[str, ...] = ()
    frames: tuple[str, ...] = ()
    limit_torques: np.ndarray | None = None

    @property
    def normal_forces(self) -> np.ndarray:
        """Each contact's normal force ``n · f``, shape (N, k), in [N]."""
        return self.forces @ np.array(self.ground.normal)

    @property
    def active(self) -> np.ndarray:
        """Which contacts push (normal force above :data:`ACTIVE_FORCE`), shape (N, k)."""
        return self.normal_forces > ACTIVE_FORCE

    def force_arrows(self) -> tuple[ExternalWrench, ...]:
        """The contact forces as :class:`robodyn.ExternalWrench` es for a recording's arrows
        (``robodyn.viz.recording.record(..., forces=run.force_arrows())``): one a frame,
        the sum of its contacts' forces (zero while none is active) at the frame's origin,
        held over each step (a box's eight corners: one arrow, the total, at its origin).
        """
        frames: dict[str, list[int]] = {}
        for index, frame in enumerate(self.frames):
            frames.setdefault(frame, []).append(index)
        t = self.trajectory.t

        def held(indices: list[int]) -> Callable[[float], np.ndarray]:
            total = self.forces[:, indices].sum(axis=1)
            return lambda time: total[int(np.clip(np.searchsorted(t, time, side="right") - 1, 0, len(t) - 1))]

        return tuple(ExternalWrench(frame, held(indices)) for frame, indices in frames.items())

    def save(self, path: str | Path, extras: dict[str, np.ndarray] | None = None) -> Path:
        """Write the motion and its contacts as a CSV trajectory: the trajectory's columns,
        ``extras`` (kind -> (N, nv), e.g. ``tau_env``, named like ``v``), then
        ``f[<contact>].x/.y/.z`` [N] and ``contact[<contact>]`` (1: active), which
        trajectory readers skip (docs/trajectory-format.md).

        Args:
            path: The ``.csv`` file to write.
            extras: More columns, kind -> values of shape (N, nv) (one row a sample, one
                column a velocity coordinate, named ``<kind>[<coordinate>]``); ``None``: none.

        Returns:
            The path written.

        Raises:
            InputError: For a file name that does not end in ``.csv``.
        """
        path = Path(path)
        if path.suffix != ".csv":
            raise InputError("path", "a .csv file name for a run on the ground (its contact forces are columns)", repr(str(path)))
        forces = self.forces.reshape(len(self.forces), 3 * len(self.contacts))
        columns = [forces, self.active.astype(float)]
        return write_csv_with_columns(path, self.trajectory, extras or {}, contact_header(self.contacts), columns)

    def summary_lines(self) -> list[str]:
        """The run's contact summary: peak normal force, slip and penetration."""
        normal = self.normal_forces
        peak = int(np.argmax(normal.max(axis=1))) if len(normal) else 0
        active_slip = np.where(self.active, self.slip, 0.0)
        lines = [
            f"ground{f' ({self.ground.origin})' if self.ground.origin else ''}: height {self.ground.height:.6g} m, normal {tuple(round(x, 6) for x in self.ground.normal)}, "
            f"μ {self.ground.friction:.6g}; {len(self.contacts)} contact points",
            f"peak normal force: {normal.max(initial=0.0):.6g} N (total {normal.sum(axis=1).max(initial=0.0):.6g} N "
            f"at t = {self.trajectory.t[peak]:.6g} s); final total {normal[-1].sum():.6g} N",
            f"peak slip speed of an active contact: {active_slip.max(initial=0.0):.3g} m/s",
            f"deepest penetration: {max(0.0, -float(self.gaps.min(initial=0.0))):.3g} m",
            f"contacts active at the end: {int(self.active[-1].sum())} of {len(self.contacts)}",
        ]
        unsolved = int((~self.converged).sum())
        if unsolved:
            lines.append(
                f"contact solver: {unsolved} of {len(self.converged)} steps stopped before ADMM's tolerance "
                f"(the first at t = {self.trajectory.t[int(np.argmin(self.converged))]:.6g} s): their forces are approximate"
            )
        if self.limit_torques is not None:
            peak = np.abs(self.limit_torques).max(axis=0)
            joint = self.trajectory.coordinate_names[1][int(np.argmax(peak))] if peak.max() > 0 else ""
            lines.append(
                "joint limits: enforced, one-sided rows of the contact problem; peak limit torque "
                + (f"{peak.max():.6g} N m or N ({joint})" if joint else "0")
            )
        return [printable(line) for line in (*lines, *self.notes)]


def simulate_contact(
    robot: Robot,
    *,
    ground: Ground,
    contacts: str | Sequence[str | ContactPoint] = "collision",
    controller: Controller = None,
    duration: float,
    dt: float = 1e-3,
    q0: np.ndarray | None = None,
    v0: np.ndarray | None = None,
    settings: ContactSettings | None = None,
    limits: str = "warn",
) -> ContactSimulation:
    """Simulate a robot touching a plane (:mod:`robodyn.sim.contact`'s scheme).

    Args:
        robot: The robot (a floating base or a fixed one).
        ground: The plane and its friction.
        contacts: ``"collision"`` (the URDF's collision spheres and boxes) or frame names /
            :class:`~robodyn.sim.ground.ContactPoint` values.
        controller: ``tau(t, q, v) -> (nv,)``, a constant (nv,), or ``None`` (no torque).
        duration: Simulated time in [s].
        dt: Step in [s].
        q0: Initial configuration (nq,), default the robot's start (:meth:`~robodyn.Robot.default_configuration`).
        v0: Initial velocity (nv,), default zero.
        settings: Solver settings (:class:`~robodyn.sim.contact.ContactSettings`).
        limits: ``"enforce"``: the joints' position limits are one-sided rows of the contact
            problem and their efforts saturate the torques (:mod:`robodyn.sim.contact_limits`);
            ``"warn"`` / ``"ignore"``: the joints move freely.

    Returns:
        The motion with every contact's force, gap and slip at each sample.

    Raises:
        InputError: For a non-positive ``dt`` or ``duration``, too many steps, states or
            torques of the wrong size, or unknown contact frames.
        SimulationError: If the state stops being finite.
    """
    if not (isinstance(ground, Ground)):
        raise InputError("ground", "a robodyn.sim.ground.Ground", repr(ground)[:80])
    if not (isinstance(dt, int | float) and math.isfinite(dt) and dt > 0):
        raise InputError("dt", "a finite step > 0 in [s]", repr(dt))
    if not (isinstance(duration, int | float) and math.isfinite(duration) and duration > 0):
        raise InputError("duration", "a finite time > 0 in [s]", repr(duration))
    steps = round(duration / dt)
    if steps > MAX_STEPS:
        raise InputError("duration", f"at most {MAX_STEPS} steps of dt", f"{steps} steps")
    found = contact_points(robot, contacts)
    q = robot.default_configuration() if q0 is None else q0
    if np.ndim(q) != 1:
        raise InputError("q0", "one configuration (a 1-D array)", f"shape {np.shape(q)}")
    (q, v), _ = robot.validate(q=q, v=np.zeros(robot.nv) if v0 is None else v0)
    if controller is not None and not callable(controller):
        (controller,), _ = robot.validate(tau=controller)
    check_mode(limits)
    return run_contacts(robot, ground, found, controller, q, v, steps, dt, settings=settings, limits=limits == "enforce")


def run_contacts(
    robot: Robot, ground: Ground, found: Contacts, controller: Controller, q: np.ndarray, v: np.ndarray,
    steps: int, dt: float, *, settings: ContactSettings | None = None, joint_friction: bool = True,
    limits: bool = False,
) -> ContactSimulation:  # fmt: skip
    """:func:`simulate_contact` of checked arguments (``joint_friction=False``: no joint damping;
    ``limits``: the joints' position limits in the contact problem and their efforts
    saturating the torques, :mod:`robodyn.sim.contact_limits`).

    Args:
        robot: The robot (a floating base or a fixed one).
        ground: The plane and its friction.
        found: The checked contact points (:func:`~robodyn.sim.ground.contact_points`); their
            ``skipped`` lines go into the run's notes.
        controller: ``tau(t, q, v) -> (nv,)``, a constant (nv,), or ``None`` (no torque).
        q: Initial configuration, shape (nq,).
        v: Initial velocity, shape (nv,).
        steps: The number of steps (the run has ``steps + 1`` samples).
        dt: Step in [s].
        settings: Solver settings (:class:`~robodyn.sim.contact.ContactSettings`); ``None``: the defaults.
        joint_friction: Apply the joints' damping ``−b v`` (:attr:`Robot.joint_damping`);
            ``False``: none. The joints' Coulomb friction is not applied (a note says so).
        limits: Put the joints' position limits in the contact problem and saturate the
            torques at their efforts.
    """
    damping = robot.joint_damping if joint_friction else np.zeros(robot.nv)
    rows = LimitRows(robot) if limits else None
    samples = _run(robot, ground, found.points, controller, (q, v), steps, dt, settings or ContactSettings(), damping, rows)
    trajectory = Trajectory(
        samples["t"], samples["q"], samples["v"], samples["a"], samples["tau"], list(robot.joint_names), robot.name
    )
    buried = buried_line(robot, samples["q"], samples["t"], ground, found)
    notes = ([buried] if buried else []) + list(found.skipped)
    if joint_friction and np.any(robot.joint_friction):
        notes.append("joint Coulomb friction of the file is not applied in contact runs")
    return ContactSimulation(
        trajectory, found.names, samples["forces"], samples["gaps"], samples["slip"], ground, samples["iterations"],
        samples["converged"], tuple(notes), tuple(point.link for point in found.points),
        samples["limit_torques"] if limits else None,
    )  # fmt: skip


def _torque(controller: Controller, t: float, q: np.ndarray, v: np.ndarray, nv: int) -> np.ndarray:
    if controller is None:
        return np.zeros(nv)
    if not callable(controller):
        return controller
    value = np.asarray(controller(t, q, v), dtype=float)
    if value.shape != (nv,) or not np.isfinite(value).all():
        raise InputError("controller(t, q, v)", f"{nv} finite torques", f"shape {value.shape}")
    return value


def _run(
    robot: Robot, ground: Ground, points: tuple[ContactPoint, ...], controller: Controller,
    state: tuple[np.ndarray, np.ndarray], steps: int, dt: float, settings: ContactSettings, damping: np.ndarray,
    rows: LimitRows | None,
) -> dict[str, np.ndarray]:  # fmt: skip
    """Samples ``t, q, v, a, tau, forces, gaps, slip, iterations, converged, limit_torques``
    of ``steps`` steps (the limit torques zero without ``rows``)."""
    keys = ("q", "v", "a", "tau", "forces", "gaps", "slip", "iterations", "converged", "limit_torques")
    samples: dict[str, list] = {key: [] for key in keys}
    (q, v), guess, held, limit_torques = state, None, None, np.zeros(robot.nv)
    for step in range(steps + 1):
        t = step * dt
        tau = _torque(controller, t, q, v, robot.nv)
        if rows is not None:
            tau = rows.limits.saturate(tau)
        result = contact_step(
            robot, q, v, tau - damping * v, dt, ground, points, settings=settings, guess=guess, limits=rows, held=held
        )
        if rows is not None and result.limits is not None:
            held = result.limits
            limit_torques = rows.torques(held, dt, robot.nv)
        values = (q, v, (result.v - v) / dt, tau, result.forces, result.gaps, result.slip, result.iterations,
                  result.converged, limit_torques)  # fmt: skip
        for key, value in zip(keys, values, strict=True):
            samples[key].append(value)
        q, v, guess = result.q, result.v, result.impulses
        if not (np.isfinite(q).all() and np.isfinite(v).all()):
            raise SimulationError(t, step, robot.dofs[int(np.argmax(~np.isfinite(v)))].joint)
    out = {key: np.array(values) for key, values in samples.items()}
    out["t"] = np.arange(steps + 1) * dt
    return out


def ground_lines(robot: Robot, contact: ContactSimulation | None) -> tuple[str, ...]:
    """A run's ground lines for its summary: the contact summary, or for a floating robot
    without a ground or constraints ``"no ground: the base falls freely"`` (nothing for a
    fixed one, nor for one its constraints hold).

    Args:
        robot: The simulated robot.
        contact: The run's contacts (:class:`ContactSimulation`), or ``None`` for a run
            without a ground.
    """
    if contact is not None:
        return tuple(contact.summary_lines())
    note = free_fall_note(robot, None)
    return (note,) if note else ()


def free_fall_note(robot: Robot, ground: Ground | None) -> str | None:
    """The one summary line of a floating robot simulated with nothing holding its base
    (no ground and no constraint), else ``None``.

    Args:
        robot: The simulated robot.
        ground: The plane the run stands on, or ``None``.
    """
    free = robot.floating_base and ground is None and not robot.constraints
    return "no ground: the base falls freely" if free else None


__all__ = ["ContactSimulation", "free_fall_note", "ground_lines", "run_contacts", "simulate_contact"]
