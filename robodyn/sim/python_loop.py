"""The integration loop in Python: RK4 or semi-implicit Euler, stage by stage.

The Pinocchio backend (:mod:`robodyn.sim.pinocchio_loop`) runs it over Pinocchio's ABA; the
compiled backend over the compiled forward dynamics when a Python controller is evaluated
at every stage. The rules it shares with the C loop are :mod:`robodyn.compiled.loop_rules`'.

On a floating base, RK4 combines its stages' velocities in the tangent space at the step's
start without the dexp correction of Runge–Kutta–Munthe-Kaas, so its error in the base's
orientation falls as dt² (solo12, 1 s at 1 kHz: momentum drift 3e-7 relative); joints keep
fourth order. A state that stops being finite ends the run with a :class:`SimulationError`
saying when and which joint, or a :class:`SingularMassMatrixError` when the mass matrix is
singular there (massless moving bodies: no step size helps).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from robodyn.compiled.loop_rules import failing_joint
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import (
    ControllerFailedError,
    InputError,
    NonFiniteResultError,
    SimulationError,
    SingularMassMatrixError,
)
from robodyn.sim.joint_friction import JointFriction
from robodyn.sim.limits import JointLimits
from robodyn.sim.observer import MomentumObserver
from robodyn.sim.plan import Controller

#: ``a(t, q, v, tau)``: the plant's accelerations under a torque.
Forward = Callable[[float, np.ndarray, np.ndarray, np.ndarray], np.ndarray]
#: Steps between two finiteness checks of the state (a divergence is located exactly).
CHECK_EVERY = 64


class StageDivergedError(Exception):
    """An integrator stage reached a non-finite state (a divergence inside the step), before
    the controller was asked for a torque there."""

    def __init__(self, joint: str) -> None:
        super().__init__(joint)
        self.joint = joint


class Stepper:
    """One integration step of ``(q, v)`` under a controller: RK4 or semi-implicit Euler.

    Args:
        robot: The plant (its configuration space: a floating base moves on SE(3)).
        forward: The plant's ``a(t, q, v, tau)``.
        controller: ``None`` when passive.
        hold: The step's torque holds through its stages (sampled, or passive).
        rk4: Classical Runge–Kutta, else semi-implicit Euler.
        observer: Fed every sample, or ``None``.
        every: Steps between two samples of a held controller.
        friction: The joints' damping and stick–slip friction, or ``None``.
    """

    def __init__(
        self,
        robot: Robot,
        forward: Forward,
        controller: Controller | None,
        *,
        hold: bool,
        rk4: bool,
        observer: MomentumObserver | None = None,
        every: int = 1,
        friction: JointFriction | None = None,
    ) -> None:
        self.controller = controller
        self.observer = observer
        self.forward = forward if friction is None else friction.wrap(forward)
        self.every = every  # steps between two samples of the controller at a step's start
        self.friction = friction
        plant, held = self.forward, controller is None or hold  # held: the step's torque (zero when passive) holds

        def accelerate(t: float, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
            finite = math.isfinite(q.dot(q)) and math.isfinite(v.dot(v))  # cheap: finite squares, every entry finite
            if not finite and not (np.isfinite(q).all() and np.isfinite(v).all()):  # blew up within the step (held too)
                raise StageDivergedError(failing_joint(robot.joint_names, q, v))
            return plant(t, q, v, tau if held else np.asarray(controller(t, q, v), dtype=float))  # type: ignore[misc]

        self.accelerate = accelerate
        # Fixed base: q moves by plain addition (no call); floating base: on SE(3).
        self.integrate = robot.integrate if robot.floating_base else None
        self.rk4 = rk4
        self.zero = np.zeros(robot.nv)

    def torque(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The controller's torque at the step's start, shape (nv,) (zero when passive).

        Args:
            t: Time in [s].
            q: Configuration, shape (nq,), in [rad] / [m].
            v: Velocity, shape (nv,), in [rad/s] / [m/s].
        """
        return self.zero if self.controller is None else np.asarray(self.controller(t, q, v), dtype=float)

    def observe(self, t: float, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> None:
        """Feed the observer (if any) a sample and the torque applied there.

        Args:
            t: Time in [s].
            q: Configuration, shape (nq,), in [rad] / [m].
            v: Velocity, shape (nv,), in [rad/s] / [m/s].
            tau: The applied torques, shape (nv,), in [N m] / [N].
        """
        if self.observer is not None:
            self.observer.update(t, q, v, tau)

    def advance(self, t: float, dt: float, q: np.ndarray, v: np.ndarray, tau: np.ndarray, a: np.ndarray):
        """:meth:`step`, cut at the joints' stick-slip events when there is joint friction.

        Args:
            t: Time in [s].
            dt: Step in [s].
            q: Configuration, shape (nq,), in [rad] / [m].
            v: Velocity, shape (nv,), in [rad/s] / [m/s].
            tau: The torques held over the step, shape (nv,), in [N m] / [N].
            a: Accelerations at ``(t, q, v)``, shape (nv,), in [rad/s²] / [m/s²].
        """
        if self.friction is None:
            return self.step(t, dt, q, v, tau, a)
        return self.friction.step(self.step, self.accelerate, t, dt, q, v, tau, a)

    def step(self, t: float, dt: float, q: np.ndarray, v: np.ndarray, tau: np.ndarray, a: np.ndarray):
        """``(q, v)`` after one step of ``dt`` from time ``t`` with acceleration ``a`` there.

        Args:
            t: Time in [s].
            dt: Step in [s].
            q: Configuration, shape (nq,), in [rad] / [m].
            v: Velocity, shape (nv,), in [rad/s] / [m/s].
            tau: The torques held over the step, shape (nv,), in [N m] / [N].
            a: Accelerations at ``(t, q, v)``, shape (nv,), in [rad/s²] / [m/s²].
        """
        if not self.rk4:
            v = v + dt * a
            return (q + dt * v if self.integrate is None else self.integrate(q, dt * v)), v
        accelerate, integrate = self.accelerate, self.integrate
        half, sixth = 0.5 * dt, dt / 6.0
        v2 = v + half * a
        if integrate is None:
            a2 = accelerate(t + half, q + half * v, v2, tau)
            v3 = v + half * a2
            a3 = accelerate(t + half, q + half * v2, v3, tau)
            v4 = v + dt * a3
            a4 = accelerate(t + dt, q + dt * v3, v4, tau)
            q = q + sixth * (v + v4 + 2.0 * (v2 + v3))
        else:
            a2 = accelerate(t + half, integrate(q, half * v), v2, tau)
            v3 = v + half * a2
            a3 = accelerate(t + half, integrate(q, half * v2), v3, tau)
            v4 = v + dt * a3
            a4 = accelerate(t + dt, integrate(q, dt * v3), v4, tau)
            q = integrate(q, sixth * (v + v4 + 2.0 * (v2 + v3)))
        return q, v + sixth * (a + a4 + 2.0 * (a2 + a3))


def integrate(
    robot: Robot, stepper: Stepper, q: np.ndarray, v: np.ndarray, steps: int, dt: float, stops: JointLimits | None
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The samples of ``steps`` steps from ``(q, v)``: positions, velocities, accelerations,
    torques, one row a sample (``stops``: joints stopped at their position limits after each step).

    Args:
        robot: The simulated robot.
        stepper: The integrator with the controller and forward dynamics.
        q: Initial configuration, shape (nq,), in [rad] / [m].
        v: Initial velocity, shape (nv,), in [rad/s] / [m/s].
        steps: Number of steps.
        dt: Step in [s].
        stops: The joints' position stops (``None``: limits not enforced).
    """
    qs: list[np.ndarray] = []
    vs: list[np.ndarray] = []
    accelerations: list[np.ndarray] = []
    torques: list[np.ndarray] = []
    q, v = q.copy(), v.copy()
    for step in range(steps):
        t = step * dt
        try:
            qs.append(q)
            vs.append(v)
            tau = stepper.torque(t, q, v) if step % stepper.every == 0 else torques[-1]
            torques.append(tau)
            stepper.observe(t, q, v, tau)
            a = stepper.forward(t, q, v, tau)
            accelerations.append(a)
            q, v = stepper.advance(t, dt, q, v, tau, a)
            if stops is not None:
                q, v = stops.stop(q, v)
        except StageDivergedError as diverged:  # a divergence, not the controller's input
            raise SimulationError(t, step, diverged.joint) from None
        except SingularMassMatrixError:  # a blown-up stage state; M was regular at the start
            if _moderate(qs[-1], vs[-1]) and singular(robot, qs[-1]):
                raise
            raise SimulationError(t, step, _fastest(robot, vs[-1])[0]) from None
        except InputError:  # a non-finite state reached a controller's checked call
            check_finite(robot, qs[:-1], vs[:-1], qs[-1], vs[-1], dt)
            raise
        except (np.linalg.LinAlgError, FloatingPointError, NonFiniteResultError) as error:  # a controller's numerics failed
            check_finite(robot, qs[:-1], vs[:-1], qs[-1], vs[-1], dt)
            joint, speed = _fastest(robot, vs[-1])
            raise ControllerFailedError(t, step, joint, speed, str(error)) from None
        if step % CHECK_EVERY == 0 or step == steps - 1:
            check_finite(robot, qs, vs, q, v, dt)
    qs.append(q)
    vs.append(v)
    torques.append(torques[-1] if steps else stepper.zero)
    stepper.observe(steps * dt, q, v, torques[-1])
    accelerations.append(stepper.forward(steps * dt, q, v, torques[-1]))  # the last sample's own acceleration
    return np.array(qs), np.array(vs), np.array(accelerations), np.array(torques)


def check_finite(robot: Robot, qs: list[np.ndarray], vs: list[np.ndarray], q: np.ndarray, v: np.ndarray, dt: float) -> None:
    """Raise :class:`SimulationError` at the first non-finite state since the last check.

    Args:
        robot: The simulated robot.
        qs: The configurations sampled so far.
        vs: The velocities sampled so far.
        q: The newest configuration, shape (nq,).
        v: The newest velocity, shape (nv,).
        dt: Step in [s] (to name the failing time).
    """
    if math.isfinite(v.dot(v)) and math.isfinite(q.dot(q)):
        return
    states = [*zip(qs[-CHECK_EVERY:], vs[-CHECK_EVERY:], strict=True), (q, v)]
    first = len(qs) - len(states) + 1
    for offset, (q_i, v_i) in enumerate(states):
        if not (np.isfinite(q_i).all() and np.isfinite(v_i).all()):
            step = first + offset - 1
            if offset > 0 and _moderate(*states[offset - 1]) and singular(robot, states[offset - 1][0]):
                raise SingularMassMatrixError(robot.name, robot.massless_joints)
            raise SimulationError(step * dt, step, failing_joint(robot.joint_names, q_i, v_i))


def _fastest(robot: Robot, v: np.ndarray) -> tuple[str, float]:
    """The joint with the largest speed and that speed (a floating base's six: its root joint)."""
    fastest = int(np.argmax(np.abs(v)))
    names = robot.joint_names
    return names[max(0, min(fastest - (robot.nv - len(names)), len(names) - 1))], float(v[fastest])


def _moderate(q: np.ndarray, v: np.ndarray) -> bool:
    """A state that did not blow up (where a singular ``M`` is the reason, not overflow)."""
    return bool(np.abs(q).max(initial=0.0) < 1e6 and np.abs(v).max(initial=0.0) < 1e6)


def singular(robot: Robot, q: np.ndarray) -> bool:
    """Whether ``M(q)`` is singular to working precision (no finite acceleration).

    Args:
        robot: The robot.
        q: Configuration, shape (nq,), in [rad] / [m].
    """
    eigenvalues = np.linalg.eigvalsh(robot.mass_matrix(q))
    return bool(eigenvalues[0] <= 1e-12 * max(abs(eigenvalues[-1]), np.finfo(float).tiny))
