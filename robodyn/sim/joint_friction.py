"""Joint damping and Coulomb friction in a simulation: viscous torque and stick–slip.

The model (docs/joint-friction.md), per degree of freedom with damping ``b`` and Coulomb
friction ``f`` (:attr:`robodyn.Robot.joint_damping`, :attr:`robodyn.Robot.joint_friction`):

- the joint torque of the damping is ``−b v`` at every evaluation of the dynamics;
- a joint with ``f > 0`` is either **sliding**, with the torque ``−f s`` where ``s = ±1`` is
  the sign of its velocity, constant while it slides, or **stuck**: ``v = 0`` and ``a = 0``
  exactly (no creep), held by the friction torque ``λ`` that the constraint needs
  (the other joints move under it: ``M a = τ − h + Eλ`` with ``a`` zero at the stuck
  joints), as long as ``|λ| <= f``;
- the switches are events located inside the step: a sliding joint stops where its
  velocity crosses zero, a stuck joint breaks away where ``|λ|`` reaches ``f``. The step is
  cut there (the root is found to 1e-12 of the step by the Illinois method on the step's
  own integrator), the velocity set to zero, the new modes decided, and the step goes on
  from there in the new modes. At a stop, every joint at rest is held first; while some
  needs more than its ``±f``, the one with the largest excess is released to slide the way
  the other torques push it (its friction ``−f`` against that way).

So within a mode the dynamics are smooth (the integrator keeps its order), a joint at rest
stays exactly at rest while the other torques stay within ``±f`` (the stiction band), and
the energy a sliding joint loses is exactly ``f`` times the angle it travels.

This module holds the friction's state for one run (:class:`JointFriction`); the
simulation calls it around its integrator (:func:`robodyn.sim.simulation.simulate`).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from robodyn.dynamics.robot import Robot

#: ``a(t, q, v, tau)``: the accelerations at a state (what the simulation's stepper evaluates).
Accelerate = Callable[[float, np.ndarray, np.ndarray, np.ndarray], np.ndarray]
#: ``step(t, h, q, v, tau, a) -> (q, v)``: one step of the simulation's integrator.
Step = Callable[[float, float, np.ndarray, np.ndarray, np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]
#: Relative width (of the step) to which an event's time is located.
EVENT_TOLERANCE = 1e-12
#: Most iterations locating one event.
_ITERATIONS = 80


def has_joint_friction(robot: Robot) -> bool:
    """Whether any joint of ``robot`` has damping or Coulomb friction.

    Args:
        robot: The robot.
    """
    return bool(np.any(robot.joint_damping) or np.any(robot.joint_friction))


class JointFriction:
    """The damping and stick–slip friction of a robot's joints during one run.

    Args:
        robot: The plant (its :attr:`~robodyn.Robot.joint_damping` and
            :attr:`~robodyn.Robot.joint_friction`).

    Attributes:
        damping, friction: ``b`` and ``f`` per degree of freedom, shape (nv,).
        stuck: Which joints are stuck, shape (nv,).
        sign: The sliding direction ``s`` of each sliding joint with ``f > 0`` (0 otherwise).
        hold: The friction torque holding each stuck joint at the last evaluation (0 otherwise).
        events: How many stick–slip events the run had.
    """

    def __init__(self, robot: Robot) -> None:
        self.damping = robot.joint_damping
        self.friction = robot.joint_friction
        self.coulomb = self.friction > 0
        nv = robot.nv
        self.stuck = np.zeros(nv, dtype=bool)
        self.sign = np.zeros(nv)
        self.hold = np.zeros(nv)
        self.events = 0
        self._mass_matrix = robot.handle.kernels.M.single
        self._max_events = 4 + 4 * int(self.coulomb.sum())

    def wrap(self, forward: Accelerate) -> Accelerate:
        """``forward`` (the rigid-body accelerations under a torque) with the joints'
        damping and friction torques added and the stuck joints held.

        Args:
            forward: The rigid-body accelerations ``a(t, q, v, tau)``.
        """
        damping, friction = self.damping, self.friction
        damped = bool(damping.any())

        def accelerate(t: float, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
            total = tau - friction * self.sign
            if damped:
                total = total - damping * v
            a = forward(t, q, v, total)
            return self._held(q, a) if self.stuck.any() else a

        return accelerate

    def _held(self, q: np.ndarray, a: np.ndarray) -> np.ndarray:
        """The accelerations ``a`` with the stuck joints held (their friction torque in
        :attr:`hold`): ``a + M⁻¹ E λ`` with ``λ = −((M⁻¹)_SS)⁻¹ a_S``."""
        stuck = self.stuck
        self.hold = np.zeros(len(a))
        if stuck.all():  # nothing moves: the friction takes all the torque
            self.hold[:] = -self._mass_matrix(q) @ a
            return np.zeros(len(a))
        columns = np.linalg.inv(self._mass_matrix(q))[:, stuck]  # M⁻¹ E
        block = columns[stuck]
        force = -a[stuck] / block[0, 0] if len(block) == 1 else -np.linalg.solve(block, a[stuck])
        held = a + columns @ force
        held[stuck] = 0.0
        self.hold[stuck] = force
        return held

    def start(self, accelerate: Accelerate, t: float, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> None:
        """Decide the modes at the run's first state: joints at rest stick or slip, the
        others slide the way they move.

        Args:
            accelerate: The accelerations ``a(t, q, v, tau)`` with the joints' friction (:meth:`wrap`).
            t: Time in [s].
            q: Configuration, shape (nq,), in [rad] / [m].
            v: Velocity, shape (nv,), in [rad/s] / [m/s].
            tau: The applied torques, shape (nv,), in [N m] / [N].
        """
        self.sign = np.where(self.coulomb, np.sign(v), 0.0)
        self._settle(accelerate, t, q, v, tau)

    def _settle(self, accelerate: Accelerate, t: float, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> None:
        """Modes of the joints at rest (``f > 0``, ``v = 0``): all held, then the one with
        the largest excess over ``±f`` released at a time, to slide the way it is pushed."""
        resting = self.coulomb & (v == 0.0)
        self.stuck = resting.copy()
        self.sign[resting] = 0.0
        while self.stuck.any():
            accelerate(t, q, v, tau)
            excess = np.where(self.stuck, np.abs(self.hold) - self.friction, -np.inf)
            joint = int(np.argmax(excess))
            if excess[joint] <= 0.0:
                return
            self.stuck[joint] = False
            self.sign[joint] = -np.sign(self.hold[joint])

    def _event_margin(self, accelerate: Accelerate, t: float, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """Per joint, how far from its next event the state is (negative: past it): the
        velocity in the sliding direction, or ``f − |λ|`` of a stuck joint; +inf elsewhere."""
        margin = np.where(self.coulomb & ~self.stuck & (self.sign != 0), self.sign * v, np.inf)
        if self.stuck.any():
            accelerate(t, q, v, tau)
            margin = np.where(self.stuck, self.friction - np.abs(self.hold), margin)
        return margin

    def step(
        self,
        step: Step,
        accelerate: Accelerate,
        t: float,
        dt: float,
        q: np.ndarray,
        v: np.ndarray,
        tau: np.ndarray,
        a: np.ndarray,
    ) -> tuple[np.ndarray, np.ndarray]:
        """One step of ``dt`` from ``(q, v)`` at time ``t`` (``a``: the accelerations
        there), cut at every stick–slip event inside it.

        Args:
            step: One integrator step ``step(t, dt, q, v, tau, a) -> (q, v)``.
            accelerate: The accelerations ``a(t, q, v, tau)`` with the joints' friction (:meth:`wrap`).
            t: Time in [s].
            dt: Step in [s].
            q: Configuration, shape (nq,), in [rad] / [m].
            v: Velocity, shape (nv,), in [rad/s] / [m/s].
            tau: The applied torques, shape (nv,), in [N m] / [N].
            a: Accelerations at ``(t, q, v)``, shape (nv,), in [rad/s²] / [m/s²].
        """
        if not self.coulomb.any():
            return step(t, dt, q, v, tau, a)
        done = 0.0
        for _ in range(self._max_events):
            remaining = dt - done
            q1, v1 = self._move(step, t + done, remaining, q, v, tau, a)
            if (self._event_margin(accelerate, t + dt, q1, v1, tau) >= 0.0).all():
                return q1, v1
            h, q, v = self._locate(step, accelerate, t + done, remaining, q, v, tau, a)
            done += h
            self.events += 1
            v = np.where(self.coulomb & (self.sign * v <= 0.0) & ~self.stuck, 0.0, v)
            self._settle(accelerate, t + done, q, v, tau)
            if dt - done <= EVENT_TOLERANCE * dt:
                return q, v
            a = accelerate(t + done, q, v, tau)
        return self._move(step, t + done, dt - done, q, v, tau, a)  # too many events in one step: finish in the last modes

    def _move(
        self, step: Step, t: float, h: float, q: np.ndarray, v: np.ndarray, tau: np.ndarray, a: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """One step of the integrator in the current modes (none when every joint is stuck)."""
        return (q, v) if self.stuck.all() else step(t, h, q, v, tau, a)

    def _locate(
        self, step: Step, accelerate: Accelerate, t: float, h: float, q: np.ndarray, v: np.ndarray, tau: np.ndarray, a: np.ndarray
    ) -> tuple[float, np.ndarray, np.ndarray]:
        """The first event within ``h`` of ``(q, v)``: its time after ``t`` and the state
        just past it (Illinois' false position on the smallest margin)."""

        def margin(length: float) -> tuple[float, np.ndarray, np.ndarray]:
            q1, v1 = self._move(step, t, length, q, v, tau, a)
            return float(self._event_margin(accelerate, t + length, q1, v1, tau).min()), q1, v1

        low, high = 0.0, h
        g_low = float(self._event_margin(accelerate, t, q, v, tau).min())
        g_high, q_high, v_high = margin(h)
        if g_low < 0.0:  # inconsistent at the start: decide the modes again here
            return 0.0, q, v
        side = 0
        for _ in range(_ITERATIONS):
            if high - low <= EVENT_TOLERANCE * h:
                break
            middle = (low * g_high - high * g_low) / (g_high - g_low)
            middle = middle if np.isfinite(middle) else 0.5 * (low + high)  # a margin blown up within the step: halve
            middle = min(max(middle, low + 0.01 * (high - low)), high - 0.01 * (high - low))
            g_middle, q_middle, v_middle = margin(middle)
            if g_middle < 0.0:
                high, g_high, q_high, v_high = middle, g_middle, q_middle, v_middle
                if side == -1:
                    g_low /= 2
                side = -1
            else:
                low, g_low = middle, g_middle
                if side == 1:
                    g_high /= 2
                side = 1
        return high, q_high, v_high


__all__ = ["EVENT_TOLERANCE", "JointFriction", "has_joint_friction"]
