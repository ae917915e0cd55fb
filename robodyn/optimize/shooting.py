"""The multiple-shooting problem of :func:`robodyn.optimize.point_to_point` in casadi's Opti
stack: the plant planned with (actuation, damping), the NLP and its starts.

See :mod:`robodyn.optimize.motion` for the method.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from robodyn.common.text import quoted
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError
from robodyn.export import casadi_functions
from robodyn.sim.limits import JointLimits
from robodyn.sim.linearize import actuation_matrix
from robodyn.trajectory import Trajectory

Cost = Literal["effort", "time"]
#: IPOPT's iteration limit.
MAX_ITERATIONS = 1000
#: Weight of the effort term in a minimum-time problem.
TIME_REGULARISATION = 1e-3
#: IPOPT's options: silent, its bounds not relaxed (limits are limits: IPOPT relaxes them by 1e-8 otherwise).
IPOPT_OPTIONS = {
    "print_time": False,
    "ipopt.print_level": 0,
    "ipopt.sb": "yes",
    "ipopt.max_iter": MAX_ITERATIONS,
    "ipopt.bound_relax_factor": 0.0,
    "ipopt.constr_viol_tol": 1e-12,  # the dynamics to rounding: an open-loop replay amplifies every defect
}


@dataclass(frozen=True)
class Plant:
    """What the plan's dynamics apply besides the rigid body: the actuation ``S`` (nv, nu)
    (``tau = S u``) and the joints' viscous damping ``b`` (nv,), in [N m s/rad] / [N s/m]."""

    selection: np.ndarray
    damping: np.ndarray


def planned_plant(robot: Robot, actuated: Sequence[str] | None, joint_friction: bool) -> Plant:
    """The actuation (default: the joints whose ``Dof.actuated``) and the damping planned with.

    Args:
        robot: The robot (fixed base).
        actuated: Names of the joints the motors drive; ``None``: those whose ``Dof.actuated`` is true.
        joint_friction: Plan with the joints' viscous damping (``False``: none).

    Raises:
        InputError: ``actuated`` naming unknown joints or none; ``joint_friction`` with a
            joint that has Coulomb friction (a rest-to-rest motion starts and ends stuck:
            stiction is not differentiable).
    """
    if actuated is None:
        actuated = [dof.joint for dof in robot.dofs if dof.actuated]
        if not actuated:
            raise InputError("actuated", "some joint an actuator drives", "a robot with no actuated joint")
    selection = actuation_matrix(robot, list(dict.fromkeys(actuated)) if not isinstance(actuated, str) else actuated)
    if not joint_friction:
        return Plant(selection, np.zeros(robot.nv))
    sliding = [dof.name for dof in robot.dofs if dof.friction > 0]
    if sliding:
        listed = ", ".join(quoted(name) for name in sliding[:8]) + (", …" if len(sliding) > 8 else "")
        raise InputError(
            "joint_friction",
            "False to plan joints with Coulomb friction (a rest-to-rest motion starts and ends at rest, where "
            "stiction is not differentiable)",
            f"True with Coulomb friction on {listed}",
        )
    return Plant(selection, robot.joint_damping.copy())


def _rk4(ca: Any, forward: Any, plant: Plant) -> Any:
    """One RK4 step of ``(q, v)`` with the input held: a casadi Function ``(x, u, dt) -> x``,
    the joint torque ``S u − b v`` (the plant's actuation and damping)."""
    nv, nu = plant.selection.shape
    x, u, dt = ca.SX.sym("x", 2 * nv), ca.SX.sym("u", nu), ca.SX.sym("dt")

    def f(state):
        torque = ca.mtimes(ca.DM(plant.selection), u) - ca.DM(plant.damping) * state[nv:]
        return ca.vertcat(state[nv:], forward(state[:nv], state[nv:], torque))

    k1 = f(x)
    k2 = f(x + dt / 2 * k1)
    k3 = f(x + dt / 2 * k2)
    k4 = f(x + dt * k3)
    return ca.Function("rk4", [x, u, dt], [x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)])


@dataclass
class Problem:
    """The NLP in casadi's Opti stack: its variables and the constraints told apart for a message."""

    opti: Any
    X: Any
    U: Any
    T: Any
    objective: Any
    bounds: dict[str, tuple[Any, np.ndarray]]


def shooting_problem(
    ca: Any, robot: Robot, plant: Plant, ends: tuple[np.ndarray, np.ndarray], duration: float, intervals: int, cost: Cost
) -> Problem:
    """Multiple shooting with limits and boundary conditions (see the module); ``ends``: start and goal.

    Args:
        ca: The ``casadi`` module.
        robot: The robot (fixed base).
        plant: The actuation and the damping planned with (:func:`planned_plant`).
        ends: Start and goal configurations, each shape (nq,), in [rad] / [m].
        duration: The motion's duration in [s] (``cost="time"``: its upper bound).
        intervals: Shooting intervals (``intervals + 1`` samples).
        cost: ``"effort"`` or ``"time"``.
    """
    (nv, nu), limits = plant.selection.shape, JointLimits(robot)
    opti = ca.Opti()
    X, U = opti.variable(2 * nv, intervals + 1), opti.variable(nu, intervals)
    T = opti.variable() if cost == "time" else duration
    step = _rk4(ca, casadi_functions(robot, frames=())["forward_dynamics"], plant).map(intervals)
    opti.subject_to(X[:, 1:] == step(X[:, :-1], U, T / intervals))
    rest = np.zeros(nv)
    opti.subject_to(X[:, 0] == np.concatenate([ends[0], rest]))
    opti.subject_to(X[:, -1] == np.concatenate([ends[1], rest]))
    driven = np.argmax(plant.selection, axis=0)  # the degree of freedom of each input
    effort = limits.effort[driven]
    bounds: dict[str, tuple[Any, np.ndarray]] = {}
    for kind, rows, lower, upper, names in (
        ("position", X[:nv, :], limits.lower, limits.upper, robot.joint_names),
        ("velocity", X[nv:, :], -limits.velocity, limits.velocity, robot.joint_names),
        ("effort", U, -effort, effort, [robot.joint_names[j] for j in driven]),
    ):
        for j in np.flatnonzero(np.isfinite(lower) | np.isfinite(upper)):
            constraint = opti.bounded(lower[j], rows[j, :], upper[j])
            opti.subject_to(constraint)
            bounds[f"the {kind} limit of {names[j]!r}"] = (constraint, np.array([lower[j], upper[j]]))
    scale = np.where(np.isfinite(effort), effort, 1.0)
    effort_term = ca.sumsqr(U / ca.repmat(scale, 1, intervals)) * (T / intervals)
    objective = effort_term if cost == "effort" else T + TIME_REGULARISATION * effort_term
    if cost == "time":
        opti.subject_to(opti.bounded(1e-3 * duration, T, duration))
        opti.set_initial(T, duration)
    opti.minimize(objective)
    return Problem(opti, X, U, T, objective, bounds)


def initial_guess(problem: Problem, robot: Robot, plant: Plant, ends: tuple[np.ndarray, np.ndarray], duration: float) -> None:
    """Straight from start to goal at constant speed, the inputs holding gravity as far as
    the actuated joints can (least squares, within the effort limits).

    Args:
        problem: The shooting problem (its CasADi ``Opti`` and decision variables).
        robot: The robot (fixed base).
        plant: The actuation and the damping planned with (:func:`planned_plant`).
        ends: Start and goal configurations, each shape (nq,), in [rad] / [m].
        duration: The motion's duration in [s].
    """
    start, goal = ends
    intervals = problem.X.shape[1] - 1
    s = np.linspace(0.0, 1.0, intervals + 1)
    q = start + s[:, None] * (goal - start)
    v = np.tile((goal - start) / duration, (intervals + 1, 1))
    effort = JointLimits(robot).effort[np.argmax(plant.selection, axis=0)]
    holding = np.atleast_2d(robot.gravity(q[:-1])) + v[:-1] * plant.damping
    u = np.clip(np.linalg.lstsq(plant.selection, holding.T, rcond=None)[0].T, -effort, effort)
    problem.opti.set_initial(problem.X, np.hstack([q, v]).T)
    problem.opti.set_initial(problem.U, u.T)


def scaled_guess(problem: Problem, plant: Plant, trajectory: Trajectory, duration: float) -> None:
    """A motion found over another duration as the start over ``duration``: a shorter one
    delayed (held at rest at the start first, which is the same motion), a longer one
    time-scaled (the same path, faster); either resampled on this problem's grid.

    Args:
        problem: The shooting problem (its CasADi ``Opti`` and decision variables).
        plant: The actuation and the damping planned with (:func:`planned_plant`).
        trajectory: The motion found over another duration (with ``tau``).
        duration: This problem's duration in [s].
    """
    intervals = problem.X.shape[1] - 1
    length = float(trajectory.t[-1])
    ratio = max(length / duration, 1.0)
    t = np.linspace(0.0, duration, intervals + 1) * ratio - max(duration - length, 0.0)
    source = np.clip(t, 0.0, length)
    q = np.column_stack([np.interp(source, trajectory.t, column) for column in trajectory.q.T])
    v = np.column_stack([np.interp(source, trajectory.t, column) for column in trajectory.v.T]) * ratio
    v[t < 0.0] = 0.0
    inputs = trajectory.tau @ plant.selection
    u = np.column_stack([np.interp(source[:-1], trajectory.t, column) for column in inputs.T])
    u[t[:-1] < 0.0] = inputs[0]  # holding the start, as the motion's first input does
    problem.opti.set_initial(problem.X, np.hstack([q, v]).T)
    problem.opti.set_initial(problem.U, u.T)
    if not isinstance(problem.T, float):
        problem.opti.set_initial(problem.T, min(length, duration))


def limiting(problem: Problem) -> str:
    """The bound with the largest multiplier at the last iterate ("" when none is active).

    Args:
        problem: The shooting problem (its CasADi ``Opti`` and decision variables). after a solve
    """
    worst, name = 0.0, ""
    for label, (constraint, _) in problem.bounds.items():
        dual = float(np.max(np.abs(problem.opti.debug.value(problem.opti.dual(constraint)))))
        if dual > worst:
            worst, name = dual, label
    return name if worst > 1e-6 else ""
