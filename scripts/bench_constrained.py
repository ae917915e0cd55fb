"""The four-bar's constrained step before and after issue 40's follow-up, measured in one run.

"Before" is the constrained dynamics as it was (each constraint's ends from per-end
Pinocchio frame calls and Python 3-vector algebra, the rows stacked by a list, ``M⁻¹`` by
``np.linalg.solve`` and the Delassus matrix by ``np.linalg.eigh`` every call), kept here
verbatim and swapped into :mod:`robodyn.dynamics.constrained` for the "before" timings,
with the simulation's per-step check of its state as it was;
"after" is the module as it is. Both run :func:`robodyn.sim.constrained.constrained_rk4_step`
(RK4 and the projection) on examples/four_bar.urdf with its constraints file, alternated,
CPU time, medians; the two paths' states are compared after the same steps.
"""

from __future__ import annotations

import contextlib
import os
import statistics
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import pinocchio as pin

import robodyn
from robodyn.constraints.algebra import End, EndKinematics, stack, world_end
from robodyn.constraints.files import read_constraints
from robodyn.dynamics import constrained
from robodyn.exceptions import SingularMassMatrixError
from robodyn.sim import constrained as sim_constrained
from robodyn.sim.constrained import simulate_constrained

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def _skew(a: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


def _before_kinematics(robot, v: np.ndarray) -> Callable[[End], EndKinematics]:
    model, data, frames, nv = robot.model, robot.handle.data, robot.handle.frames, robot.nv

    def kinematics(end: End) -> EndKinematics:
        if end.link is None:
            return world_end(end, nv)
        index = frames[end.link]
        placement = data.oMf[index]
        lever = placement.rotation @ end.position
        jacobian = pin.getFrameJacobian(model, data, index, pin.LOCAL_WORLD_ALIGNED).reshape(6, nv)
        angular = jacobian[3:]
        omega = angular @ v
        acceleration = pin.getFrameClassicalAcceleration(model, data, index, pin.LOCAL_WORLD_ALIGNED)
        alpha = acceleration.angular.copy()
        return EndKinematics(
            placement.translation + lever,
            placement.rotation @ end.rotation,
            jacobian[:3] - _skew(lever) @ angular,
            angular.copy(),
            acceleration.linear + _cross(alpha, lever) + _cross(omega, _cross(omega, lever)),
            alpha,
        )

    return kinematics


def before_state_rows(robot, bounds, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, ...]:
    """The rows as they were computed before."""
    model, data = robot.model, robot.handle.data
    pin.computeJointJacobians(model, data, q)
    pin.forwardKinematics(model, data, q, v, np.zeros(robot.nv))
    pin.updateFramePlacements(model, data)
    return stack(bounds, _before_kinematics(robot, v), robot.nv)


def before_solve_kkt(mass, force, jacobian, drift, name="robot") -> tuple[np.ndarray, np.ndarray]:
    """The KKT solve as it was before."""
    try:
        solved = np.linalg.solve(mass, np.column_stack([force, jacobian.T]))
    except np.linalg.LinAlgError:
        raise SingularMassMatrixError(name, []) from None
    free, response = solved[:, 0], solved[:, 1:]
    if not len(drift):
        return free, np.zeros(0)
    delassus = jacobian @ response
    values, vectors = np.linalg.eigh(0.5 * (delassus + delassus.T))
    keep = values > constrained.RANK_TOLERANCE * max(float(values[-1]), 1e-300)
    target = -(drift + jacobian @ free)
    multipliers = vectors[:, keep] @ ((vectors[:, keep].T @ target) / values[keep])
    return free + response @ multipliers, multipliers


def before_forward_dynamics(robot, bounds, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The inner loop's constrained dynamics as they were (nothing reused between calls)."""
    mass, bias = robot.mass_matrix(q), robot.nonlinear_effects(q, v)
    _, jacobian, drift = before_state_rows(robot, bounds, q, v)
    return before_solve_kkt(mass, tau - bias, jacobian, drift, robot.name)


@contextlib.contextmanager
def before() -> Iterator[None]:
    """:mod:`robodyn.dynamics.constrained`'s inner-loop functions as they were, and the
    simulation's step checking its state and binding its constraints again every step."""
    names = ("state_rows", "solve_kkt", "forward_dynamics_unchecked")
    saved = [getattr(constrained, name) for name in names]
    step = sim_constrained._step

    def checked_step(robot, bounds, q, v, tau, dt, t):
        constrained.bound(robot, None)
        (q, v), _ = robot.validate(q=q, v=v)
        return step(robot, bounds, q, v, tau, dt, t)

    for name, function in zip(names, (before_state_rows, before_solve_kkt, before_forward_dynamics), strict=True):
        setattr(constrained, name, function)
    sim_constrained._step = checked_step
    try:
        yield
    finally:
        for name, function in zip(names, saved, strict=True):
            setattr(constrained, name, function)
        sim_constrained._step = step


def bench_constrained_step(quick: bool) -> list[dict]:
    """The four-bar's constrained simulation (RK4, projection, the samples' λ and residual)
    per step, before vs after, CPU time, alternated, medians."""
    robot = robodyn.load(EXAMPLES / "four_bar.urdf", constraints=read_constraints(EXAMPLES / "four_bar_constraints.yaml"))
    duration, repeats = (0.05, 5) if quick else (0.3, 9)
    steps = round(duration / 1e-3)

    def run() -> np.ndarray:
        return simulate_constrained(robot, np.array([0.3, 0.0, 0.0]), np.array([2.0, 0.0, 0.0]), duration=duration).trajectory.q

    times: dict[str, list[float]] = {"before": [], "after": []}
    ends: dict[str, np.ndarray] = {}
    for _ in range(repeats):
        for side in ("before", "after"):
            with before() if side == "before" else contextlib.nullcontext():
                began = time.process_time()
                ends[side] = run()
                times[side].append((time.process_time() - began) / steps)
    ratios = [b / a for b, a in zip(times["before"], times["after"], strict=True)]
    return [
        {
            "robot": "four_bar (examples/four_bar.urdf + its constraints file: 3 joints, a 3-row loop, 1 row redundant)",
            "run": f"simulate_constrained, {steps} steps of 1 ms (RK4, projection, λ and |Φ| each sample)",
            "before_us_per_step": round(statistics.median(times["before"]) * 1e6, 1),
            "after_us_per_step": round(statistics.median(times["after"]) * 1e6, 1),
            "speedup": round(statistics.median(ratios), 2),
            "max_q_difference": float(np.abs(ends["before"] - ends["after"]).max()),
            "load_average": round(os.getloadavg()[0], 2),
        }
    ]


__all__ = ["before", "bench_constrained_step"]
