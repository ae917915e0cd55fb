"""A simulation run's plan: everything :func:`robodyn.simulate` was asked, checked once.

:func:`plan` validates the arguments of a run (the state, the step count, the integrator,
the controller's sampling, the limits mode, the joint dynamics, the external wrenches, the
observer, the engine asked for) into one frozen :class:`RunPlan`. A backend — the Pinocchio
loop (:mod:`robodyn.sim.pinocchio_loop`) or the compiled one
(:mod:`robodyn.sim.compiled_backend`) — runs a plan and returns plain arrays; each says
what it cannot run in ``unsupported(plan) -> list[str]``; :mod:`robodyn.sim.engine`
chooses between them (the way MuJoCo's ``rollout`` separates the plan from the loop).

New physics (contacts, constraints) is one more field here, checked in :func:`plan`, and
one backend change: the loop that models it, and the other backend's ``unsupported``
naming it until it does.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Literal, NamedTuple

import numpy as np

from robodyn.common.text import counted, quoted
from robodyn.compiled.loop_rules import INTEGRATORS, Integrator, check_integrator, period_steps, step_count
from robodyn.compiled.simulation import SimulationArrays
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError
from robodyn.sim.contact_checks import check_contact_run
from robodyn.sim.ground import ContactPoint, Contacts, Ground, resolve_ground
from robodyn.sim.joint_friction import has_joint_friction
from robodyn.sim.limits import LimitMode, check_mode
from robodyn.sim.observer import MomentumObserver

#: A controller maps time in [s], q and v to joint torques, shape (nv,).
Controller = Callable[[float, np.ndarray, np.ndarray], np.ndarray]
#: Where the loop runs: Python over Pinocchio, or C (:mod:`robodyn.compiled`); ``"auto"``
#: chooses (:func:`robodyn.sim.engine.choose`).
Engine = Literal["auto", "pinocchio", "compiled"]
ENGINES: tuple[Engine, ...] = ("auto", "pinocchio", "compiled")

__all__ = ["ENGINES", "INTEGRATORS", "Controller", "Engine", "ExternalWrench", "Integrator", "Outcome", "RunPlan", "plan"]


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
        """The wrench at a time, shape (6,) or (3,).

        Args:
            time: Simulation time in [s].
        """
        return np.asarray(self.wrench(time) if callable(self.wrench) else self.wrench, dtype=float)


def external_torques(robot: Robot, q: np.ndarray, time: float, external: Sequence[ExternalWrench]) -> np.ndarray:
    """Sum of ``J(q)ᵀ w`` over external wrenches at a time, shape (nv,).

    Args:
        robot: The simulated robot.
        q: Configuration, shape (nq,), in [rad] / [m].
        time: Simulation time in [s].
        external: The external wrenches.
    """
    total = np.zeros(robot.nv)
    for item in external:
        total += robot.wrench_torques(q, item.frame, item.value(time))
    return total


@dataclass(frozen=True)
class RunPlan:
    """One run, checked: what every backend reads.

    Attributes:
        robot: The plant.
        q0: Initial configuration, shape (nq,); v0: initial velocity, shape (nv,).
        dt: Step in [s]; steps: how many (the run has ``steps + 1`` samples).
        integrator: ``"rk4"`` or ``"semi-implicit-euler"``.
        controller: ``controller(t, q, v) -> tau``, ``None`` when passive.
        every: Steps between two samples of a held controller; ``None``: evaluated at every
            integrator stage (or passive).
        limits: ``"warn"``, ``"enforce"`` or ``"ignore"``.
        friction: Whether the joints' damping and Coulomb friction act (asked for, and the
            robot has some).
        external: Wrenches the environment applies.
        observer: A momentum observer fed every sample, or ``None``.
        engine: The engine asked for (``"auto"``, ``"pinocchio"`` or ``"compiled"``).
        ground: The plane the robot touches (:mod:`robodyn.sim.ground`), or ``None``.
        contacts: The robot's points that touch it (and what of its collision geometry
            they leave out); ``None`` without a ground.
    """

    robot: Robot
    q0: np.ndarray
    v0: np.ndarray
    dt: float
    steps: int
    integrator: Integrator
    controller: Controller | None
    every: int | None
    limits: LimitMode
    friction: bool
    external: tuple[ExternalWrench, ...]
    observer: MomentumObserver | None
    engine: Engine
    ground: Ground | None = None
    contacts: Contacts | None = None

    @property
    def rk4(self) -> bool:
        """Whether the integrator is classical Runge–Kutta (else semi-implicit Euler)."""
        return self.integrator == "rk4"

    @property
    def control_period(self) -> float | None:
        """The period in [s] the controller is sampled and held at; ``None``: every stage."""
        return None if self.every is None else self.every * self.dt

    @property
    def coulomb(self) -> bool:
        """Whether joints' Coulomb friction (stick–slip) acts in this run."""
        return self.friction and bool(self.robot.joint_friction.any())

    @property
    def damping(self) -> np.ndarray | None:
        """The joints' damping ``b`` acting in this run, shape (nv,); ``None``: none."""
        return self.robot.joint_damping if self.friction and self.robot.joint_damping.any() else None

    def times(self) -> np.ndarray:
        """The samples' times in [s], shape (steps + 1,)."""
        return np.arange(self.steps + 1) * self.dt


class Outcome(NamedTuple):
    """What a backend returns: the run's arrays, the loop's wall-clock time in [s] and
    whether the controller ran in C."""

    arrays: SimulationArrays
    loop_time: float
    controller_in_c: bool = False
    contact: Any = None  # a contact run's robodyn.sim.contact_run.ContactSimulation
    constrained: Any = None  # a constrained run's robodyn.sim.constrained.ConstrainedSimulation


def plan(
    robot: Robot,
    q0: np.ndarray,
    v0: np.ndarray,
    duration: float,
    dt: float,
    *,
    controller: Controller | None = None,
    integrator: Integrator | None = None,
    external: Sequence[ExternalWrench] = (),
    hold: bool = False,
    limits: LimitMode = "warn",
    engine: Engine = "auto",
    control_period: float | None = None,
    observer: MomentumObserver | None = None,
    joint_friction: bool = True,
    ground: Ground | str | None = None,
    contacts: str | Sequence[str | ContactPoint] = "collision",
) -> RunPlan:
    """Check a run's arguments, once, into its plan.

    Args:
        robot: The plant.
        q0: Initial configuration, shape (nq,).
        v0: Initial velocity, shape (nv,).
        duration: Simulated time in [s], a whole number of steps (to 1e-9 relative).
        dt: Step in [s].
        controller: ``controller(t, q, v) -> tau``; ``None`` for zero torque (passive).
        integrator: ``"rk4"`` or ``"semi-implicit-euler"``; default ``"rk4"``, or with a
            ``ground`` ``"semi-implicit-euler"`` (the contact step's scheme, the only one).
        external: Wrenches the environment applies (constant or functions of time), each
            at a frame some joint moves.
        hold: Sample the controller once per step and hold its torque (zero-order hold)
            instead of evaluating it at every integration stage (``control_period=dt``).
        limits: ``"warn"``, ``"enforce"`` or ``"ignore"`` (see :mod:`robodyn.sim.limits`).
        engine: ``"auto"`` (default: :func:`robodyn.sim.engine.choose`), ``"pinocchio"``
            (the loop in Python, ABA per stage) or ``"compiled"`` (:mod:`robodyn.compiled`;
            refused, naming the reason, for what it does not model:
            :func:`robodyn.sim.compiled_backend.unsupported`).
        control_period: Sample the controller every ``control_period`` [s] (a whole
            number of steps) and hold its torque in between, in either engine; ``None``:
            evaluate it continuously.
        observer: A momentum observer fed every sample (time, state, applied torque) as
            the run goes; afterwards ``observer.residuals`` holds its estimate of the
            external torques at each sample. Give it ``torque="held"`` with ``hold`` or a
            ``control_period``, ``"sampled"`` otherwise.
        joint_friction: Honour the joints' damping and Coulomb friction
            (:attr:`Robot.joint_damping`, :attr:`Robot.joint_friction`: ``−b v``, and
            stick–slip friction up to ``±f``, :mod:`robodyn.sim.joint_friction`); ``False``
            gives the rigid-body motion.
        ground: A :class:`~robodyn.sim.ground.Ground` the robot stands on (contact with
            friction, :mod:`robodyn.sim.contact`; the Pinocchio engine only); ``"file"``:
            the plane the robot's file states (an MJCF's, :func:`~robodyn.sim.ground.resolve_ground`);
            ``None``: none.
        contacts: With a ground, the points that touch it: ``"collision"`` (the URDF's
            collision spheres and boxes) or frame names / ``ContactPoint`` values.

    Raises:
        InputError: For a bad initial state, step, duration, integrator, limits mode,
            engine or control period (or one given without a controller).
        FrameError: An external wrench on a frame that is unknown or that no joint moves.
        InputError: A robot with constraints (closed loops, welds: ``robot.constraints``)
            with what its loop does not model (another integrator than RK4, a control period,
            enforced limits, an observer, a ground, Coulomb friction).
    """
    ground = resolve_ground(robot, ground)
    integrator = integrator or ("semi-implicit-euler" if ground is not None else "rk4")
    check_integrator(integrator)
    check_mode(limits)
    if engine not in ENGINES:
        raise InputError("engine", f"one of {', '.join(ENGINES)}", repr(engine))
    steps = step_count(duration, dt)
    if control_period is not None and controller is None:
        raise InputError("control_period", "given only with a controller (a passive run samples nothing)", repr(control_period))
    every = period_steps(control_period, dt) if control_period is not None else (1 if hold and controller is not None else None)
    (q, v), _ = robot.validate(q=q0, v=v0)
    if q.ndim != 1:
        raise InputError("q0", "one state (1-D)", f"shape {q.shape}")
    for item in external:
        robot.task_frame(item.frame, "an external wrench")
    _check_constrained(robot, integrator, every, limits, observer, ground)
    found = check_contact_run(robot, ground, contacts, q0=q, integrator=integrator, every=every, limits=limits, observer=observer)
    return RunPlan(
        robot, q, v, float(dt), steps, integrator, controller, every, limits, joint_friction and has_joint_friction(robot),
        tuple(external), observer, engine, ground, found,
    )  # fmt: skip


def _check_constrained(robot: Robot, integrator: str, every: int | None, limits: str, observer: object, ground: object) -> None:
    """Refuse what a robot with constraints (its file's ``<equality>``, ``load(constraints=)``)
    cannot be simulated with: the constrained loop is RK4 plus a projection, evaluates the
    controller at every stage, and models no ground, enforced limits, observer or Coulomb
    friction (simulating the open tree instead would be a different mechanism). A ground
    is refused first: no integrator serves both, so naming one would send a user in circles."""
    if not robot.constraints:
        return
    names = ", ".join(quoted(c.name or type(c).__name__) for c in robot.constraints[:4])
    held = f"{robot.name} has {counted(len(robot.constraints), 'constraint')} ({names})"
    refusals = [
        (
            "ground",
            ground is not None,
            "left out for a robot with constraints (constraints= or the file's <equality>; "
            "a ground and constraints together are not modelled)",
            held,
        ),
        (
            "integrator",
            integrator != "rk4",
            "'rk4' for a robot with constraints (RK4, then a projection onto them)",
            repr(integrator),
        ),
        (
            "control_period",
            every not in (None, 1),
            "left out for a robot with constraints (the controller runs at every stage)",
            held,
        ),
        ("limits", limits == "enforce", "'warn' or 'ignore' for a robot with constraints", repr(limits)),
        ("observer", observer is not None, "left out for a robot with constraints", held),
    ]
    for name, refused, expected, received in refusals:
        if refused:
            raise InputError(name, expected, received)
    if robot.joint_friction.any():
        raise InputError(
            "joint_friction",
            "False for a robot with constraints and Coulomb friction (stick-slip is not modelled with loops)",
            held,
        )
