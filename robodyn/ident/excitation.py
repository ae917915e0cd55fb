"""Exciting trajectories: periodic finite Fourier series that make the base regressor well
conditioned (Swevers et al., 1997).

Joint ``i`` follows, with the fundamental ``ω = 2π / T`` (``T`` the period) and ``L``
harmonics,

    q_i(t) = q0_i + Σ_l  a_il / (l ω) · sin(l ω t) − b_il / (l ω) · cos(l ω t)
    v_i(t) = Σ_l  a_il cos(l ω t) + b_il sin(l ω t)
    a_i(t) = Σ_l  l ω (−a_il sin(l ω t) + b_il cos(l ω t))

so the motion is periodic (it starts and ends in the same state, and repeats smoothly).
``q``, ``v`` and ``a`` are linear in the coefficients ``x = (q0, a, b)``, so the limits —
positions within ``[lower + margin, upper − margin]`` (``margin`` a fraction of the range),
``|v| ≤ velocity limit``, ``|a| ≤ acceleration limit`` — are linear inequalities at
``constraint_points`` instants of the period (ranges from
:func:`robodyn.ident.base.joint_ranges`: unlimited joints are kept within [−π, π]). The objective is ``log cond(W_b)``, the
condition number of the base regressor stacked at ``objective_points`` instants, minimised
by scipy's SLSQP from a random feasible start.

The result is the best *feasible* point the optimiser visited (its start included):
SLSQP's last point may break a limit even when earlier iterates did not, so every iterate
is kept and the one with the lowest condition number among those within the limits is
returned. When none improves on the start (``Excitation.improved`` is false) a one-line
:class:`ExcitationNotImprovedWarning` says so; the trajectory is then the random start,
within the limits but not optimised (more ``iterations``, another ``seed`` or fewer
``harmonics`` may help).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
import scipy.optimize

from robodyn.dynamics.robot import Robot
from robodyn.exceptions import IdentificationError, InputError, RobodynWarning
from robodyn.ident.base import BaseParameters, base_parameters, joint_ranges

#: Velocity and acceleration limits used when the URDF gives none, in [rad/s] or [m/s]
#: and [rad/s²] or [m/s²] (per second: prismatic joints use a tenth).
DEFAULT_VELOCITY = 2.0
DEFAULT_ACCELERATION = 5.0
#: The constraints at the sampled instants use this fraction of the limits, so that the
#: motion between them stays within the limits (checked on a 10x finer grid).
SAFETY = 0.99
#: A point counts as within the linear limits when it breaks none by more than this.
FEASIBLE = 1e-9


class ExcitationNotImprovedWarning(RobodynWarning):
    """The optimiser found no feasible point better conditioned than its random start."""


@dataclass(frozen=True)
class Excitation:
    """A periodic excitation trajectory (module docstring).

    Attributes:
        robot: Name of the robot.
        joint_names: Its joints.
        period: ``T`` in [s].
        offset: ``q0``, shape (nv,).
        sine, cosine: Coefficients ``a`` and ``b``, shape (nv, L), in [rad/s] or [m/s].
        condition: ``cond(W_b)`` at the objective points.
        initial_condition: The same for the start of the optimisation.
        velocity_limit, acceleration_limit: The limits respected, shape (nv,).
        improved: Whether the optimiser improved on its start (false: the trajectory is
            the unoptimised random start).
    """

    robot: str
    joint_names: list[str]
    period: float
    offset: np.ndarray
    sine: np.ndarray
    cosine: np.ndarray
    condition: float
    initial_condition: float
    velocity_limit: np.ndarray
    acceleration_limit: np.ndarray
    improved: bool = True

    def evaluate(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``q, v, a`` at times ``t`` (M,), each (M, nv).

        Args:
            t: Times in [s], shape (M,).
        """
        return _series(self.offset, self.sine, self.cosine, 2 * np.pi / self.period, np.asarray(t, dtype=float))

    def sample(self, robot: Robot, *, rate: float = 100.0, periods: int = 1) -> tuple[np.ndarray, ...]:
        """``t, q, v, a, tau`` sampled at ``rate`` [Hz] over ``periods`` periods, with
        ``tau`` the robot's inverse dynamics along it, its joints' damping and friction
        included (``joint_friction=True``: what the robot needs to follow it), shapes (M,)
        and (M, nv); the columns of :class:`robodyn.trajectory.Trajectory`.

        Args:
            robot: The robot that follows the motion.
            rate: Samples per second in [Hz].
            periods: Number of periods sampled, at least 1.
        """
        if not (np.isfinite(rate) and rate > 0) or periods < 1:
            raise InputError("rate and periods", "a positive rate in [Hz] and at least one period", f"{rate!r}, {periods!r}")
        t = np.arange(0.0, periods * self.period, 1.0 / rate)
        q, v, a = self.evaluate(t)
        return t, q, v, a, robot.inverse_dynamics(q, v, a, joint_friction=True)


def _series(
    offset: np.ndarray, sine: np.ndarray, cosine: np.ndarray, omega: float, t: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    harmonics = np.arange(1, sine.shape[1] + 1)
    phase = omega * np.outer(t, harmonics)  # (M, L)
    s, c = np.sin(phase), np.cos(phase)
    lw = harmonics * omega
    q = offset + (s / lw) @ sine.T - (c / lw) @ cosine.T
    v = c @ sine.T + s @ cosine.T
    a = (-s * lw) @ sine.T + (c * lw) @ cosine.T
    return q, v, a


def _basis(t: np.ndarray, nv: int, harmonics: int, omega: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Matrices mapping ``x = (q0, a.ravel(), b.ravel())`` to q, v, a at ``t``: (M·nv, dim)."""
    dim = nv * (1 + 2 * harmonics)
    rows = []
    for k in range(dim):
        x = np.zeros(dim)
        x[k] = 1.0
        rows.append(np.stack(_series(*_unpack(x, nv, harmonics), omega, t)))
    basis = np.stack(rows, axis=-1)  # (3, M, nv, dim)
    return basis[0].reshape(-1, dim), basis[1].reshape(-1, dim), basis[2].reshape(-1, dim)


def _unpack(x: np.ndarray, nv: int, harmonics: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    offset = x[:nv]
    sine = x[nv : nv + nv * harmonics].reshape(nv, harmonics)
    cosine = x[nv + nv * harmonics :].reshape(nv, harmonics)
    return offset, sine, cosine


def _per_joint(robot: Robot, name: str, values) -> np.ndarray:
    """One limit for every joint, or one a joint, as (nv,); another count is refused (by name)."""
    limits = np.asarray(values, dtype=float)
    if limits.size not in (1, robot.nv) or limits.ndim > 1:
        joints = ", ".join(robot.joint_names)
        raise InputError(name, f"one value or {robot.nv} ({joints})", f"{limits.size} values")
    return np.broadcast_to(limits.reshape(-1), (robot.nv,)).copy()


def _limits(robot: Robot, velocity, acceleration, margin):
    prismatic = np.array([joint.type == "prismatic" for joint in robot.joints])
    scale = np.where(prismatic, 0.1, 1.0)
    urdf_velocity = np.array([joint.velocity for joint in robot.joints])
    default_velocity = np.where(np.isfinite(urdf_velocity) & (urdf_velocity > 0), urdf_velocity, DEFAULT_VELOCITY * scale)
    velocity_limit = default_velocity if velocity is None else _per_joint(robot, "velocity_limit", velocity)
    acceleration_limit = (
        DEFAULT_ACCELERATION * scale if acceleration is None else _per_joint(robot, "acceleration_limit", acceleration)
    )
    for name, values in (("velocity_limit", velocity_limit), ("acceleration_limit", acceleration_limit)):
        if not (np.isfinite(values).all() and (values > 0).all()):
            raise InputError(name, f"positive finite limits ({robot.nv} or one)", repr(values.tolist()))
    lower, upper = joint_ranges(robot)
    span = upper - lower
    lower, upper = lower + margin * span, upper - margin * span
    return lower, upper, velocity_limit, acceleration_limit


def excite(
    robot: Robot,
    *,
    duration: float = 10.0,
    harmonics: int = 5,
    velocity_limit: float | np.ndarray | None = None,
    acceleration_limit: float | np.ndarray | None = None,
    margin: float = 0.05,
    objective_points: int = 60,
    constraint_points: int = 200,
    iterations: int = 60,
    seed: int = 0,
    base: BaseParameters | None = None,
) -> Excitation:
    """An exciting periodic trajectory for ``robot`` (module docstring).

    Args:
        robot: A fixed-base robot.
        duration: The period ``T`` in [s].
        harmonics: ``L``, the number of harmonics per joint.
        velocity_limit, acceleration_limit: Per joint or one for all; default the URDF's
            velocity limits (``DEFAULT_VELOCITY`` when it has none) and
            ``DEFAULT_ACCELERATION`` (a tenth of both, in m, for prismatic joints).
        margin: Fraction of each position range kept free at both ends.
        objective_points, constraint_points: Instants where the condition number and
            the limits are evaluated.
        iterations: Largest number of SLSQP iterations.
        seed: Seed of the random start.
        base: Base parameter set whose regressor is conditioned (default all bodies).

    Raises:
        InputError: For bad options or a floating-base robot.
        IdentificationError: If no feasible start is found or the result violates a limit.
    """
    if robot.floating_base:
        raise InputError("robot", "a fixed-base robot (a floating base cannot follow a joint-space Fourier series)", robot.name)
    if not (np.isfinite(duration) and duration > 0) or harmonics < 1 or not 0 <= margin < 0.5:
        raise InputError(
            "duration, harmonics, margin", "T > 0 s, L ≥ 1, 0 ≤ margin < 0.5", f"{duration!r}, {harmonics!r}, {margin!r}"
        )
    lower, upper, v_max, a_max = _limits(robot, velocity_limit, acceleration_limit, margin)  # refused before any work
    base = base_parameters(robot) if base is None else base
    nv = robot.nv
    omega = 2 * np.pi / duration
    t_constraint = np.linspace(0.0, duration, constraint_points, endpoint=False)
    t_objective = np.linspace(0.0, duration, objective_points, endpoint=False)
    Bq, Bv, Ba = _basis(t_constraint, nv, harmonics, omega)
    tile = lambda values: np.tile(values, constraint_points)  # noqa: E731
    # A x ≤ b  <=>  b − A x ≥ 0
    A = np.vstack([Bq, -Bq, Bv, -Bv, Ba, -Ba])
    inner = 0.5 * (upper - lower) * (1 - SAFETY)  # between the instants the motion may overshoot a little
    v_bound, a_bound = SAFETY * v_max, SAFETY * a_max
    b = np.concatenate([tile(upper - inner), -tile(lower + inner), tile(v_bound), tile(v_bound), tile(a_bound), tile(a_bound)])

    def log_condition(x: np.ndarray) -> float:
        q, v, a = _series(*_unpack(x, nv, harmonics), omega, t_objective)
        w = base.regressor(q, v, a).reshape(-1, base.count)
        eigenvalues = np.linalg.eigvalsh(w.T @ w)  # squared singular values, ascending
        return float(0.5 * np.log(eigenvalues[-1] / max(eigenvalues[0], 1e-32 * eigenvalues[-1], 1e-300)))

    rng = np.random.default_rng(seed)
    x0 = np.concatenate([(lower + upper) / 2, rng.standard_normal(2 * nv * harmonics)])
    moving = A[:, nv:] @ x0[nv:]
    room = b - A[:, :nv] @ x0[:nv]
    if not (room > 0).all():
        raise IdentificationError(robot.name, "the joint limits leave no room for motion")
    x0[nv:] *= 0.5 * float(np.min(room / np.maximum(moving, 1e-300), initial=np.inf, where=moving > 0))
    initial = log_condition(x0)
    visited = [x0]
    result = scipy.optimize.minimize(
        log_condition,
        x0,
        method="SLSQP",
        constraints=[{"type": "ineq", "fun": lambda x: b - A @ x, "jac": lambda x: -A}],
        options={"maxiter": iterations, "ftol": 1e-6},
        callback=lambda xk: visited.append(np.array(xk, dtype=float)),
    )
    visited.append(np.asarray(result.x, dtype=float))
    x, best = _best_feasible(visited, lambda x: bool(np.all(b - A @ x >= -FEASIBLE)), log_condition)
    improved = best < initial
    if not improved:
        warnings.warn(
            f"{robot.name}: the optimiser found nothing better conditioned than its random start in {iterations} "
            "iterations; the excitation is that start, not optimised (try another seed or more iterations)",
            ExcitationNotImprovedWarning,
            stacklevel=2,
        )
    offset, sine, cosine = _unpack(x, nv, harmonics)
    excitation = Excitation(
        robot.name, list(robot.joint_names), float(duration), offset, sine, cosine,
        float(np.exp(best)), float(np.exp(initial)), v_max, a_max, improved,
    )  # fmt: skip
    _check_limits(robot, excitation, lower, upper)
    return excitation


def _best_feasible(visited: list[np.ndarray], feasible, objective) -> tuple[np.ndarray, float]:
    """The feasible point of ``visited`` (the start first, then the iterates) with the
    lowest objective, and that value; the start wins ties."""
    best_x, best = visited[0], objective(visited[0])
    for x in visited[1:]:
        if np.all(np.isfinite(x)) and feasible(x):
            value = objective(x)
            if value < best:
                best_x, best = x, value
    return best_x, best


def _check_limits(robot: Robot, excitation: Excitation, lower, upper) -> None:
    """Refuse a trajectory that leaves the limits between the constraint instants."""
    t = np.linspace(0.0, excitation.period, 10 * 200, endpoint=False)
    q, v, a = excitation.evaluate(t)
    tolerance = 1e-12
    span = np.maximum(upper - lower, 1e-9)
    worst = {
        "position": float(np.max(np.maximum(lower - q, q - upper) / span)),
        "velocity": float(np.max(np.abs(v) / excitation.velocity_limit - 1)),
        "acceleration": float(np.max(np.abs(a) / excitation.acceleration_limit - 1)),
    }
    for kind, excess in worst.items():
        if excess > tolerance:
            raise IdentificationError(
                robot.name, f"the excitation exceeds a {kind} limit by {100 * excess:.2g} % between samples"
            )


__all__ = ["Excitation", "ExcitationNotImprovedWarning", "excite"]
