"""Simulation: integrate the forward dynamics (ABA) of a robot in time.

:func:`simulate` advances ``(q, v)`` with a fixed step ``dt``, either by the classical
fourth-order Runge–Kutta method (``"rk4"``) or by semi-implicit (symplectic) Euler
(``"semi-implicit-euler"``: ``v ← v + dt a(q, v)``, then ``q ← q ⊕ dt v``). Positions move
on the configuration manifold (``Robot.integrate``: plain addition for joints, SE(3) for a
floating base). On a floating base, RK4 combines its stages' velocities in the tangent
space at the step's start without the dexp correction of Runge–Kutta–Munthe-Kaas, so its
error in the base's orientation falls as dt² (solo12, 1 s at 1 kHz: momentum drift 3e-7
relative); joints keep fourth order.

The controller is a continuous-time law evaluated wherever the integrator evaluates the
dynamics (every Runge–Kutta stage), in either engine; with ``hold=True`` it is sampled once
per step and its torque held during the step (zero-order hold, as on a digital controller),
with ``control_period=`` every so many steps. Engines (``engine=``): ``"pinocchio"`` (this
loop, ABA per stage), ``"compiled"`` (:mod:`robodyn.compiled`: passive runs and compiled
controllers wholly in C; a Python controller called from Python at every stage around the
compiled dynamics) and ``"auto"`` (:func:`choose_engine`); :func:`simulate_run` also says
which ran, why, and the loop's and the compilation's times. External
wrenches are evaluated at every stage. An ``observer=`` (a
:class:`~robodyn.sim.observer.MomentumObserver`) is updated once per step, at the state
actually reached, with the torque applied there; its ``residuals`` are then the external
torques it estimated, one a sample. The
result is a :class:`Trajectory` (one row a sample) that saves to and loads from CSV and NPZ.

Joint limits (``limits=``, see :mod:`robodyn.sim.limits`): ``"warn"`` (default) reports
every position, velocity and effort limit the run broke in one
:class:`~robodyn.exceptions.JointLimitWarning`; ``"enforce"`` saturates the torques at
the effort limits and stops joints at their position limits; ``"ignore"`` does neither.

Joint damping and Coulomb friction (``<dynamics>``, :attr:`Robot.joint_damping`,
:attr:`Robot.joint_friction`) act by default (``joint_friction=False``: the rigid-body
motion): ``−b v``, and stick–slip friction with its events located inside the step
(:mod:`robodyn.sim.joint_friction`, docs/joint-friction.md). The compiled engine has the
damping (in C, at every stage) but no stick–slip: it refuses a robot with Coulomb friction
unless ``joint_friction=False`` (``engine="auto"`` runs such a robot on the Pinocchio engine).

A state that stops being finite ends the run with a :class:`SimulationError` saying when
and which joint, or a :class:`SingularMassMatrixError` when the mass matrix is singular
there (massless moving bodies: no step size helps).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from time import perf_counter
from typing import Literal

import numpy as np

from robodyn.common.text import quoted
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import (
    CompileError,
    ControllerFailedError,
    InputError,
    JointLimitWarning,
    NonFiniteResultError,
    SimulationError,
    SingularMassMatrixError,
)
from robodyn.sim.joint_friction import JointFriction, has_joint_friction
from robodyn.sim.limits import JointLimits, LimitMode, check_mode, warning_text
from robodyn.sim.observer import MomentumObserver
from robodyn.trajectory import Trajectory

#: A controller maps time in [s], q and v to joint torques, shape (nv,).
Controller = Callable[[float, np.ndarray, np.ndarray], np.ndarray]
#: Integration schemes: classical Runge–Kutta, or semi-implicit (symplectic) Euler.
Integrator = Literal["rk4", "semi-implicit-euler"]
INTEGRATORS: tuple[Integrator, ...] = ("rk4", "semi-implicit-euler")
#: Where the loop runs: Python over Pinocchio, or C (:mod:`robodyn.compiled`); ``"auto"``
#: chooses (see :func:`choose_engine`).
Engine = Literal["auto", "pinocchio", "compiled"]
ENGINES: tuple[Engine, ...] = ("auto", "pinocchio", "compiled")
#: Most steps one run may take (a guard against durations like 1e9 s at 1 ms).
MAX_STEPS = 10_000_000
#: Steps between two finiteness checks of the state (a divergence is located exactly).
_CHECK_EVERY = 64


@dataclass(frozen=True)
class ExternalWrench:
    """A wrench applied by the environment at a frame's origin (world axes).

    Attributes:
        frame: Link or joint name.
        wrench: Force in [N] and torque in [N m] (shape (6,), or a force, shape (3,)), or a
            function of time in [s] returning one.
    """

    frame: str
    wrench: np.ndarray | Sequence[float] | Callable[[float], np.ndarray]

    def value(self, time: float) -> np.ndarray:
        """The wrench at a time, shape (6,) or (3,)."""
        return np.asarray(self.wrench(time) if callable(self.wrench) else self.wrench, dtype=float)


def external_torques(robot: Robot, q: np.ndarray, time: float, external: Sequence[ExternalWrench]) -> np.ndarray:
    """Sum of ``J(q)ᵀ w`` over external wrenches at a time, shape (nv,)."""
    total = np.zeros(robot.nv)
    for item in external:
        total += robot.wrench_torques(q, item.frame, item.value(time))
    return total


@dataclass(frozen=True)
class EngineRun:
    """How a run went: the engine that ran, why, and where the time went.

    Attributes:
        engine: ``"pinocchio"`` or ``"compiled"``: the engine that ran.
        reason: Why that engine, one sentence (with ``engine="auto"``: why it was chosen).
        loop_time: Wall-clock time of the integration loop alone, in [s].
        compile_time: Wall-clock time spent choosing the engine and compiling (or loading
            the cached) kernels, importing the code generator included, in [s] (0 when
            ``engine="pinocchio"`` was asked for).
        control_period: The period in [s] at which the controller was sampled and its
            torque held; ``None`` when it was evaluated at every integrator stage (or there
            is none).
        controller_in_c: Whether the controller ran in C (passive runs: ``False``).
    """

    engine: Literal["pinocchio", "compiled"]
    reason: str
    loop_time: float
    compile_time: float = 0.0
    control_period: float | None = None
    controller_in_c: bool = False


def simulate(
    robot: Robot,
    q0: np.ndarray,
    v0: np.ndarray,
    duration: float,
    dt: float,
    *,
    controller: Controller | None = None,
    integrator: Integrator = "rk4",
    external: Sequence[ExternalWrench] = (),
    hold: bool = False,
    limits: LimitMode = "warn",
    engine: Engine = "auto",
    control_period: float | None = None,
    observer: MomentumObserver | None = None,
    joint_friction: bool = True,
) -> Trajectory:
    """Simulate a robot from ``(q0, v0)`` for ``duration`` seconds.

    Both engines evaluate the controller at every integrator stage (a Python controller in
    the compiled engine is called from Python at each stage, the dynamics in C) unless
    ``hold`` or ``control_period`` asks for sampling and holding it; the two engines give
    the same trajectory (to ~1e-12). :func:`simulate_run` also says which engine ran, why,
    and how long the loop and the compilation took.

    Args:
        robot: The plant.
        q0: Initial configuration, shape (nq,).
        v0: Initial velocity, shape (nv,).
        duration: Simulated time in [s].
        dt: Step in [s].
        controller: ``controller(t, q, v) -> tau``; ``None`` for zero torque (passive).
        integrator: ``"rk4"`` or ``"semi-implicit-euler"``.
        external: Wrenches the environment applies (constant or functions of time).
        hold: Sample the controller once per step and hold its torque (zero-order hold)
            instead of evaluating it at every integration stage (``control_period=dt``).
        limits: ``"warn"``, ``"enforce"`` or ``"ignore"`` (see :mod:`robodyn.sim.limits`).
        engine: ``"auto"`` (default: see :func:`choose_engine`), ``"pinocchio"`` (this
            loop in Python, ABA per stage) or ``"compiled"`` (:mod:`robodyn.compiled`;
            no external wrenches, no observer, limits warned or ignored; a floating base
            passive or under PD / computed torque, or a Python controller). Passive runs, PD + gravity and computed torque along a quintic run
            wholly in C on their own compiled models; any other controller is called from
            Python at every stage around the compiled dynamics.
        control_period: Sample the controller every ``control_period`` [s] (a whole
            number of steps) and hold its torque in between (zero-order hold, as on a
            digital controller), in either engine; ``None``: evaluate it continuously.
        observer: A momentum observer fed every sample (time, state, applied torque) as
            the run goes (Pinocchio engine); afterwards ``observer.residuals`` holds its
            estimate of the external torques at each sample. Give it ``torque="held"``
            with ``hold=True``, ``"sampled"`` otherwise.

        joint_friction: Honour the joints' damping and Coulomb friction
            (:attr:`Robot.joint_damping`, :attr:`Robot.joint_friction`: ``−b v``, and
            stick–slip friction up to ``±f``, :mod:`robodyn.sim.joint_friction`); ``False``
            gives the rigid-body motion. The ``tau`` column stays the applied torque.

    Returns:
        The trajectory, ``round(duration / dt) + 1`` samples from ``t = 0`` (``tau`` is
        the applied torque: saturated with ``limits="enforce"``).

    Raises:
        InputError: For bad initial states, step, integrator, limits mode, engine or
            control period, or a duration that is not a whole number of steps (to 1e-9
            relative); with ``engine="compiled"``, for what it does not model.
        CompileError: With ``engine="compiled"``, for a floating base under a frame
            controller (task space, operational space, impedance).
        FrameError: An external wrench on a frame that is unknown or that no joint moves.
        SingularMassMatrixError: If the mass matrix is singular (no motion is defined).
        SimulationError: If the state stops being finite (``ControllerFailedError``: if
            the controller's own numerics fail, e.g. a singular solve on a blown-up state).

    Warns:
        JointLimitWarning: With ``limits="warn"``, when a limit was broken.
    """
    trajectory, _ = _simulate(
        robot, q0, v0, duration, dt, controller=controller, integrator=integrator, external=external, hold=hold,
        limits=limits, engine=engine, control_period=control_period, observer=observer, joint_friction=joint_friction,
    )  # fmt: skip
    return trajectory


def simulate_run(
    robot: Robot,
    q0: np.ndarray,
    v0: np.ndarray,
    duration: float,
    dt: float,
    *,
    controller: Controller | None = None,
    integrator: Integrator = "rk4",
    external: Sequence[ExternalWrench] = (),
    hold: bool = False,
    limits: LimitMode = "warn",
    engine: Engine = "auto",
    control_period: float | None = None,
    observer: MomentumObserver | None = None,
    joint_friction: bool = True,
) -> tuple[Trajectory, EngineRun]:
    """:func:`simulate`, also saying which engine ran, why, and the loop's and the
    compilation's wall-clock times (:class:`EngineRun`). Arguments, errors and warnings
    are :func:`simulate`'s."""
    return _simulate(
        robot, q0, v0, duration, dt, controller=controller, integrator=integrator, external=external, hold=hold,
        limits=limits, engine=engine, control_period=control_period, observer=observer, joint_friction=joint_friction,
    )  # fmt: skip


def _simulate(
    robot: Robot,
    q0: np.ndarray,
    v0: np.ndarray,
    duration: float,
    dt: float,
    *,
    controller: Controller | None,
    integrator: str,
    external: Sequence[ExternalWrench],
    hold: bool,
    limits: str,
    engine: str,
    control_period: float | None,
    observer: MomentumObserver | None,
    joint_friction: bool,
) -> tuple[Trajectory, EngineRun]:
    """The run and how it went; a :class:`JointLimitWarning` for the limits it broke (with
    ``limits="warn"``; none with ``"ignore"``)."""
    _check_modes(integrator, limits, engine)
    steps = _step_count(duration, dt)
    every = _period_steps(control_period, hold, dt, controller)
    (q, v), _ = robot.validate(q=q0, v=v0)
    if q.ndim != 1:
        raise InputError("q0", "one state (1-D)", f"shape {q.shape}")
    friction = joint_friction and has_joint_friction(robot)
    if engine == "compiled":
        _check_compiled_applies(robot, external, limits, observer)
        if friction:
            _refuse_compiled_friction(robot)
    chosen, reason = ("pinocchio", "asked for (engine='pinocchio')") if engine == "pinocchio" else ("compiled", "")
    began = perf_counter()  # choosing and compiling: importing the code generator counts here
    if engine == "auto":
        chosen, reason = choose_engine(
            robot, controller, external=external, limits=limits, observer=observer, every=every, joint_friction=friction
        )
    compiled = None
    if chosen == "compiled":
        try:
            compiled = _prepare_compiled(robot, controller, every)
        except CompileError as error:  # CompilerNotFoundError included
            if engine == "compiled":
                raise
            chosen, reason = "pinocchio", f"the compiled engine does not apply: {error}"
    compile_time = perf_counter() - began if chosen == "compiled" or engine != "pinocchio" else 0.0
    if compiled is not None:
        trajectory, run = _simulate_compiled(robot, q, v, steps, dt, controller, integrator, every, compiled, friction=friction)
        run = replace(run, reason=reason or "asked for (engine='compiled')", compile_time=compile_time)
    else:
        trajectory, run = _simulate_pinocchio(
            robot, q, v, steps, dt, controller=controller, integrator=integrator, external=external, every=every,
            limits=limits, observer=observer, friction=friction,
        )  # fmt: skip
        run = replace(run, reason=reason, compile_time=compile_time)
    violations = [] if limits == "ignore" else JointLimits(robot).violations(trajectory)
    if violations:  # stack level 3: the caller of simulate / simulate_run
        warnings.warn(JointLimitWarning(warning_text(robot.name, violations), violations), stacklevel=3)
    return trajectory, run


def choose_engine(
    robot: Robot,
    controller: Controller | None,
    *,
    external: Sequence[ExternalWrench] = (),
    limits: str = "warn",
    observer: MomentumObserver | None = None,
    every: int | None = None,
    joint_friction: bool = False,
) -> tuple[Literal["pinocchio", "compiled"], str]:
    """The engine ``engine="auto"`` runs, and why (one sentence).

    The compiled engine when the whole loop runs in C there: a robot with moving mass
    (a floating base: passive, or PD / computed torque on its joints), no external wrenches, no observer, limits not enforced, passive or under
    a controller with a compiled counterpart (PD + gravity, computed torque along a
    quintic; evaluated at every stage or once a step), a C compiler on the PATH, and the
    robot compiled before (its kernels in the cache: loading them takes milliseconds,
    while a cold compile derives the equations, seconds to minutes, so auto never starts
    one; ``engine="compiled"`` or :func:`robodyn.compile` does). Otherwise the Pinocchio
    engine. Both give the same trajectory to ~1e-12.

    Args:
        robot: The plant.
        controller: The controller (``None``: passive).
        external, limits, observer: As for :func:`simulate`.
        every: Steps between two samples of a held controller (``None``: every stage).
        joint_friction: Whether the joints' damping and friction act in this run.

    Returns:
        ``"compiled"`` or ``"pinocchio"``, and the reason.
    """
    if robot.floating_base and _frame_law_in_c(controller, every):
        return "pinocchio", f"a floating base under {type(controller).__name__} (its compiled twin models fixed bases)"
    refusals = [
        (bool(external), "external wrenches"),
        (observer is not None, "a momentum observer"),
        (limits == "enforce", "limits enforced"),
        (joint_friction and bool(robot.joint_friction.any()), "joint Coulomb friction"),
        (bool(robot.massless_joints) or robot.nv == 0, "no moving mass to compile"),
    ]
    for refused, what in refusals:
        if refused:
            return "pinocchio", f"{what} (the compiled engine models none)"
    if controller is not None and not _runs_in_c(controller, every):
        return "pinocchio", "a Python controller (called from Python at every stage in either engine)"
    from robodyn.compiled.build import find_compiler  # the code generator's imports: only when needed

    try:
        find_compiler()
    except CompileError as error:
        return "pinocchio", f"no C compiler ({error})"
    if not _compiled_before(robot, controller):
        return "pinocchio", (
            "not compiled yet (engine='compiled' builds it once, in seconds to minutes; auto uses it from then on)"
        )
    what = "passive" if controller is None else f"{type(controller).__name__} in C"
    return "compiled", f"{'floating' if robot.floating_base else 'fixed'} base, {what}, compiled before (cached)"


def _compiled_before(robot: Robot, controller: Controller | None) -> bool:
    """Whether the plant's kernels, and the controller's model's, are in the cache (a cold
    compile derives the equations: seconds for 2 joints, minutes for 7 oblique ones)."""
    from robodyn.compiled.build import cached_kernels
    from robodyn.compiled.robot import robot_key

    model = getattr(controller, "model", None)
    models = [robot] if not isinstance(model, Robot) else [robot, model]
    keys = {robot_key(each) for each in models}
    return all(cached_kernels(key) is not None for key in keys)


def _check_modes(integrator: str, limits: str, engine: str) -> None:
    """Refuse an unknown integrator, limits mode or engine."""
    if integrator not in INTEGRATORS:
        raise InputError("integrator", f"one of {', '.join(INTEGRATORS)}", repr(integrator))
    check_mode(limits)
    if engine not in ENGINES:
        raise InputError("engine", f"one of {', '.join(ENGINES)}", repr(engine))


def _step_count(duration: float, dt: float) -> int:
    """The number of steps of ``dt`` in ``duration`` (both in [s]), refused unless whole."""
    if not (math.isfinite(dt) and dt > 0 and math.isfinite(duration) and duration >= 0):
        raise InputError("dt and duration", "finite, dt > 0 and duration >= 0", f"dt={dt}, duration={duration}")
    steps = round(duration / dt)
    if abs(steps * dt - duration) > 1e-9 * max(duration, dt):
        raise InputError("duration", f"a whole number of steps of dt = {dt:g} s", f"{duration:g} s ({duration / dt:.6g} steps)")
    if steps > MAX_STEPS:
        raise InputError("duration / dt", f"at most {MAX_STEPS:,} steps", f"{steps:,} steps")
    return steps


def _period_steps(control_period: float | None, hold: bool, dt: float, controller: Controller | None) -> int | None:
    """Steps between two samples of a held controller (``hold``: 1), ``None`` for a
    controller evaluated at every stage; a period that is not a whole number of steps, or
    one without a controller, is refused."""
    if control_period is None:
        return 1 if hold and controller is not None else None
    if controller is None:
        raise InputError("control_period", "given only with a controller (a passive run samples nothing)", repr(control_period))
    every = round(control_period / dt) if math.isfinite(control_period) and control_period > 0 else 0
    if every < 1 or abs(every * dt - control_period) > 1e-9 * control_period:
        raise InputError("control_period", f"a whole number of steps of dt = {dt:g} s, in [s]", repr(control_period))
    return every


class _Stepper:
    """One integration step of ``(q, v)`` under a controller: RK4 or semi-implicit Euler."""

    def __init__(
        self,
        robot: Robot,
        external: Sequence[ExternalWrench],
        controller: Controller | None,
        *,
        hold: bool,
        rk4: bool,
        observer: MomentumObserver | None = None,
        forward: Callable[[float, np.ndarray, np.ndarray, np.ndarray], np.ndarray] | None = None,
        every: int = 1,
        friction: JointFriction | None = None,
    ) -> None:
        self.controller = controller
        self.observer = observer
        self.forward = _accelerator(robot, external) if forward is None else forward
        self.every = every  # steps between two samples of the controller at a step's start
        self.friction = friction
        if friction is not None:  # the joints' damping and stick-slip friction
            self.forward = friction.wrap(self.forward)
        if controller is None or hold:  # the step's torque (zero when passive) holds
            self.accelerate = self.forward
        else:
            forward = self.forward
            self.accelerate = lambda t, q, v, tau: forward(t, q, v, np.asarray(controller(t, q, v), dtype=float))
        # Fixed base: q moves by plain addition (no call); floating base: on SE(3).
        self.integrate = robot.integrate if robot.floating_base else None
        self.rk4 = rk4
        self.zero = np.zeros(robot.nv)

    def torque(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The controller's torque at the step's start, shape (nv,) (zero when passive)."""
        return self.zero if self.controller is None else np.asarray(self.controller(t, q, v), dtype=float)

    def observe(self, t: float, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> None:
        """Feed the observer (if any) a sample and the torque applied there."""
        if self.observer is not None:
            self.observer.update(t, q, v, tau)

    def advance(self, t: float, dt: float, q: np.ndarray, v: np.ndarray, tau: np.ndarray, a: np.ndarray):
        """:meth:`step`, cut at the joints' stick-slip events when there is joint friction."""
        if self.friction is None:
            return self.step(t, dt, q, v, tau, a)
        return self.friction.step(self.step, self.accelerate, t, dt, q, v, tau, a)

    def step(self, t: float, dt: float, q: np.ndarray, v: np.ndarray, tau: np.ndarray, a: np.ndarray):
        """``(q, v)`` after one step of ``dt`` from time ``t`` with acceleration ``a`` there."""
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


def _integrate(
    robot: Robot, stepper: _Stepper, q: np.ndarray, v: np.ndarray, steps: int, dt: float, stops: JointLimits | None
) -> tuple[list, list, list, list]:
    """The samples of ``steps`` steps from ``(q, v)``: positions, velocities, accelerations,
    torques (``stops``: joints stopped at their position limits after each step)."""
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
        except InputError:  # a non-finite state reached a controller's checked call
            _check_finite(robot, qs[:-1], vs[:-1], qs[-1], vs[-1], dt)
            raise
        except (np.linalg.LinAlgError, FloatingPointError, NonFiniteResultError) as error:  # a controller's numerics failed
            _check_finite(robot, qs[:-1], vs[:-1], qs[-1], vs[-1], dt)
            fastest = int(np.argmax(np.abs(vs[-1])))
            joint = robot.joint_names[max(0, min(fastest - (robot.nv - len(robot.joint_names)), len(robot.joint_names) - 1))]
            raise ControllerFailedError(t, step, joint, float(vs[-1][fastest]), str(error)) from None
        if step % _CHECK_EVERY == 0 or step == steps - 1:
            _check_finite(robot, qs, vs, q, v, dt)
    qs.append(q)
    vs.append(v)
    torques.append(torques[-1] if steps else stepper.zero)
    stepper.observe(steps * dt, q, v, torques[-1])
    accelerations.append(stepper.forward(steps * dt, q, v, torques[-1]))  # the last sample's own acceleration
    return qs, vs, accelerations, torques


def _simulate_pinocchio(
    robot: Robot,
    q: np.ndarray,
    v: np.ndarray,
    steps: int,
    dt: float,
    *,
    controller: Controller | None,
    integrator: str,
    external: Sequence[ExternalWrench],
    every: int | None,
    limits: str,
    observer: MomentumObserver | None,
    friction: bool = False,
) -> tuple[Trajectory, EngineRun]:
    """The run in Python over Pinocchio's ABA (checked state ``q``, ``v``; ``friction``: the
    joints' damping and stick-slip friction act)."""
    for item in external:
        robot.task_frame(item.frame, "an external wrench")
    if robot.massless_joints or _singular(robot, q):
        raise SingularMassMatrixError(robot.name, robot.massless_joints)
    joint_limits = JointLimits(robot)
    enforce = limits == "enforce"
    if enforce and controller is not None:
        commanded = controller
        controller = lambda t, q, v: joint_limits.saturate(np.asarray(commanded(t, q, v), dtype=float))  # noqa: E731
    joint_friction = JointFriction(robot) if friction else None
    stepper = _Stepper(
        robot, external, controller, hold=every is not None, rk4=integrator == "rk4", observer=observer, every=every or 1,
        friction=joint_friction,
    )  # fmt: skip
    if joint_friction is not None:
        joint_friction.start(stepper.accelerate, 0.0, q, v, stepper.torque(0.0, q, v))
    began = perf_counter()
    qs, vs, accelerations, torques = _integrate(robot, stepper, q, v, steps, dt, joint_limits if enforce else None)
    loop = perf_counter() - began
    trajectory = Trajectory(
        np.arange(steps + 1) * dt, np.array(qs), np.array(vs), np.array(accelerations), np.array(torques),
        list(robot.joint_names), robot.name,
    )  # fmt: skip
    return trajectory, EngineRun("pinocchio", "", loop, control_period=None if every is None else every * dt)


def _check_compiled_applies(
    robot: Robot, external: Sequence[ExternalWrench], limits: str, observer: MomentumObserver | None
) -> None:
    """Refuse, in one sentence, what ``engine="compiled"`` does not model."""
    if external:
        raise InputError("external", "no wrenches with engine='compiled' (use the Pinocchio engine)", f"{len(external)} wrenches")
    if limits == "enforce":
        raise InputError(
            "limits", "'warn' or 'ignore' with engine='compiled' (enforce runs on the Pinocchio engine)", "'enforce'"
        )
    if observer is not None:
        raise InputError("observer", "none with engine='compiled' (use the Pinocchio engine)", "an observer")


def _runs_in_c(controller: Controller, every: int | None) -> bool:
    """Whether a controller has a compiled twin the C loop evaluates at every stage
    (:func:`robodyn.compiled.has_twin`: PD, computed torque along a quintic, task space,
    operational space with a fixed target, impedance, LQR)."""
    from robodyn.compiled import has_twin

    return every in (None, 1) and has_twin(controller)


def _frame_law_in_c(controller: Controller | None, every: int | None) -> bool:
    """Whether the controller's compiled twin is a frame controller (task space, operational
    space, impedance: their compiled frame kinematics model fixed bases; PD and computed
    torque run on a floating base's joints, its base free, in C as in Python)."""
    return controller is not None and _runs_in_c(controller, every) and type(controller).__name__ not in _JOINT_LAWS


#: The controllers whose compiled twins also drive a floating robot's joints.
_JOINT_LAWS = ("PDGravity", "ComputedTorque")


@dataclass(frozen=True)
class _Compiled:
    """The compiled plant, the controller's compiled counterpart (``None``: Python or
    passive) and the time compiling them took in [s]."""

    plant: object
    law: object | None
    seconds: float


def _prepare_compiled(robot: Robot, controller: Controller | None, every: int | None) -> _Compiled:
    """Compile (or load from the cache) the plant and the controller's compiled twin."""
    from robodyn.compiled import compile, compiled_controller

    began = perf_counter()
    if robot.floating_base and _frame_law_in_c(controller, every):
        raise CompileError(robot.name, f"it has a floating base; {type(controller).__name__} compiles for fixed-base robots")
    plant = compile(robot)
    law = compiled_controller(controller) if controller is not None and _runs_in_c(controller, every) else None
    return _Compiled(plant, law, perf_counter() - began)


def _simulate_compiled(
    robot: Robot,
    q: np.ndarray,
    v: np.ndarray,
    steps: int,
    dt: float,
    controller: Controller | None,
    integrator: str,
    every: int | None,
    compiled: _Compiled,
    *,
    friction: bool = False,
) -> tuple[Trajectory, EngineRun]:
    """The run on compiled kernels: wholly in C when passive or under a compiled law, or a
    Python controller sampled every ``every`` steps (C between samples); else stage by
    stage from Python (the controller at every stage, the dynamics in C). ``friction``:
    the joints' damping acts (Coulomb friction was refused before)."""
    from robodyn.compiled import CompiledRobot, simulate_compiled

    plant = compiled.plant
    assert isinstance(plant, CompiledRobot)
    began = perf_counter()
    if controller is not None and compiled.law is None and every is None:
        forward = _compiled_accelerator(plant)
        if friction and robot.joint_damping.any():  # − b v as JointFriction adds it
            undamped, damping = forward, robot.joint_damping
            forward = lambda t, q, v, tau: undamped(t, q, v, tau - damping * v)  # noqa: E731
        stepper = _Stepper(robot, (), controller, hold=False, rk4=integrator == "rk4", forward=forward)
        qs, vs, accelerations, torques = _integrate(robot, stepper, q, v, steps, dt, None)
        arrays = (np.array(qs), np.array(vs), np.array(accelerations), np.array(torques))
    else:
        law = compiled.law if compiled.law is not None else controller
        run = simulate_compiled(
            plant, q, v, steps * dt, dt, integrator=integrator, controller=law,  # type: ignore[arg-type]
            control_period=None if compiled.law is not None or controller is None else every * dt,  # type: ignore[operator]
            hold=every is not None, joint_friction=friction,  # Coulomb friction refused before
        )  # fmt: skip
        arrays = (run.q, run.v, run.a, run.tau)
    loop = perf_counter() - began
    trajectory = Trajectory(np.arange(steps + 1) * dt, *arrays, list(robot.joint_names), robot.name)
    period = None if every is None else every * dt
    return trajectory, EngineRun("compiled", "", loop, compiled.seconds, period, compiled.law is not None)


def _compiled_accelerator(plant: object) -> Callable[[float, np.ndarray, np.ndarray, np.ndarray], np.ndarray]:
    """``a(t, q, v, tau)`` by the compiled forward dynamics: straight to C on float64
    contiguous finite arrays, else the checked call (its errors)."""
    fd, checked = plant.module.fd, plant.forward_dynamics  # type: ignore[attr-defined]

    def forward(t: float, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        a = fd(q, v, tau, 1)
        return a if a.__class__ is np.ndarray else checked(q, v, tau)

    return forward


def _check_finite(robot: Robot, qs: list[np.ndarray], vs: list[np.ndarray], q: np.ndarray, v: np.ndarray, dt: float) -> None:
    """Raise :class:`SimulationError` at the first non-finite state since the last check."""
    if math.isfinite(v.dot(v)) and math.isfinite(q.dot(q)):
        return
    states = [*zip(qs[-_CHECK_EVERY:], vs[-_CHECK_EVERY:], strict=True), (q, v)]
    first = len(qs) - len(states) + 1
    for offset, (q_i, v_i) in enumerate(states):
        if not (np.isfinite(q_i).all() and np.isfinite(v_i).all()):
            bad = (
                np.flatnonzero(~np.isfinite(v_i))
                if not np.isfinite(v_i).all()
                else np.flatnonzero(~np.isfinite(q_i[robot.nq - robot.nv :]))
            )
            joint = robot.joint_names[min(int(bad[0]) if bad.size else 0, len(robot.joint_names) - 1)]
            step = first + offset - 1
            if offset > 0 and _moderate(*states[offset - 1]) and _singular(robot, states[offset - 1][0]):
                raise SingularMassMatrixError(robot.name, robot.massless_joints)
            raise SimulationError(step * dt, step, joint)


def _moderate(q: np.ndarray, v: np.ndarray) -> bool:
    """A state that did not blow up (where a singular ``M`` is the reason, not overflow)."""
    return bool(np.abs(q).max(initial=0.0) < 1e6 and np.abs(v).max(initial=0.0) < 1e6)


def _singular(robot: Robot, q: np.ndarray) -> bool:
    """Whether ``M(q)`` is singular to working precision (no finite acceleration)."""
    eigenvalues = np.linalg.eigvalsh(robot.mass_matrix(q))
    return bool(eigenvalues[0] <= 1e-12 * max(abs(eigenvalues[-1]), np.finfo(float).tiny))


def _accelerator(
    robot: Robot, external: Sequence[ExternalWrench]
) -> Callable[[float, np.ndarray, np.ndarray, np.ndarray], np.ndarray]:
    """``a(t, q, v, tau)``: forward dynamics with the external wrenches' torques added.

    Calls Pinocchio without the boundary checks (the state was checked once, and the loop
    checks finiteness each step).
    """
    forward = robot.forward_dynamics_unchecked
    if not external:
        if robot.mimic is None:  # straight to Pinocchio's ABA
            import pinocchio as pin

            aba, model, data = pin.aba, robot.model, robot.data
            return lambda t, q, v, tau: aba(model, data, q, v, tau)
        return lambda t, q, v, tau: forward(q, v, tau)
    return lambda t, q, v, tau: forward(q, v, tau + external_torques(robot, q, t, external))


def _refuse_compiled_friction(robot: Robot) -> None:
    """Refuse the compiled engine for a robot whose joints have Coulomb friction (its loop
    in C has the damping but no stick–slip; ``joint_friction=False`` asks for the
    rigid-body motion)."""
    if robot.joint_friction.any():
        joints = [dof.name for dof in robot.dofs if dof.friction]
        listed = ", ".join(quoted(name) for name in joints[:8]) + (", …" if len(joints) > 8 else "")
        raise InputError(
            "engine",
            "'pinocchio' for joint Coulomb friction (the compiled loop has the damping, not stick-slip; "
            "joint_friction=False simulates the rigid-body motion compiled)",
            f"'compiled' for {quoted(robot.name)}, whose joints {listed} have some",
        )
