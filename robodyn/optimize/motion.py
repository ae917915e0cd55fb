"""``point_to_point``: a minimum-effort or minimum-time rest-to-rest motion within the joint limits.

Direct multiple shooting on robodyn's exported CasADi dynamics
(:func:`robodyn.export.casadi_functions`' ``forward_dynamics``, the tree LDLᵀ):

- the motion is ``intervals`` steps of equal length ``dt = T / intervals``; the unknowns are
  the state ``(q_k, v_k)`` at every grid point and the actuated joints' torques ``u_k`` held
  over each step (``tau = S u``: the joints not ``actuated`` get none);
- each step is one classical RK4 step of ``q̇ = v``, ``v̇ = FD(q, v, S u_k − b v)`` (the stages
  of :func:`robodyn.simulate`'s ``"rk4"`` on a fixed base; ``b`` the joints' viscous damping,
  which the simulation applies by default, zero with ``joint_friction=False``), and the state
  after it must equal the next grid point's (to 1e-12: an open-loop replay amplifies defects);
- the motion starts at ``start`` and ends at ``goal``, both at rest; at every grid point the
  positions stay within the URDF's position limits, the velocities within its velocity
  limits, and the torques within its effort limits (the unspecified ones do not count, as in
  :mod:`robodyn.sim.limits`); between grid points the RK4 stages are not constrained;
- ``cost="effort"`` minimises ``Σ dt Σ_j (tau_j / effort_j)²`` (``effort_j`` the joint's
  effort limit, 1 where unlimited) over the given ``duration``; ``cost="time"`` minimises
  ``T ≤ duration`` (plus 1e-3 times the effort term, which makes the bang-bang optimum
  unique).

IPOPT (shipped in the casadi wheel) solves it silently, from a straight line at constant
speed. Its "infeasible" is local: when it fails, :func:`point_to_point` solves the motion over
2, 4 or 8 times the duration, then the fastest motion from there, and starts again from that
one, delayed (held at the start) or time-scaled; only then is the request refused, worded as
a local verdict. The result is a :class:`~robodyn.trajectory.Trajectory` at the grid, with
``a = FD(q, v, tau − b v)`` by the Pinocchio engine at every sample (so
``RNEA(q, v, a) = tau − b v`` there; the last sample holds the last torque), ready for
``robodyn record`` and ``robodyn simulate``.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from robodyn.common.extras import require
from robodyn.common.text import printable
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError, OptimizationError
from robodyn.export.programs import check_exportable
from robodyn.optimize.shooting import (
    IPOPT_OPTIONS,
    MAX_ITERATIONS,
    TIME_REGULARISATION,
    Cost,
    Plant,
    Problem,
    initial_guess,
    limiting,
    planned_plant,
    scaled_guess,
    shooting_problem,
)
from robodyn.sim.limits import JointLimits
from robodyn.trajectory import Trajectory

__all__ = ["COSTS", "MAX_INTERVALS", "MAX_ITERATIONS", "TIME_REGULARISATION", "OptimalMotion", "point_to_point"]

COSTS: tuple[Cost, ...] = ("effort", "time")
#: Most shooting intervals accepted.
MAX_INTERVALS = 2000

Progress = Callable[[str, int, int], None]


@dataclass(frozen=True)
class OptimalMotion:
    """What :func:`point_to_point` found.

    Attributes:
        trajectory: The motion at the shooting grid (t, q, v, a, tau).
        cost: The objective's value (``"effort"``: in [s]; ``"time"``: ``T`` in [s] plus the
            regularisation).
        duration: ``T`` in [s].
        status: IPOPT's return status.
        iterations: IPOPT's iterations.
        solve_time: Wall-clock time of the solve (export and problem building excluded), in [s].
        peak_torque: Largest ``|tau|`` of each degree of freedom, in [N m] / [N].
        effort_units: The unit of each degree of freedom's effort (``"N m"`` or ``"N"``).
        kind: The cost asked for (``"effort"`` or ``"time"``).
        starts: The solves it took: 1 from the straight line; more when that failed and
            IPOPT was started again (:func:`point_to_point`'s retry).
    """

    trajectory: Trajectory
    cost: float
    duration: float
    status: str
    iterations: int
    solve_time: float
    peak_torque: tuple[float, ...]
    effort_units: tuple[str, ...] = ()
    kind: str = "effort"
    starts: int = 1

    def text(self) -> str:
        """One line: IPOPT's status, the cost, the duration, the solve and the peak efforts."""
        units = self.effort_units or ("",) * len(self.peak_torque)
        names = self.trajectory.coordinate_names[1]  # one per degree of freedom
        peaks = ", ".join(
            f"{printable(name)} {peak:.4g} {unit}".rstrip()
            for name, peak, unit in zip(names, self.peak_torque, units, strict=True)
        )
        retried = "" if self.starts == 1 else f" (in {self.starts} solves: retried from a time-scaled start)"
        return (
            f"{printable(self.status)}{retried}: {self.kind} cost {self.cost:.6g} s, duration {self.duration:.6g} s, "
            f"{self.iterations} iterations in {self.solve_time:.3g} s; peak efforts {peaks}"
        )


def _check(robot: Robot, start: Any, goal: Any, duration: float, intervals: int, cost: str) -> tuple[np.ndarray, np.ndarray]:
    """Refuse what cannot be optimised (one sentence naming the parameter)."""
    check_exportable(robot)
    if cost not in COSTS:
        raise InputError("cost", f"one of {', '.join(COSTS)}", repr(cost))
    if isinstance(intervals, bool) or not isinstance(intervals, int | np.integer) or not 2 <= intervals <= MAX_INTERVALS:
        raise InputError("intervals", f"a whole number from 2 to {MAX_INTERVALS}", repr(intervals))
    if not (isinstance(duration, int | float) and np.isfinite(duration) and duration > 0):
        raise InputError("duration", "a positive time in [s]", repr(duration))
    limits = JointLimits(robot)
    states = []
    for name, values in (("start", start), ("goal", goal)):
        (state,), _ = robot.validate(**{name: values})  # fixed base: nq == nv
        if state.ndim != 1:
            raise InputError(name, f"one configuration of {robot.nq} values", f"shape {state.shape}")
        outside = (state < limits.lower - 1e-12) | (state > limits.upper + 1e-12)
        if outside.any():
            joint = robot.joint_names[int(np.argmax(outside))]
            raise InputError(name, f"within the position limits of {joint!r}", f"{state[int(np.argmax(outside))]:g}")
        states.append(state)
    return states[0], states[1]


def point_to_point(
    robot: Robot,
    start: Any,
    goal: Any,
    duration: float,
    *,
    intervals: int = 50,
    cost: Cost = "effort",
    actuated: Sequence[str] | None = None,
    joint_friction: bool = True,
    progress: Progress | None = None,
) -> OptimalMotion:
    """A rest-to-rest motion from ``start`` to ``goal`` within the joint limits (see the module).

    Args:
        robot: From :func:`robodyn.load` (fixed base).
        start, goal: Configurations, shape (nq,), in [rad] / [m], within the position limits.
        duration: The motion's duration in [s] (``cost="time"``: its upper bound).
        intervals: Shooting intervals (the trajectory has ``intervals + 1`` samples).
        cost: ``"effort"`` or ``"time"``.
        actuated: The joints the motors drive (the others get no torque); ``None``: those
            whose :attr:`~robodyn.dynamics.dofs.Dof.actuated` is true.
        joint_friction: Plan with the joints' viscous damping, as :func:`robodyn.simulate`
            applies it by default (``False``: the rigid-body motion). Coulomb friction is
            refused (the motion starts and ends at rest, where stiction is not differentiable).
        progress: Called as ``progress(stage, done, total)`` (each IPOPT iteration).

    Returns:
        The motion and the solve's facts.

    Raises:
        InputError: Naming the parameter (``start``, ``goal``, ``duration``, ``intervals``,
            ``cost``, ``actuated``, ``joint_friction``, ``robot`` for a floating base).
        OptimizationError: When IPOPT finds no motion, from the straight-line start and
            again from a time-scaled one (its status, the limiting constraint; IPOPT's
            verdict is local).
        MissingExtraError: Without casadi (``robodyn[optimize]``).
    """
    ca = require("casadi", extra="optimize", purpose="optimal motions")
    ends = _check(robot, start, goal, duration, intervals, cost)
    plant = planned_plant(robot, actuated, bool(joint_friction))
    task = _Task(ca, robot, plant, ends, int(intervals), cost, progress)
    try:
        return task.solve(float(duration))
    except OptimizationError as error:
        return _retried(task, float(duration), error)


#: The retry's longer durations, multiples of the one asked for.
RETRY_STRETCHES = (2.0, 4.0, 8.0)


def _retried(task: _Task, duration: float, first: OptimizationError) -> OptimalMotion:
    """The retry after IPOPT failed from the straight line (its verdict is local): a
    minimum-effort motion over a longer time (easier: slower), from it the fastest motion
    IPOPT finds, and from that one, delayed or time-scaled, the motion asked for.

    Raises:
        OptimizationError: ``first``'s, worded as local, when no start succeeds.
    """
    longer = None
    for stretch in RETRY_STRETCHES:
        try:
            longer = task.solve(stretch * duration, cost="effort")
            break
        except OptimizationError:
            continue
    if longer is None:
        tried = f"from a straight line, also over {', '.join(f'{k:g}' for k in RETRY_STRETCHES)}x the duration"
        raise _local(first, tried)
    fastest = task.solve(longer.duration, cost="time", guess=longer)
    if task.cost == "time" and fastest.duration <= duration:
        return replace(fastest, solve_time=task.spent, starts=task.starts)
    try:
        motion = task.solve(duration, guess=fastest)
    except OptimizationError as error:
        tried = f"from a straight line and from the fastest motion found ({fastest.duration:.4g} s), delayed or time-scaled"
        raise _local(error, tried) from None
    return replace(motion, solve_time=task.spent, starts=task.starts)


def _local(error: OptimizationError, tried: str) -> OptimizationError:
    """``error`` worded as what it is: IPOPT's local verdict from the starts tried."""
    worded = OptimizationError(
        error.robot, f"{error.status} ({tried}: a local verdict, another start may succeed)", error.limiting
    )
    worded.status = error.status
    return worded


class _Task:
    """One planning request, solvable over several durations and from several starts."""

    def __init__(
        self, ca: Any, robot: Robot, plant: Plant, ends: tuple[np.ndarray, np.ndarray], intervals: int, cost: Cost,
        progress: Progress | None,
    ) -> None:  # fmt: skip
        self.ca, self.robot, self.plant, self.ends, self.intervals, self.cost = ca, robot, plant, ends, intervals, cost
        self.progress, self.spent, self.starts = progress, 0.0, 0

    def solve(self, duration: float, *, cost: Cost | None = None, guess: OptimalMotion | None = None) -> OptimalMotion:
        """IPOPT over ``duration`` (``cost``: the request's unless given) from the straight
        line, or from ``guess`` delayed or time-scaled (:func:`scaled_guess`).

        Raises:
            OptimizationError: IPOPT's status and the limiting constraint.
        """
        robot, progress = self.robot, self.progress
        if progress:
            progress("exporting the dynamics", 0, MAX_ITERATIONS)
        cost = cost or self.cost
        self.starts += 1
        problem = shooting_problem(self.ca, robot, self.plant, self.ends, duration, self.intervals, cost)
        if guess is None:
            initial_guess(problem, robot, self.plant, self.ends, duration)
        else:
            scaled_guess(problem, self.plant, guess.trajectory, duration)
        problem.opti.solver("ipopt", IPOPT_OPTIONS)
        if progress:
            problem.opti.callback(lambda iteration: progress("solving", int(iteration), MAX_ITERATIONS))
        began = time.perf_counter()
        try:
            solution = problem.opti.solve()
        except RuntimeError:
            self.spent += time.perf_counter() - began
            status = str(problem.opti.stats().get("return_status", "an error"))
            raise OptimizationError(robot.name, status, limiting(problem)) from None
        elapsed = time.perf_counter() - began
        self.spent += elapsed
        return _motion(robot, self.plant, problem, solution, self.intervals, elapsed, cost)


def _motion(
    robot: Robot, plant: Plant, problem: Problem, solution: Any, intervals: int, elapsed: float, cost: str
) -> OptimalMotion:
    """The solution as a trajectory at the grid: ``tau = S u`` the motors' torques, ``a`` by
    the engine's forward dynamics under ``tau − b v`` (the damping's torque taken off)."""
    nv, nu = plant.selection.shape
    X = np.atleast_2d(solution.value(problem.X)).reshape(2 * nv, intervals + 1)
    U = np.atleast_2d(solution.value(problem.U)).reshape(nu, intervals)
    T = float(solution.value(problem.T))
    q, v = X[:nv].T.copy(), X[nv:].T.copy()
    tau = np.vstack([U.T, U.T[-1:]]) @ plant.selection.T
    a = robot.forward_dynamics(q, v, tau - v * plant.damping)
    t = np.linspace(0.0, T, intervals + 1)
    trajectory = Trajectory(t, q, v, a, tau, joint_names=list(robot.joint_names), robot=robot.name)
    stats = solution.stats()
    return OptimalMotion(
        trajectory=trajectory,
        cost=float(solution.value(problem.objective)),
        duration=T,
        status=str(stats.get("return_status", "")),
        iterations=int(stats.get("iter_count", 0)),
        solve_time=elapsed,
        peak_torque=tuple(float(x) for x in np.abs(tau).max(axis=0)),
        effort_units=tuple(dof.effort_unit for dof in robot.dofs),
        kind=cost,
    )
