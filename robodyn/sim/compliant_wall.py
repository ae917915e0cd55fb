"""Force control against an environment of finite stiffness: a compliant flat wall.

:class:`CompliantWall` is a spring–damper contact of stated stiffness ``k`` [N/m] and
damping ``d`` [N s/m]: where a frame's origin is ``p = −n·(x − c)`` inside the plane
through ``c`` with outward normal ``n``, the wall pushes it along ``n`` with

    f = max(0, k p + d ṗ)      (it pushes, never pulls; zero outside, ``p ≤ 0``)

applied as the generalised force ``Jᵀ f n`` (``J``: the frame's position Jacobian).

:class:`ExplicitForce` — explicit force control with integral action on the measured
force ``f_m`` (the wall's ``f``; a force sensor):

    F_c  = F + Kf (F − f_m) + Ki ∫ (F − f_m) dt
    tau  = G + Jᵀ (−F_c n − Dn n nᵀ J v + Ω (Kp e − Kd J v))

(``Ω = I − n nᵀ``, ``e = x_d − x`` along the wall). At rest ``∫`` stops moving only where
``f_m = F``: the integral removes the steady error a model error (a wrong payload, an
unmodelled joint torque) leaves to the proportional law. For a 1-D normal motion of mass
``m`` against the wall the loop ``m s³ + Dn s² + k (1 + Kf) s + k Ki`` is stable for
``Ki < Dn (1 + Kf) / m``.

:func:`simulate_compliant` integrates ``(q, v, ∫)`` together with classical RK4 (the
integral is part of the state, so the four stages see one consistent controller).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import KW_ONLY, dataclass, field

import numpy as np
import pinocchio as pin

from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError, SimulationError
from robodyn.sim.force_control import scalar, unit_normal, vector

#: Most steps of one simulation.
MAX_STEPS = 100_000


def _frame(robot: Robot, frame_id: int, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The frame origin's position (3,) and position Jacobian (3, nv), world axes."""
    jacobian = pin.computeFrameJacobian(robot.model, robot.data, q, frame_id, pin.LOCAL_WORLD_ALIGNED)
    return robot.data.oMf[frame_id].translation.copy(), jacobian.reshape(6, robot.nv)[:3].copy()


@dataclass
class CompliantWall:
    """A flat spring–damper wall pushing a frame's origin (module docstring).

    Attributes:
        robot: The robot the wall acts on (the simulated one).
        frame: The frame whose origin touches the wall.
        normal: The wall's outward normal (toward the robot), world axes (3,).
        plane_point: A point of the wall's surface in [m] (3,).
        stiffness: ``k`` in [N/m] (> 0). damping: ``d`` in [N s/m] (≥ 0).
    """

    robot: Robot
    frame: str
    normal: np.ndarray | Sequence[float]
    plane_point: np.ndarray | Sequence[float]
    _: KW_ONLY
    stiffness: float
    damping: float = 0.0
    _frame_id: int = field(init=False, repr=False)
    _normal: np.ndarray = field(init=False, repr=False)
    _point: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self._frame_id = self.robot.frame_id(self.frame)
        self._normal = unit_normal(self.normal)
        self._point = vector(self.plane_point, "plane_point")
        self.stiffness = scalar(self.stiffness, "stiffness", "a finite stiffness > 0 in [N/m]")
        if not self.stiffness > 0:
            raise InputError("stiffness", "a finite stiffness > 0 in [N/m]", repr(self.stiffness))
        self.damping = scalar(self.damping, "damping", "a finite damping >= 0 in [N s/m]")

    def penetration(self, q: np.ndarray) -> float:
        """``p = −n·(x − c)`` in [m] (> 0: inside the wall).

        Args:
            q: Configuration, shape (nq,), in [rad] / [m].
        """
        position, _ = _frame(self.robot, self._frame_id, q)
        return float(-self._normal @ (position - self._point))

    def force(self, q: np.ndarray, v: np.ndarray) -> float:
        """The wall's push ``f = max(0, k p + d ṗ)`` in [N] (zero outside the wall).

        Args:
            q: Configuration, shape (nq,), in [rad] / [m].
            v: Velocity, shape (nv,), in [rad/s] / [m/s].
        """
        position, jacobian = _frame(self.robot, self._frame_id, q)
        depth = float(-self._normal @ (position - self._point))
        if depth <= 0:
            return 0.0
        return max(0.0, self.stiffness * depth - self.damping * float(self._normal @ (jacobian @ v)))

    def torques(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The generalised force ``Jᵀ f n`` of the wall's push, (nv,).

        Args:
            q: Configuration, shape (nq,), in [rad] / [m].
            v: Velocity, shape (nv,), in [rad/s] / [m/s].
        """
        _, jacobian = _frame(self.robot, self._frame_id, q)
        return jacobian.T @ (self.force(q, v) * self._normal)


@dataclass
class ExplicitForce:
    """Explicit force control with integral action along a wall's normal (module docstring).

    Attributes:
        model: The controller's model of the robot.
        frame: The frame pressing the wall; ``None``: the end effector.
        normal: The wall's outward normal, world axes (3,).
        force: The commanded normal force ``F`` in [N] (≥ 0).
        sensor: ``sensor(q, v) -> f_m``, the measured normal force in [N].
        motion: Target position in [m] (3,) of the frame; only its part along the wall is used.
        force_gain: ``Kf`` [1]. integral_gain: ``Ki`` [1/s]. normal_damping: ``Dn`` [N s/m].
        kp: Stiffness along the wall [N/m]. kd: Damping along the wall [N s/m].
    """

    model: Robot
    frame: str | None
    normal: np.ndarray | Sequence[float]
    force: float
    sensor: Callable[[np.ndarray, np.ndarray], float]
    motion: np.ndarray | Sequence[float]
    _: KW_ONLY
    force_gain: float = 1.0
    integral_gain: float = 20.0
    normal_damping: float = 100.0
    kp: float = 500.0
    kd: float = 50.0
    _frame_id: int = field(init=False, repr=False)
    _normal: np.ndarray = field(init=False, repr=False)
    _motion: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self.frame = self.model.task_frame(self.frame, "explicit force control")
        self._frame_id = self.model.frame_id(self.frame)
        self._normal = unit_normal(self.normal)
        self._motion = vector(self.motion, "motion")
        self.force = scalar(self.force, "force", "a finite normal force >= 0 in [N] (pressing)")
        for name in ("force_gain", "integral_gain", "normal_damping", "kp", "kd"):
            setattr(self, name, scalar(getattr(self, name), name, "a finite gain >= 0"))

    def integral_rate(self, q: np.ndarray, v: np.ndarray) -> float:
        """``d∫/dt = F − f_m`` in [N].

        Args:
            q: Configuration, shape (nq,), in [rad] / [m].
            v: Velocity, shape (nv,), in [rad/s] / [m/s].
        """
        return self.force - float(self.sensor(q, v))

    def torques(self, q: np.ndarray, v: np.ndarray, integral: float) -> np.ndarray:
        """``tau`` (nv,) at a state and the integral ``∫ (F − f_m) dt`` in [N s].

        Args:
            q: Configuration, shape (nq,), in [rad] / [m].
            v: Velocity, shape (nv,), in [rad/s] / [m/s].
            integral: The controller's state ``∫ (F − f_m) dt`` in [N s].
        """
        position, jacobian = _frame(self.model, self._frame_id, q)
        velocity, n = jacobian @ v, self._normal
        command = self.force + self.force_gain * (self.force - float(self.sensor(q, v))) + self.integral_gain * integral
        along = np.eye(3) - np.outer(n, n)
        wrench = (
            -command * n
            - self.normal_damping * n * (n @ velocity)
            + along @ (self.kp * (self._motion - position) - self.kd * velocity)
        )
        return self.model.gravity(q) + jacobian.T @ wrench


def simulate_compliant(
    robot: Robot,
    q0: np.ndarray,
    torques: Callable[[float, np.ndarray, np.ndarray, float], np.ndarray],
    wall: CompliantWall,
    *,
    duration: float,
    dt: float = 1e-3,
    integral_rate: Callable[[np.ndarray, np.ndarray], float] | None = None,
) -> dict[str, np.ndarray]:
    """RK4 of ``M v̇ + C v + G = tau + Jᵀ f n`` and ``d∫/dt`` from rest at ``q0``.

    Args:
        robot: The simulated robot.
        q0: Initial configuration (nq,).
        torques: ``torques(t, q, v, integral) -> tau`` (nv,).
        wall: The compliant wall.
        duration: Simulated time in [s].
        dt: Step in [s].
        integral_rate: ``d∫/dt`` of the controller's state (``None``: no state).

    Returns:
        ``{"t", "q", "v", "integral", "force"}``: stacked samples (force: the wall's push in [N]).

    Raises:
        InputError: Bad ``dt``, ``duration`` or ``q0``. SimulationError: A state that stops being finite.
    """
    if not (math.isfinite(dt) and dt > 0 and math.isfinite(duration) and duration > 0):
        raise InputError("dt", "a finite step > 0 and a finite duration > 0 in [s]", f"dt={dt!r}, duration={duration!r}")
    steps = round(duration / dt)
    if steps > MAX_STEPS:
        raise InputError("duration", f"at most {MAX_STEPS} steps of dt", f"{steps} steps")
    (q,), batch = robot.validate(q=q0)
    if batch:
        raise InputError("q0", "one configuration (a 1-D array)", f"shape {q.shape}")
    rate = integral_rate or (lambda q, v: 0.0)

    def derivative(t: float, q: np.ndarray, v: np.ndarray, z: float) -> tuple[np.ndarray, float]:
        tau = torques(t, q, v, z) + wall.torques(q, v)
        return robot.forward_dynamics(q, v, tau), rate(q, v)

    v, z = np.zeros(robot.nv), 0.0
    samples: dict[str, list] = {key: [] for key in ("t", "q", "v", "integral", "force")}
    for step in range(steps + 1):
        t = step * dt
        for key, value in zip(samples, (t, q, v, z, wall.force(q, v)), strict=True):
            samples[key].append(value)
        if step == steps:
            break
        a1, z1 = derivative(t, q, v, z)
        q2, v2, w2 = pin.integrate(robot.model, q, 0.5 * dt * v), v + 0.5 * dt * a1, z + 0.5 * dt * z1
        a2, z2 = derivative(t + 0.5 * dt, q2, v2, w2)
        q3, v3, w3 = pin.integrate(robot.model, q, 0.5 * dt * v2), v + 0.5 * dt * a2, z + 0.5 * dt * z2
        a3, z3 = derivative(t + 0.5 * dt, q3, v3, w3)
        q4, v4, w4 = pin.integrate(robot.model, q, dt * v3), v + dt * a3, z + dt * z3
        a4, z4 = derivative(t + dt, q4, v4, w4)
        q = pin.integrate(robot.model, q, dt / 6 * (v + 2 * v2 + 2 * v3 + v4))
        v, z = v + dt / 6 * (a1 + 2 * a2 + 2 * a3 + a4), z + dt / 6 * (z1 + 2 * z2 + 2 * z3 + z4)
        if not (np.isfinite(q).all() and np.isfinite(v).all()):
            raise SimulationError(t, step, robot.dofs[int(np.argmax(~np.isfinite(v)))].joint)
    return {key: np.array(value) for key, value in samples.items()}


__all__ = ["CompliantWall", "ExplicitForce", "simulate_compliant"]
