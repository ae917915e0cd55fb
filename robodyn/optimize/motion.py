"""``point_to_point``: a minimum-effort or minimum-time rest-to-rest motion within the joint limits.

Direct multiple shooting on robodyn's exported CasADi dynamics
(:func:`robodyn.export.casadi_functions`' ``forward_dynamics``, the tree LDLᵀ):

- the motion is ``intervals`` steps of equal length ``dt = T / intervals``; the unknowns are
  the state ``(q_k, v_k)`` at every grid point and a torque ``tau_k`` held over each step;
- each step is one classical RK4 step of ``q̇ = v``, ``v̇ = FD(q, v, tau_k)`` (the stages of
  :func:`robodyn.simulate`'s ``"rk4"`` on a fixed base), and the state after it must equal the
  next grid point's;
- the motion starts at ``start`` and ends at ``goal``, both at rest; at every grid point the
  positions stay within the URDF's position limits, the velocities within its velocity
  limits, and the torques within its effort limits (the unspecified ones do not count, as in
  :mod:`robodyn.sim.limits`); between grid points the RK4 stages are not constrained;
- ``cost="effort"`` minimises ``Σ dt Σ_j (tau_j / effort_j)²`` (``effort_j`` the joint's
  effort limit, 1 where unlimited) over the given ``duration``; ``cost="time"`` minimises
  ``T ≤ duration`` (plus 1e-3 times the effort term, which makes the bang-bang optimum
  unique).

IPOPT (shipped in the casadi wheel) solves it silently. The result is a
:class:`~robodyn.trajectory.Trajectory` at the grid, with ``a = FD(q, v, tau)`` by the
Pinocchio engine at every sample (so ``RNEA(q, v, a) = tau`` there; the last sample holds
the last torque), ready for ``robodyn record`` and ``robodyn simulate``.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from robodyn.common.extras import require
from robodyn.common.text import printable
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError, OptimizationError
from robodyn.export import casadi_functions
from robodyn.export.programs import check_exportable
from robodyn.sim.limits import JointLimits
from robodyn.trajectory import Trajectory

Cost = Literal["effort", "time"]
COSTS: tuple[Cost, ...] = ("effort", "time")
#: Most shooting intervals accepted.
MAX_INTERVALS = 2000
#: IPOPT's iteration limit.
MAX_ITERATIONS = 1000
#: Weight of the effort term in a minimum-time problem.
TIME_REGULARISATION = 1e-3

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

    def text(self) -> str:
        """One line: IPOPT's status, the cost, the duration, the solve and the peak efforts."""
        units = self.effort_units or ("",) * len(self.peak_torque)
        names = self.trajectory.coordinate_names[1]  # one per degree of freedom
        peaks = ", ".join(
            f"{printable(name)} {peak:.4g} {unit}".rstrip()
            for name, peak, unit in zip(names, self.peak_torque, units, strict=True)
        )
        return (
            f"{printable(self.status)}: {self.kind} cost {self.cost:.6g} s, duration {self.duration:.6g} s, "
            f"{self.iterations} iterations in {self.solve_time:.3g} s; peak efforts {peaks}"
        )


def _rk4(ca: Any, forward: Any, nv: int) -> Any:
    """One RK4 step of ``(q, v)`` with the torque held: a casadi Function ``(x, tau, dt) -> x``."""
    x, tau, dt = ca.SX.sym("x", 2 * nv), ca.SX.sym("tau", nv), ca.SX.sym("dt")

    def f(state):
        return ca.vertcat(state[nv:], forward(state[:nv], state[nv:], tau))

    k1 = f(x)
    k2 = f(x + dt / 2 * k1)
    k3 = f(x + dt / 2 * k2)
    k4 = f(x + dt * k3)
    return ca.Function("rk4", [x, tau, dt], [x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)])


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


@dataclass
class _Problem:
    """The NLP in casadi's Opti stack: its variables and the constraints told apart for a message."""

    opti: Any
    X: Any
    U: Any
    T: Any
    objective: Any
    bounds: dict[str, tuple[Any, np.ndarray]]


def _problem(ca: Any, robot: Robot, start: np.ndarray, goal: np.ndarray, duration: float, intervals: int, cost: Cost) -> _Problem:
    """Multiple shooting with limits and boundary conditions (see the module)."""
    nv, limits = robot.nv, JointLimits(robot)
    opti = ca.Opti()
    X, U = opti.variable(2 * nv, intervals + 1), opti.variable(nv, intervals)
    T = opti.variable() if cost == "time" else duration
    step = _rk4(ca, casadi_functions(robot, frames=())["forward_dynamics"], nv).map(intervals)
    opti.subject_to(X[:, 1:] == step(X[:, :-1], U, T / intervals))
    rest = np.zeros(nv)
    opti.subject_to(X[:, 0] == np.concatenate([start, rest]))
    opti.subject_to(X[:, -1] == np.concatenate([goal, rest]))
    bounds: dict[str, tuple[Any, np.ndarray]] = {}
    for kind, rows, lower, upper in (
        ("position", X[:nv, :], limits.lower, limits.upper),
        ("velocity", X[nv:, :], -limits.velocity, limits.velocity),
        ("effort", U, -limits.effort, limits.effort),
    ):
        for j in np.flatnonzero(np.isfinite(lower) | np.isfinite(upper)):
            constraint = opti.bounded(lower[j], rows[j, :], upper[j])
            opti.subject_to(constraint)
            bounds[f"the {kind} limit of {robot.joint_names[j]!r}"] = (constraint, np.array([lower[j], upper[j]]))
    scale = np.where(np.isfinite(limits.effort), limits.effort, 1.0)
    effort = ca.sumsqr(U / ca.repmat(scale, 1, intervals)) * (T / intervals)
    objective = effort if cost == "effort" else T + TIME_REGULARISATION * effort
    if cost == "time":
        opti.subject_to(opti.bounded(1e-3 * duration, T, duration))
        opti.set_initial(T, duration)
    opti.minimize(objective)
    return _Problem(opti, X, U, T, objective, bounds)


def _initial_guess(problem: _Problem, robot: Robot, start: np.ndarray, goal: np.ndarray, duration: float, intervals: int) -> None:
    """Straight from start to goal at constant speed, holding gravity (within the effort limits)."""
    s = np.linspace(0.0, 1.0, intervals + 1)
    q = start + s[:, None] * (goal - start)
    v = np.tile((goal - start) / duration, (intervals + 1, 1))
    effort = JointLimits(robot).effort
    tau = np.clip(robot.gravity(q[:-1]), -effort, effort)
    problem.opti.set_initial(problem.X, np.hstack([q, v]).T)
    problem.opti.set_initial(problem.U, tau.T)


def _limiting(problem: _Problem) -> str:
    """The bound with the largest multiplier at the last iterate ("" when none is active)."""
    worst, name = 0.0, ""
    for label, (constraint, _) in problem.bounds.items():
        dual = float(np.max(np.abs(problem.opti.debug.value(problem.opti.dual(constraint)))))
        if dual > worst:
            worst, name = dual, label
    return name if worst > 1e-6 else ""


def point_to_point(
    robot: Robot,
    start: Any,
    goal: Any,
    duration: float,
    *,
    intervals: int = 50,
    cost: Cost = "effort",
    progress: Progress | None = None,
) -> OptimalMotion:
    """A rest-to-rest motion from ``start`` to ``goal`` within the joint limits (see the module).

    Args:
        robot: From :func:`robodyn.load` (fixed base).
        start, goal: Configurations, shape (nq,), in [rad] / [m], within the position limits.
        duration: The motion's duration in [s] (``cost="time"``: its upper bound).
        intervals: Shooting intervals (the trajectory has ``intervals + 1`` samples).
        cost: ``"effort"`` or ``"time"``.
        progress: Called as ``progress(stage, done, total)`` (each IPOPT iteration).

    Returns:
        The motion and the solve's facts.

    Raises:
        InputError: Naming the parameter (``start``, ``goal``, ``duration``, ``intervals``,
            ``cost``, ``robot`` for a floating base).
        OptimizationError: When IPOPT finds no motion (its status, the limiting constraint).
        MissingExtraError: Without casadi (``robodyn[optimize]``).
    """
    ca = require("casadi", extra="optimize", purpose="optimal motions")
    start_q, goal_q = _check(robot, start, goal, duration, intervals, cost)
    if progress:
        progress("exporting the dynamics", 0, MAX_ITERATIONS)
    problem = _problem(ca, robot, start_q, goal_q, float(duration), int(intervals), cost)
    _initial_guess(problem, robot, start_q, goal_q, float(duration), int(intervals))
    options = {
        "print_time": False,
        "ipopt.print_level": 0,
        "ipopt.sb": "yes",
        "ipopt.max_iter": MAX_ITERATIONS,
        "ipopt.bound_relax_factor": 0.0,  # limits are limits: IPOPT relaxes them by 1e-8 otherwise
    }
    problem.opti.solver("ipopt", options)
    if progress:
        problem.opti.callback(lambda iteration: progress("solving", int(iteration), MAX_ITERATIONS))
    began = time.perf_counter()
    try:
        solution = problem.opti.solve()
    except RuntimeError:
        status = str(problem.opti.stats().get("return_status", "an error"))
        raise OptimizationError(robot.name, status, _limiting(problem)) from None
    elapsed = time.perf_counter() - began
    return _motion(robot, problem, solution, int(intervals), elapsed, cost)


def _motion(robot: Robot, problem: _Problem, solution: Any, intervals: int, elapsed: float, cost: str) -> OptimalMotion:
    """The solution as a trajectory at the grid (``a`` by the engine's forward dynamics)."""
    nv = robot.nv
    X = np.atleast_2d(solution.value(problem.X)).reshape(2 * nv, intervals + 1)
    U = np.atleast_2d(solution.value(problem.U)).reshape(nv, intervals)
    T = float(solution.value(problem.T))
    q, v = X[:nv].T.copy(), X[nv:].T.copy()
    tau = np.vstack([U.T, U.T[-1:]])
    a = robot.forward_dynamics(q, v, tau)
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
