"""The rules of a simulation loop, written once for both engines (and the C loop's wrapper).

The integrators, the step count of a run, the sampling period of a held controller, the
joint a divergence names and the joints' damping torque ``−b v``: :mod:`robodyn.sim`'s
run plan and its Pinocchio loop use them, and so does :func:`robodyn.compiled.simulate_compiled`
(this module sits in the lowest layer both reach; numpy and the exceptions only, no code
generator).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Literal

import numpy as np

from robodyn.exceptions import InputError

#: Integration schemes: classical Runge–Kutta, or semi-implicit (symplectic) Euler.
Integrator = Literal["rk4", "semi-implicit-euler"]
INTEGRATORS: tuple[Integrator, ...] = ("rk4", "semi-implicit-euler")
#: Most steps one run may take (a guard against durations like 1e9 s at 1 ms).
MAX_STEPS = 10_000_000


def check_integrator(integrator: str) -> None:
    """Refuse an integrator that is not one of :data:`INTEGRATORS`.

    Args:
        integrator: The integrator's name (``"rk4"`` or ``"semi-implicit-euler"``).

    Raises:
        InputError: Any other name.
    """
    if integrator not in INTEGRATORS:
        raise InputError("integrator", f"one of {', '.join(INTEGRATORS)}", repr(integrator))


def step_count(duration: float, dt: float) -> int:
    """The number of steps of ``dt`` in ``duration`` (both in [s]).

    Args:
        duration: The simulated time in [s].
        dt: The integration step in [s].

    Raises:
        InputError: For a step or duration that is not finite and positive (a duration of
            0 is one sample), a duration that is not a whole number of steps (to 1e-9
            relative) or more than :data:`MAX_STEPS` steps.
    """
    if not (math.isfinite(dt) and dt > 0 and math.isfinite(duration) and duration >= 0):
        raise InputError("dt and duration", "finite, dt > 0 and duration >= 0", f"dt={dt}, duration={duration}")
    steps = round(duration / dt)
    if abs(steps * dt - duration) > 1e-9 * max(duration, dt):
        raise InputError("duration", f"a whole number of steps of dt = {dt:g} s", f"{duration:g} s ({duration / dt:.6g} steps)")
    if steps > MAX_STEPS:
        raise InputError("duration / dt", f"at most {MAX_STEPS:,} steps", f"{steps:,} steps")
    return steps


def period_steps(control_period: float, dt: float) -> int:
    """The steps of ``dt`` in one control period (both in [s]), refused unless a whole number ≥ 1.

    Args:
        control_period: The controller's sampling period in [s] (its torque held between samples).
        dt: The integration step in [s].

    Raises:
        InputError: ``control_period`` is not a whole number (≥ 1) of steps of ``dt``.
    """
    every = round(control_period / dt) if math.isfinite(control_period) and control_period > 0 else 0
    if every < 1 or abs(every * dt - control_period) > 1e-9 * control_period:
        raise InputError("control_period", f"a whole number of steps of dt = {dt:g} s, in [s]", repr(control_period))
    return every


def failing_joint(joint_names: Sequence[str], q: np.ndarray, v: np.ndarray) -> str:
    """The joint a non-finite state names: the first whose velocity is not finite, else the
    first whose position is not (a floating base's q read by its velocity's entries).

    Args:
        joint_names: The robot's joint names (``Robot.joint_names``).
        q: The configuration, shape (nq,).
        v: The velocity, shape (nv,).
    """
    bad = np.flatnonzero(~np.isfinite(v)) if not np.isfinite(v).all() else np.flatnonzero(~np.isfinite(q[q.size - v.size :]))
    return joint_names[min(int(bad[0]) if bad.size else 0, len(joint_names) - 1)]


def damped(tau: np.ndarray, damping: np.ndarray | None, v: np.ndarray) -> np.ndarray:
    """The torque with the joints' damping: ``tau − b v`` (``tau`` itself without damping).

    Args:
        tau: The joint torques, shape (nv,), in [N m] or [N].
        damping: The joints' viscous damping ``b`` (``Robot.joint_damping``), shape (nv,),
            in [N m s/rad] or [N s/m]; ``None``: none.
        v: The velocity, shape (nv,), in [rad/s] or [m/s].
    """
    return tau if damping is None else tau - damping * v
