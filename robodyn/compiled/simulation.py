"""Simulation in C: RK4 or semi-implicit Euler on a compiled robot.

The integration loop is :func:`robodyn.simulate`'s, step for step (the same stage order
and formulas), written in C. The torque comes from:

- nothing (passive motion, zero torque);
- a compiled joint-space controller evaluated in C at every integration stage (or once a
  step with ``hold=True``), on its **own** compiled model (a mismatched model is a
  different compiled robot): :class:`CompiledPDGravity`, :class:`CompiledComputedTorque`;
- a Python controller ``controller(t, q, v) -> tau`` called only every ``control_period``
  (a whole number of steps), its torque held in between (zero-order hold): Python stays
  out of the inner loop.

The result is plain arrays (:class:`SimulationArrays`); :mod:`robodyn.sim` wraps them in a
``Trajectory`` (this package sits below it).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

from robodyn.common.inputs import as_state
from robodyn.common.text import quoted
from robodyn.compiled.controllers import (
    CompiledFrameController,
    CompiledImpedance,
    CompiledLQR,
    CompiledOperationalSpace,
    CompiledTaskSpace,
)
from robodyn.compiled.robot import CompiledRobot, compile
from robodyn.exceptions import CompileError, InputError, SimulationError

INTEGRATORS = ("rk4", "semi-implicit-euler")


@dataclass(frozen=True)
class CompiledPDGravity:
    """``tau = Kp (target − q) − Kd v + G(q)``, ``G`` from the controller's own compiled model.

    Attributes:
        model: The controller's model (may differ from the plant).
        target: Joint target, shape (nv,).
        kp: Stiffness in [N m/rad] or [N/m], scalar or shape (nv,).
        kd: Damping in [N m s/rad] or [N s/m], scalar or shape (nv,).
    """

    model: CompiledRobot
    target: np.ndarray
    kp: float | np.ndarray = 100.0
    kd: float | np.ndarray = 20.0

    def params(self, nv: int) -> np.ndarray:
        return np.concatenate([as_state(self.target, "target", nv), _gain(self.kp, "kp", nv), _gain(self.kd, "kd", nv)])


@dataclass(frozen=True)
class CompiledComputedTorque:
    """Computed torque along a quintic rest-to-rest reference (:func:`robodyn.sim.control.quintic_reference`):
    ``tau = M(q) (a_d + Kd (v_d − v) + Kp (q_d − q)) + C v + G`` on the controller's model.

    Attributes:
        model: The controller's model.
        q_start, q_end: Ends of the reference, shape (nv,).
        duration: Motion time in [s] (then the reference holds ``q_end``).
        kp: Position gain in [1/s²]; kd: velocity gain in [1/s] (scalars or shape (nv,)).
    """

    model: CompiledRobot
    q_start: np.ndarray
    q_end: np.ndarray
    duration: float
    kp: float | np.ndarray = 400.0
    kd: float | np.ndarray = 40.0

    def params(self, nv: int) -> np.ndarray:
        if not (math.isfinite(self.duration) and self.duration > 0):
            raise InputError("duration", "finite and > 0", repr(self.duration))
        return np.concatenate(
            [
                as_state(self.q_start, "q_start", nv),
                as_state(self.q_end, "q_end", nv),
                _gain(self.kp, "kp", nv),
                _gain(self.kd, "kd", nv),
                [float(self.duration)],
            ]
        )


def _gain(value: float | np.ndarray, name: str, nv: int) -> np.ndarray:
    return as_state(np.broadcast_to(np.asarray(value, dtype=float), (nv,)) if np.ndim(value) == 0 else value, name, nv)


class SimulationArrays(NamedTuple):
    """A simulated run, one row a sample: ``t`` (N,), ``q``, ``v``, ``a``, ``tau`` (N, nv)."""

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    tau: np.ndarray


PythonController = Callable[[float, np.ndarray, np.ndarray], np.ndarray]


def simulate_compiled(
    compiled: CompiledRobot,
    q0: np.ndarray,
    v0: np.ndarray,
    duration: float,
    dt: float,
    *,
    integrator: str = "rk4",
    controller: CompiledPDGravity | CompiledComputedTorque | CompiledFrameController | PythonController | None = None,
    control_period: float | None = None,
    hold: bool = False,
    joint_friction: bool = True,
) -> SimulationArrays:
    """Simulate a compiled robot from ``(q0, v0)`` for ``duration`` seconds, in C.

    Args:
        compiled: The plant.
        q0, v0: Initial state, shapes (nq,) and (nv,) (a floating base: Pinocchio's free
            flyer, integrated on SE(3) as ``pinocchio.integrate``).
        duration: Simulated time in [s]; dt: step in [s].
        integrator: ``"rk4"`` or ``"semi-implicit-euler"``.
        controller: ``None`` (passive), a compiled controller (joint space, or a frame
            controller of :mod:`robodyn.compiled.controllers`; :func:`compiled_controller`
            makes one from a Python controller), or a Python callable
            ``controller(t, q, v) -> tau`` sampled every ``control_period``.
        control_period: For a Python controller, in [s], a whole number of steps
            (default ``dt``).
        hold: For a compiled controller: sample it once a step instead of at every stage.
        joint_friction: The joints' damping (:attr:`Robot.joint_damping`) acts in C at
            every stage, ``−b v`` added to the torque as :mod:`robodyn.sim.joint_friction`
            does; a robot with Coulomb friction (:attr:`Robot.joint_friction`, stick–slip
            events) is refused unless ``joint_friction=False`` asks for the rigid-body
            motion (damping left out too).

    Returns:
        ``round(duration / dt) + 1`` samples (the conventions of :func:`robodyn.simulate`).

    Raises:
        InputError: For bad states, step, integrator, controller or control period.
        SimulationError: If the state stops being finite.
    """
    if integrator not in INTEGRATORS:
        raise InputError("integrator", f"one of {', '.join(INTEGRATORS)}", repr(integrator))
    damping = _joint_damping(compiled, joint_friction)
    if not (math.isfinite(dt) and dt > 0 and math.isfinite(duration) and duration >= 0):
        raise InputError("dt and duration", "finite, dt > 0 and duration >= 0", f"dt={dt}, duration={duration}")
    (q, v), batch = compiled.robot.validate(q=q0, v=v0)
    if batch:
        raise InputError("q0", "one state (1-D)", f"shape {q.shape}")
    nv, steps = compiled.nv, round(duration / dt)
    rk4 = int(integrator == "rk4")
    out = [np.empty((steps + 1, size)) for size in (compiled.nq, nv, nv, nv)]
    joints = nv - 6 if compiled.robot.floating_base else nv  # a floating base's PD and CT laws: its joints
    q, v = np.ascontiguousarray(q), np.ascontiguousarray(v)
    if controller is None or isinstance(
        controller, CompiledPDGravity | CompiledComputedTorque | CompiledFrameController | CompiledLQR
    ):
        if control_period is not None:
            raise InputError("control_period", "used with a Python controller only", repr(control_period))
        kind, params, model, frame = 0, np.zeros(nv), None, None
        if compiled.robot.floating_base and isinstance(controller, CompiledFrameController | CompiledLQR):
            raise InputError("controller", "passive, PD or computed torque on a floating base", type(controller).__name__)
        if controller is not None:
            if controller.model.nv != nv:
                raise InputError("controller.model", f"a compiled robot with {nv} joints", f"{controller.model.nv}")
            kind = 1 if isinstance(controller, CompiledPDGravity) else 2
            params, model = controller.params(joints), controller.model.module._kernels
            if isinstance(controller, CompiledFrameController):
                kind, frame = controller.kind, controller.frame_kernels()
            if isinstance(controller, CompiledLQR):
                kind = controller.kind
        failed = compiled.module.simulate(q, v, float(dt), steps, 0.0, rk4, kind, int(hold), params, model, *out, frame, damping)
        _raise_if_failed(compiled, failed, out, dt, 0)
    elif callable(controller):
        period = dt if control_period is None else control_period
        every = round(period / dt) if math.isfinite(period) and period > 0 else 0
        if every < 1 or abs(every * dt - period) > 1e-9 * period:
            raise InputError("control_period", f"a whole number of steps of dt = {dt}", repr(control_period))
        if steps == 0:  # one sample, zero torque (as robodyn.simulate)
            failed = compiled.module.simulate(q, v, float(dt), 0, 0.0, rk4, 0, 1, np.zeros(nv), None, *out, None, damping)
        for start in range(0, steps, every):
            count = min(every, steps - start)
            tau = np.asarray(controller(start * dt, q.copy(), v.copy()), dtype=float)
            if tau.shape != (nv,):
                raise InputError("controller output", f"{nv} torques", f"shape {tau.shape}")
            views = [array[start : start + count + 1] for array in out]
            failed = compiled.module.simulate(
                q, v, float(dt), count, start * dt, rk4, 0, 1, np.ascontiguousarray(tau), None, *views, None, damping
            )
            _raise_if_failed(compiled, failed, out, dt, start)
            q, v = out[0][start + count].copy(), out[1][start + count].copy()
    else:
        raise InputError("controller", "None, a compiled controller or a callable (t, q, v) -> tau", repr(controller))
    q_out, v_out, a_out, tau_out = out
    if steps:  # the last sample's own acceleration, under the torque held at the end (as robodyn.simulate)
        applied = tau_out[-1] if damping is None else tau_out[-1] - damping * v_out[-1]
        a_out[-1] = compiled.forward_dynamics(q_out[-1], v_out[-1], applied)
    return SimulationArrays(np.arange(steps + 1) * dt, *out)


def _joint_damping(compiled: CompiledRobot, joint_friction: bool) -> np.ndarray | None:
    """The damping the loop in C applies, ``b`` per joint (``None``: none acts).

    Raises:
        InputError: For ``joint_friction`` on a robot with Coulomb friction (stick–slip has
            no loop in C).
    """
    robot = compiled.robot
    if joint_friction and robot.joint_friction.any():
        raise InputError(
            "joint_friction",
            "False for a robot whose joints have Coulomb friction (the compiled loop has damping, not stick-slip)",
            f"True for {quoted(robot.name)}",
        )
    return np.ascontiguousarray(robot.joint_damping, dtype=float) if joint_friction and robot.joint_damping.any() else None


def _raise_if_failed(compiled: CompiledRobot, failed: int, out: list[np.ndarray], dt: float, start: int) -> None:
    """A :class:`SimulationError` naming the first non-finite joint, as :func:`robodyn.simulate` does."""
    if failed < 0:
        return
    step = start + failed
    q, v = out[0][step + 1], out[1][step + 1]
    bad = np.flatnonzero(~np.isfinite(v)) if not np.isfinite(v).all() else np.flatnonzero(~np.isfinite(q[q.size - v.size :]))
    names = compiled.joint_names  # as robodyn.simulate names it (a floating base's q: its velocity's entries)
    joint = names[min(int(bad[0]) if bad.size else 0, len(names) - 1)]
    raise SimulationError(step * dt, step, joint)


#: The Python controllers that have a compiled twin, by qualified class name (the compiled
#: layer sits below robodyn.sim and does not import it; exact classes only: a subclass may
#: change the law).
_TWINS = {
    "robodyn.sim.control.PDGravity": "pd",
    "robodyn.sim.control.ComputedTorque": "computed-torque",
    "robodyn.sim.control.TaskSpace": "task-space",
    "robodyn.sim.operational_space.OperationalSpace": "operational-space",
    "robodyn.sim.operational_space.Impedance": "impedance",
    "robodyn.sim.control.LQR": "lqr",
}

CompiledController = CompiledPDGravity | CompiledComputedTorque | CompiledFrameController | CompiledLQR


def has_twin(controller: object) -> bool:
    """Whether :func:`compiled_controller` has a twin for this controller (its class and, for
    computed torque, its reference; for operational space, a fixed target)."""
    kind = _TWINS.get(f"{type(controller).__module__}.{type(controller).__qualname__}")
    c: Any = controller
    if kind == "computed-torque":
        return type(c.reference).__qualname__ == "QuinticReference"
    if kind == "operational-space":
        return not callable(c.position)
    return kind is not None


def compiled_controller(controller: object) -> CompiledController:
    """The compiled twin of a Python controller of :mod:`robodyn.sim` (on its own model, compiled).

    ``PDGravity``, ``ComputedTorque`` along a quintic (:func:`robodyn.sim.control.quintic_reference`),
    ``TaskSpace``, ``OperationalSpace`` with a fixed target, ``Impedance``, ``LQR``: the same law in C,
    evaluated wherever the integrator evaluates the dynamics.

    Raises:
        CompileError: For any other controller (one sentence saying why), or a model that
            does not compile (a floating base under a frame controller).
    """
    kind = _TWINS.get(f"{type(controller).__module__}.{type(controller).__qualname__}")
    c: Any = controller
    if kind is None:
        raise CompileError(
            getattr(getattr(c, "model", None), "name", "?"),
            f"the controller {type(controller).__name__} has no compiled twin (run it on the Pinocchio engine)",
        )
    if kind == "pd":
        return CompiledPDGravity(compile(c.model), c.target, c.kp, c.kd)
    if kind == "computed-torque":
        reference = c.reference
        if type(reference).__qualname__ != "QuinticReference":
            raise CompileError(c.model.name, "computed torque compiles along a quintic_reference only")
        return CompiledComputedTorque(compile(c.model), reference.q_start, reference.q_end, reference.duration, c.kp, c.kd)
    if kind == "lqr":
        return CompiledLQR(compile(c.model), c.gain, c.u_eq, c.actuation, c.x_eq)
    if kind == "task-space":
        return CompiledTaskSpace(compile(c.model), c.frame, c.target, c.kp, c.kd, c.damping, c.joint_damping)
    if callable(c.position):
        raise CompileError(c.model.name, f"{type(controller).__name__} compiles with a fixed target, not a path")
    rotation = c._rotation  # the validated target attitude (the orientation given in any form)
    if kind == "operational-space":
        return CompiledOperationalSpace(
            compile(c.model), c.frame, c.position, rotation, c.kp, c.kd, c.posture, c.posture_kp, c.posture_kd, c.damping
        )
    return CompiledImpedance(compile(c.model), c.frame, c.position, rotation, c.stiffness, c.damping, c.null_damping)
