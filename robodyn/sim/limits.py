"""Joint limits in simulation: what a run did to them, and how ``enforce`` keeps them.

Three modes (``simulate(..., limits=...)``, ``robodyn simulate --limits``):

- ``"warn"`` (default): the dynamics are unconstrained; every position, velocity and
  effort limit that the run broke is reported (:func:`limit_violations`: joint, first
  time, worst value, limit) and :func:`robodyn.simulate` emits one
  :class:`~robodyn.exceptions.JointLimitWarning`.
- ``"enforce"``: the model of a joint with stops and current-limited motors —
  the applied torque is saturated at the effort limit, ``tau = clip(tau_c, −effort,
  effort)`` (at every evaluation of the controller, so RK4's stages see it too), and
  after every step a joint beyond a position limit is put back on it and its velocity
  into the limit is set to zero (a perfectly plastic stop: no bounce, no penetration;
  the velocity away from the limit is kept). Velocity limits are reported, not enforced.
  On a ground the position limits are instead one-sided rows of the contact problem
  (:mod:`robodyn.sim.contact_limits`: stops solved with the contacts, their torques
  reported).
- ``"ignore"``: neither enforced nor reported.

Limits that a URDF leaves unspecified do not count: infinite ones, placeholder position
limits (magnitude ≥ 1e3, :data:`robodyn.dynamics.robot.PLACEHOLDER_LIMIT`), empty position
ranges (``lower == upper`` on a moving joint), and effort or velocity limits of zero (the
URDF's "unknown"). A floating base has no limits.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from robodyn.common.text import printable
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError
from robodyn.trajectory import Trajectory

#: What a run does with joint limits (see the module docstring).
LimitMode = Literal["warn", "enforce", "ignore"]
LIMIT_MODES: tuple[LimitMode, ...] = ("warn", "enforce", "ignore")
#: Slack before a value counts as beyond its limit: absolute, plus relative to the limit.
TOLERANCE = 1e-9


def check_mode(limits: str) -> str:
    """Refuse an unknown limits mode.

    Args:
        limits: The limits mode, one of :data:`LIMIT_MODES`.
    """
    if limits not in LIMIT_MODES:
        raise InputError("limits", f"one of {', '.join(LIMIT_MODES)}", repr(limits))
    return limits


@dataclass(frozen=True)
class LimitViolation:
    """One limit a run broke.

    Attributes:
        joint: Joint name.
        quantity: ``"position"``, ``"velocity"`` or ``"effort"``.
        side: ``"lower"`` or ``"upper"`` for positions; ``"magnitude"`` otherwise.
        first_time: When the value first went beyond the limit, in [s].
        worst: The value furthest beyond the limit (signed), in ``unit``.
        limit: The limit it broke (signed like ``worst``), in ``unit``.
        unit: ``"rad"``, ``"m"``, ``"rad/s"``, ``"m/s"``, ``"N m"`` or ``"N"``.
    """

    joint: str
    quantity: str
    side: str
    first_time: float
    worst: float
    limit: float
    unit: str

    def text(self) -> str:
        """E.g. ``"panda_joint2 effort 474 N m beyond ±87 N m from t = 0 s"``."""
        bound = f"{self.limit:.4g}" if self.side != "magnitude" else f"±{abs(self.limit):.4g}"
        return (
            f"{printable(self.joint)} {self.quantity} {self.worst:.4g} {self.unit} beyond {bound} {self.unit} "
            f"from t = {self.first_time:.4g} s"
        )

    def as_dict(self) -> dict:
        """JSON-ready, units in the keys' companion ``unit``."""
        return {
            "joint": self.joint,
            "quantity": self.quantity,
            "side": self.side,
            "first_time_s": float(f"{self.first_time:.12g}"),  # t = step × dt, without its rounding noise
            "worst": self.worst,
            "limit": self.limit,
            "unit": self.unit,
        }


class JointLimits:
    """The limits of a robot's joints as arrays over the coordinates they apply to.

    Attributes:
        lower, upper: Position limits of the joint coordinates of ``q`` (the floating
            base's seven excluded), ±inf where unlimited; shape (nj,).
        velocity, effort: Limits per velocity coordinate (inf where unlimited), (nv,).
    """

    def __init__(self, robot: Robot) -> None:
        self.robot = robot
        self.lower, self.upper = robot.physical_limits()
        self.joints = robot.joints[1:] if robot.floating_base else robot.joints
        velocity = np.array([dof.velocity_limit for dof in robot.dofs], dtype=float)  # a base's: inf
        effort = np.array([dof.effort_limit for dof in robot.dofs], dtype=float)
        self.velocity = np.where(velocity > 0, velocity, np.inf)
        self.effort = np.where(effort > 0, effort, np.inf)
        self._q_start = robot.nq - len(self.joints)
        self._v_start = robot.nv - len(self.joints)
        self._has_stops = bool(np.isfinite(self.lower).any() or np.isfinite(self.upper).any())
        self._has_efforts = bool(np.isfinite(self.effort).any())

    def saturate(self, tau: np.ndarray) -> np.ndarray:
        """Torques clipped at the effort limits, shape (nv,).

        Args:
            tau: Torques, shape (nv,), in [N m] / [N].
        """
        return np.clip(tau, -self.effort, self.effort) if self._has_efforts else tau

    def stop(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Put joints beyond a position limit back on it, with no velocity into it.

        Args:
            q: Configuration, shape (nq,), in [rad] / [m].
            v: Velocity, shape (nv,), in [rad/s] / [m/s].
        """
        if not self._has_stops:
            return q, v
        joints = q[self._q_start :]
        below, above = joints < self.lower, joints > self.upper
        if not (below.any() or above.any()):
            return q, v
        q, v = q.copy(), v.copy()
        q[self._q_start :] = np.clip(joints, self.lower, self.upper)
        speeds = v[self._v_start :]
        speeds[(below & (speeds < 0)) | (above & (speeds > 0))] = 0.0
        return q, v

    def violations(self, trajectory: Trajectory) -> list[LimitViolation]:
        """Every limit the trajectory broke, by joint then quantity (units from ``robot.dofs``).

        Each column's comparisons, first times and worst samples come from whole-array
        operations (one per quantity, every joint at once); a violation is then read off its
        column.

        Args:
            trajectory: A trajectory of the robot (its ``tau`` may be ``None``: efforts then unchecked).
        """
        if len(trajectory.t) == 0:
            return []
        # one row a joint (contiguous: the reductions run along rows)
        positions = np.ascontiguousarray(trajectory.q[:, self._q_start :].T)
        velocities = np.ascontiguousarray(trajectory.v[:, self._v_start :].T)
        torques = (
            np.zeros_like(velocities) if trajectory.tau is None else np.ascontiguousarray(trajectory.tau[:, self._v_start :].T)
        )
        speed, effort = self.velocity[self._v_start :], self.effort[self._v_start :]
        lower, upper = self.lower[:, None], self.upper[:, None]
        checks = [  # quantity, side, values compared, signed values, limits, beyond, worst sample
            ("position", "lower", positions, None, self.lower, positions < lower - _slack(lower), positions.argmin(axis=1)),
            ("position", "upper", positions, None, self.upper, positions > upper + _slack(upper), positions.argmax(axis=1)),
            ("velocity", "magnitude", np.abs(velocities), velocities, speed, None, None),
            ("effort", "magnitude", np.abs(torques), torques, effort, None, None),
        ]
        columns = []
        for quantity, side, values, signed, limits, beyond, worst in checks:
            if beyond is None:
                beyond, worst = values > limits[:, None] + _slack(limits[:, None]), values.argmax(axis=1)
            hit = beyond.any(axis=1) & np.isfinite(limits)
            if hit.any():
                rows = np.flatnonzero(hit)
                times = trajectory.t[beyond[rows].argmax(axis=1)].tolist()
                worsts = values[rows, worst[rows]] if signed is None else signed[rows, worst[rows]]
                found_here = zip(times, worsts.tolist(), limits[rows].tolist(), strict=True)
                columns.append((quantity, side, dict(zip(rows.tolist(), found_here, strict=True))))
        found = []
        for index, dof in enumerate(self.robot.dofs[self._v_start :]):
            units = {"position": dof.position_unit, "velocity": dof.velocity_unit, "effort": dof.effort_unit}
            for quantity, side, broken in columns:
                if index in broken:
                    time, worst, limit = broken[index]
                    bound = limit if side != "magnitude" else math.copysign(limit, worst)
                    found.append(LimitViolation(dof.joint, quantity, side, time, worst, bound, units[quantity]))
        return found


def _slack(limits: np.ndarray) -> np.ndarray:
    """The tolerance a value may pass each limit by before it counts (relative and absolute)."""
    return TOLERANCE * (1.0 + np.abs(limits))


def limit_violations(robot: Robot, trajectory: Trajectory) -> list[LimitViolation]:
    """Every position, velocity and effort limit a trajectory of ``robot`` broke.

    Each violation names the joint, the first time in [s], the worst value and the limit.

    Args:
        robot: The robot whose limits are checked.
        trajectory: A trajectory of ``robot``.
    """
    return JointLimits(robot).violations(trajectory)


def warning_text(robot: str, violations: list[LimitViolation], *, shown: int = 4) -> str:
    """One line summarising the violations (the first ``shown`` in full).

    Args:
        robot: The robot's name.
        violations: The violations (:func:`limit_violations`).
        shown: How many are listed in full.
    """
    listed = "; ".join(violation.text() for violation in violations[:shown])
    more = f"; and {len(violations) - shown} more" if len(violations) > shown else ""
    return f"{printable(robot)}: {len(violations)} joint limit violation{'s' if len(violations) != 1 else ''}: {listed}{more}"
