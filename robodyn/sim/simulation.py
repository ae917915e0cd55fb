"""Simulation: integrate the forward dynamics (ABA) of a robot in time.

:func:`simulate` advances ``(q, v)`` with a fixed step ``dt``, either by the classical
fourth-order Runge–Kutta method (``"rk4"``) or by semi-implicit (symplectic) Euler
(``"semi-implicit-euler"``: ``v ← v + dt a(q, v)``, then ``q ← q ⊕ dt v``). Positions move
on the configuration manifold (``Robot.integrate``: plain addition for joints, SE(3) for a
floating base).

One call is three steps, each in its module:

1. :func:`robodyn.sim.plan.plan` checks every argument once into a frozen
   :class:`~robodyn.sim.plan.RunPlan` (its parameters are :func:`simulate`'s);
2. :func:`robodyn.sim.engine.choose` names the backend: ``engine="pinocchio"``
   (:mod:`robodyn.sim.pinocchio_loop`, ABA per stage), ``"compiled"``
   (:mod:`robodyn.sim.compiled_backend`: passive runs and controllers with a compiled twin
   wholly in C; a Python controller called from Python at every stage around the compiled
   dynamics) or ``"auto"`` (the compiled one when the whole loop runs in C and the robot was
   compiled before; else the Pinocchio one, with the reason). ``engine="compiled"`` refuses
   what the compiled engine does not model (external wrenches, an observer, enforced
   limits, Coulomb friction, a floating base under a frame controller), naming it;
3. the backend returns plain arrays, which :func:`robodyn.sim.engine.run` wraps in a
   :class:`Trajectory` (one row a sample; saves to CSV and NPZ).

The controller is a continuous-time law evaluated wherever the integrator evaluates the
dynamics (every Runge–Kutta stage), in either engine; with ``hold=True`` it is sampled once
per step and its torque held during the step (zero-order hold), with ``control_period=``
every so many steps. External wrenches are evaluated at every stage. An ``observer=`` (a
:class:`~robodyn.sim.observer.MomentumObserver`) is updated once per step, at the state
actually reached, with the torque applied there.

Joint limits (``limits=``, see :mod:`robodyn.sim.limits`): ``"warn"`` (default) reports
every position, velocity and effort limit the run broke in one
:class:`~robodyn.exceptions.JointLimitWarning`; ``"enforce"`` saturates the torques at
the effort limits and stops joints at their position limits; ``"ignore"`` does neither.
Joint damping and Coulomb friction (``<dynamics>``) act by default (``joint_friction=False``:
the rigid-body motion); the compiled engine has the damping but no stick–slip.

A state that stops being finite ends the run with a :class:`SimulationError` saying when
and which joint, or a :class:`SingularMassMatrixError` when the mass matrix is singular
there (massless moving bodies: no step size helps).
"""

from __future__ import annotations

import functools
import inspect
from collections.abc import Callable
from typing import Any, Literal, ParamSpec, TypeVar

import numpy as np

from robodyn.exceptions import SimulationError, SingularMassMatrixError
from robodyn.sim import engine as engines
from robodyn.sim.engine import EngineRun
from robodyn.sim.observer import MomentumObserver
from robodyn.sim.plan import (
    ENGINES,
    INTEGRATORS,
    Controller,
    Engine,
    ExternalWrench,
    Integrator,
    RunPlan,
    external_torques,
    plan,
)
from robodyn.sim.stability import largest_stable_step, round_step
from robodyn.trajectory import Trajectory

__all__ = [
    "ENGINES", "INTEGRATORS", "Controller", "Engine", "EngineRun", "ExternalWrench", "Integrator", "SimulationError",
    "SingularMassMatrixError", "choose_engine", "external_torques", "simulate", "simulate_run",
]  # fmt: skip

_P = ParamSpec("_P")
_R = TypeVar("_R")


def _from_plan(builder: Callable[_P, RunPlan]) -> Callable[[Callable[[RunPlan], _R]], Callable[_P, _R]]:
    """Give a function of a plan the builder's parameters: ``f(*args, **kwargs)`` is
    ``f(builder(*args, **kwargs))`` (so the run's parameters are written once, in :func:`plan`)."""

    def decorate(body: Callable[[RunPlan], _R]) -> Callable[_P, _R]:
        @functools.wraps(body)
        def call(*args: _P.args, **kwargs: _P.kwargs) -> _R:
            return body(builder(*args, **kwargs))

        returns = inspect.signature(body).return_annotation
        call.__signature__ = inspect.signature(builder).replace(return_annotation=returns)  # type: ignore[attr-defined]
        return call

    return decorate


@_from_plan(plan)
def simulate(run_plan: RunPlan) -> Trajectory:
    """Simulate a robot from ``(q0, v0)`` for ``duration`` seconds.

    ``simulate(robot, q0, v0, duration, dt, *, controller=None, integrator="rk4",
    external=(), hold=False, limits="warn", engine="auto", control_period=None,
    observer=None, joint_friction=True)``: the arguments of :func:`robodyn.sim.plan.plan`,
    which documents each. Both engines evaluate the controller at every integrator stage
    unless ``hold`` or ``control_period`` asks for sampling and holding it, and give the
    same trajectory (to ~1e-12). :func:`simulate_run` also says which engine ran, why, and
    how long the loop and the compilation took.

    Returns:
        The trajectory, ``round(duration / dt) + 1`` samples from ``t = 0`` (``tau`` is
        the applied torque: saturated with ``limits="enforce"``).

    Raises:
        InputError: For bad initial states, step, integrator, limits mode, engine or
            control period, or a duration that is not a whole number of steps (to 1e-9
            relative); with ``engine="compiled"``, for what it does not model.
        CompileError: With ``engine="compiled"``, when the build fails.
        FrameError: An external wrench on a frame that is unknown or that no joint moves.
        SingularMassMatrixError: If the mass matrix is singular (no motion is defined).
        SimulationError: If the state stops being finite (``ControllerFailedError``: if
            the controller's own numerics fail, e.g. a singular solve on a blown-up state);
            when ``dt`` was above the largest stable step at the start, it names that step,
            the joint and the cause (gains, damping on light links).

    Warns:
        JointLimitWarning: With ``limits="warn"``, when a limit was broken.
    """
    return _run(run_plan)[0]


@_from_plan(plan)
def simulate_run(run_plan: RunPlan) -> tuple[Trajectory, EngineRun]:
    """:func:`simulate`, also saying which engine ran, why, and the loop's and the
    compilation's wall-clock times (:class:`EngineRun`). Errors and warnings are
    :func:`simulate`'s; the arguments, those of :func:`robodyn.sim.plan.plan`, which
    documents each."""
    return _run(run_plan)


def _run(run_plan: RunPlan) -> tuple[Trajectory, EngineRun]:
    """:func:`robodyn.sim.engine.run`; a divergence from a step above the largest stable one
    at the start is re-raised naming it, its joint and its cause (gains, damping on light
    links: :func:`robodyn.sim.stability.largest_stable_step`)."""
    try:
        return engines.run(run_plan)
    except SimulationError as error:
        found = largest_stable_step(run_plan) if type(error) is SimulationError else None
        if found is None or run_plan.dt <= found[0]:
            raise
        limit, joint, cause = found
        advice = (
            f"dt = {run_plan.dt:.3g} s is above the largest stable step at the start, about {limit:.2g} s (its fastest "
            f"mode, mostly joint {joint!r}, set by {cause}): use dt <= {limit:.2g} s (e.g. {round_step(limit):g} s)"
        )
        raise SimulationError(error.time, error.step, error.joint, advice) from None


def choose_engine(
    robot: Any,
    controller: Controller | None,
    *,
    external: tuple[ExternalWrench, ...] | list[ExternalWrench] = (),
    limits: str = "warn",
    observer: MomentumObserver | None = None,
    every: int | None = None,
    joint_friction: bool = False,
) -> tuple[Literal["pinocchio", "compiled"], str]:
    """The engine ``engine="auto"`` runs for a robot and controller, and why
    (:func:`robodyn.sim.engine.choose` of their plan, at the robot's start).

    Args:
        robot: The plant.
        controller: The controller (``None``: passive).
        external, limits, observer, joint_friction: As for :func:`simulate`.
        every: Steps between two samples of a held controller (``None``: every stage).
    """
    state = (robot.default_configuration(), np.zeros(robot.nv))
    period = {"control_period": float(every)} if every is not None and controller is not None else {}
    return engines.choose(
        plan(robot, *state, 0.0, 1.0, controller=controller, external=external, limits=limits,  # type: ignore[arg-type]
             observer=observer, joint_friction=joint_friction, **period)  # type: ignore[arg-type]
    )  # fmt: skip
