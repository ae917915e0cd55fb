"""Simulation in C: RK4 or semi-implicit Euler on a compiled robot.

The integration loop is :func:`robodyn.simulate`'s, step for step (the same stage order
and formulas, the rules of :mod:`robodyn.compiled.loop_rules`), written in C. The torque
comes from:

- nothing (passive motion, zero torque);
- a controller's compiled twin (:mod:`robodyn.compiled.controllers`) evaluated in C at every
  integration stage (or once a step with ``hold=True``), on its **own** compiled model;
- a Python controller ``controller(t, q, v) -> tau`` called only every ``control_period``
  (a whole number of steps), its torque held in between (zero-order hold): Python stays
  out of the inner loop.

The result is plain arrays (:class:`SimulationArrays`); :mod:`robodyn.sim` wraps them in a
``Trajectory`` (this package sits below it). Importing this module loads no code generator.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from robodyn.common.text import quoted
from robodyn.compiled.controllers import (
    CompiledComputedTorque,
    CompiledLaw,
    CompiledPDGravity,
    HasTwin,
    check_layout,
)
from robodyn.compiled.loop_rules import check_integrator, damped, failing_joint, period_steps, step_count
from robodyn.exceptions import CompileError, InputError, SimulationError

if TYPE_CHECKING:
    from robodyn.compiled.robot import CompiledRobot

__all__ = [
    "CompiledComputedTorque",
    "CompiledPDGravity",
    "SimulationArrays",
    "compiled_controller",
    "has_twin",
    "law_torque",
    "simulate_checked",
    "simulate_compiled",
]


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
    controller: CompiledLaw | PythonController | None = None,
    control_period: float | None = None,
    hold: bool = False,
    joint_friction: bool = True,
) -> SimulationArrays:
    """Simulate a compiled robot from ``(q0, v0)`` for ``duration`` seconds, in C.

    Args:
        compiled: The plant.
        q0, v0: Initial state, shapes (nq,) and (nv,) (a floating base: Pinocchio's free
            flyer, integrated on SE(3) as ``pinocchio.integrate``).
        duration: Simulated time in [s], a whole number of steps.
        dt: Integration step in [s].
        integrator: ``"rk4"`` or ``"semi-implicit-euler"``.
        controller: ``None`` (passive), a compiled twin (:mod:`robodyn.compiled.controllers`;
            :func:`compiled_controller` makes one from a Python controller), or a Python
            callable ``controller(t, q, v) -> tau`` sampled every ``control_period``.
        control_period: For a Python controller, in [s], a whole number of steps
            (default ``dt``).
        hold: For a compiled twin: sample it once a step instead of at every stage.
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
    check_integrator(integrator)
    damping = _joint_damping(compiled, joint_friction)
    steps = step_count(duration, dt)
    (q, v), batch = compiled.robot.validate(q=q0, v=v0)
    if batch:
        raise InputError("q0", "one state (1-D)", f"shape {q.shape}")
    return simulate_checked(
        compiled, q, v, steps, float(dt), integrator=integrator, controller=controller, control_period=control_period,
        hold=hold, damping=damping,
    )  # fmt: skip


def simulate_checked(
    compiled: CompiledRobot,
    q: np.ndarray,
    v: np.ndarray,
    steps: int,
    dt: float,
    *,
    integrator: str,
    controller: CompiledLaw | PythonController | None,
    control_period: float | None,
    hold: bool,
    damping: np.ndarray | None,
) -> SimulationArrays:
    """:func:`simulate_compiled` on arguments already checked (the caller did what it does:
    ``q``, ``v`` one valid state, ``steps`` of ``dt`` from :func:`step_count`, a known
    integrator, ``damping`` the joints' ``b`` or ``None``, no Coulomb friction), so a run
    planned once (:mod:`robodyn.sim.plan`) is not checked twice.

    Args:
        compiled: The plant.
        q, v: The initial state, checked, shapes (nq,) and (nv,).
        steps: Steps of ``dt`` (the run has ``steps + 1`` samples).
        dt: The step in [s].
        integrator, controller, control_period, hold: As :func:`simulate_compiled`.
        damping: The joints' damping ``b`` acting in C, shape (nv,), float64; ``None``: none.

    Raises:
        InputError: For a bad controller or control period.
        SimulationError: If the state stops being finite.
    """
    out = [np.empty((steps + 1, size)) for size in (compiled.nq, compiled.nv, compiled.nv, compiled.nv)]
    q, v = np.ascontiguousarray(q, dtype=float), np.ascontiguousarray(v, dtype=float)
    if controller is None or isinstance(controller, CompiledLaw):
        if control_period is not None:
            raise InputError("control_period", "used with a Python controller only", repr(control_period))
        kind, params, model, frame = _law(compiled, controller)
        rk4 = int(integrator == "rk4")
        failed = compiled.module.simulate(q, v, float(dt), steps, 0.0, rk4, kind, int(hold), params, model, *out, frame, damping)
        _raise_if_failed(compiled, failed, out, dt, 0)
    elif callable(controller):
        every = period_steps(dt if control_period is None else control_period, dt)
        _sampled(compiled, controller, q, v, dt, steps, every, integrator, out, damping)
    else:
        raise InputError("controller", "None, a compiled controller or a callable (t, q, v) -> tau", repr(controller))
    q_out, v_out, a_out, tau_out = out
    if steps:  # the last sample's own acceleration, under the torque held at the end (as robodyn.simulate)
        a_out[-1] = compiled.forward_dynamics(q_out[-1], v_out[-1], damped(tau_out[-1], damping, v_out[-1]))
    return SimulationArrays(np.arange(steps + 1) * dt, *out)


def law_torque(compiled: CompiledRobot, twin: CompiledLaw) -> Callable[[np.ndarray, np.ndarray], np.ndarray]:
    """The twin's torque ``tau(0, q, v)`` evaluated in C: the first sample's torque of one
    step of the loop (for a check that evaluates a library law many times, such as its
    feedback by differences).

    Args:
        compiled: The plant.
        twin: A controller's compiled twin (:mod:`robodyn.compiled.controllers`).

    Returns:
        ``torque(q, v)``, shape (nv,), for checked states of the plant.

    Raises:
        InputError: For a twin that does not fit the plant (as :func:`simulate_compiled`).
    """
    kind, params, model, frame = _law(compiled, twin)
    nq, nv, simulate = compiled.nq, compiled.nv, compiled.module.simulate

    def torque(q: np.ndarray, v: np.ndarray) -> np.ndarray:
        out = [np.empty((2, nq)), np.empty((2, nv)), np.empty((2, nv)), np.empty((2, nv))]
        q, v = np.ascontiguousarray(q, dtype=float), np.ascontiguousarray(v, dtype=float)
        simulate(q, v, 1e-6, 1, 0.0, 0, kind, 1, params, model, *out, frame, None)
        return out[3][0].copy()

    return torque


def _law(compiled: CompiledRobot, twin: CompiledLaw | None) -> tuple[int, np.ndarray, object | None, object | None]:
    """The C loop's controller arguments: kind, parameters, the law's model kernels, its frame's."""
    nv = compiled.nv
    if twin is None:
        return 0, np.zeros(nv), None, None
    if compiled.robot.floating_base and not twin.floating:
        raise InputError("controller", "passive, PD or computed torque on a floating base", type(twin).__name__)
    if twin.model.nv != nv:
        raise InputError("controller.model", f"a compiled robot with {nv} joints", f"{twin.model.nv}")
    joints = nv - 6 if compiled.robot.floating_base else nv  # a floating base's PD and CT laws: its joints
    return twin.kind, check_layout(twin, joints), twin.model.module._kernels, twin.frame_kernels()


def _sampled(
    compiled: CompiledRobot,
    controller: PythonController,
    q: np.ndarray,
    v: np.ndarray,
    dt: float,
    steps: int,
    every: int,
    integrator: str,
    out: list[np.ndarray],
    damping: np.ndarray | None,
) -> None:
    """A Python controller sampled every ``every`` steps, its torque held by the C loop in between."""
    nv, rk4 = compiled.nv, int(integrator == "rk4")
    if steps == 0:  # one sample, zero torque (as robodyn.simulate)
        compiled.module.simulate(q, v, float(dt), 0, 0.0, rk4, 0, 1, np.zeros(nv), None, *out, None, damping)
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
    raise SimulationError(step * dt, step, failing_joint(compiled.joint_names, out[0][step + 1], out[1][step + 1]))


def has_twin(controller: object) -> bool:
    """Whether a controller owns a compiled twin (:class:`~robodyn.compiled.controllers.HasTwin`
    with no refusal: e.g. computed torque along a quintic, operational space with a fixed target).

    Args:
        controller: Any controller (a :mod:`robodyn.sim` controller or a callable).
    """
    return isinstance(controller, HasTwin) and controller.twin_refusal() is None


def compiled_controller(controller: object) -> CompiledLaw:
    """The compiled twin of a controller (its own ``compiled()``, on its own model compiled).

    Args:
        controller: A :mod:`robodyn.sim` controller with a compiled twin
            (:class:`~robodyn.compiled.controllers.HasTwin`).

    Raises:
        CompileError: For a controller without one (one sentence saying why), or a model
            that does not compile.
    """
    name = getattr(getattr(controller, "model", None), "name", "?")
    if not isinstance(controller, HasTwin):
        raise CompileError(
            name, f"the controller {type(controller).__name__} has no compiled twin (run it on the Pinocchio engine)"
        )
    refusal = controller.twin_refusal()
    if refusal is not None:
        raise CompileError(name, refusal)
    return controller.compiled()
