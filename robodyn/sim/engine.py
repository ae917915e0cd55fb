"""The engine choice and the run: a plan handed to the backend that runs it.

:func:`choose` names the backend for a plan and why (``engine="auto"``: the compiled one
when the whole loop runs in C there, the robot was compiled before and a C compiler exists,
else the Pinocchio one, with the first reason); :func:`run` runs the plan on it, wraps the
arrays in a :class:`~robodyn.trajectory.Trajectory` and reports the joint limits broken.
Choosing costs a cache lookup (:mod:`robodyn.compiled.lookup`), never the code generator.
"""

from __future__ import annotations

import warnings
import weakref
from dataclasses import dataclass
from time import perf_counter
from typing import Any, Literal

import numpy as np

from robodyn.exceptions import CompileError, InputError, JointLimitWarning, RobodynWarning
from robodyn.sim import compiled_backend, pinocchio_loop
from robodyn.sim.limits import TOLERANCE, JointLimits, warning_text
from robodyn.sim.plan import Outcome, RunPlan
from robodyn.sim.stability import step_warning, task_warning
from robodyn.trajectory import Trajectory


@dataclass(frozen=True)
class EngineRun:
    """How a run went: the engine that ran, why, and where the time went.

    Attributes:
        engine: ``"pinocchio"`` or ``"compiled"``: the engine that ran.
        reason: Why that engine, one sentence (with ``engine="auto"``: why it was chosen).
        loop_time: Wall-clock time of the integration loop alone, in [s].
        compile_time: Wall-clock time spent choosing the engine and compiling (or loading
            the cached) kernels, in [s] (0 when ``engine="pinocchio"`` was asked for).
        control_period: The period in [s] at which the controller was sampled and its
            torque held; ``None`` when it was evaluated at every integrator stage (or there
            is none).
        controller_in_c: Whether the controller ran in C (passive runs: ``False``).
        contact: A run on the ground: its contact forces, gaps and summary
            (:class:`robodyn.sim.contact_run.ContactSimulation`); ``None`` without a ground.
        constrained: A run with constraints: its multipliers and residual
            (:class:`robodyn.sim.constrained.ConstrainedSimulation`); else ``None``.
    """

    engine: Literal["pinocchio", "compiled"]
    reason: str
    loop_time: float
    compile_time: float = 0.0
    control_period: float | None = None
    controller_in_c: bool = False
    contact: Any = None
    constrained: Any = None


def choose(plan: RunPlan) -> tuple[Literal["pinocchio", "compiled"], str]:
    """The engine a plan runs on, and why (one phrase).

    Args:
        plan: The checked simulation request (robot, controller, options).

    Raises:
        InputError: With ``engine="compiled"``, for what the compiled engine does not
            model (:func:`robodyn.sim.compiled_backend.unsupported`'s first reason).
    """
    if plan.engine == "pinocchio":
        return "pinocchio", "asked for (engine='pinocchio')"
    reasons = compiled_backend.unsupported(plan)
    if plan.engine == "compiled":
        if reasons:
            first = reasons[0]
            parameter = getattr(first, "parameter", "engine")
            if parameter == "engine":
                raise InputError("engine", f"'pinocchio' or 'auto' for a run with {first}", "'compiled'")
            raise InputError(parameter, f"left out for engine='compiled': {first}", "given")
        return "compiled", "asked for (engine='compiled')"
    reasons += compiled_backend.not_ready(plan)
    if reasons:
        return "pinocchio", reasons[0]
    return "compiled", compiled_backend.ready_reason(plan)


def run(plan: RunPlan) -> tuple[Trajectory, EngineRun]:
    """Run a plan on the engine :func:`choose` names: the trajectory and how it went.

    Args:
        plan: The checked simulation request (robot, controller, options).

    Raises:
        CompileError: With ``engine="compiled"``, if the build fails (with ``"auto"`` the
            run falls back to the Pinocchio engine, saying why).
        SingularMassMatrixError, SimulationError: As :func:`robodyn.simulate`.

    Warns:
        RobodynWarning: At the start, when the step exceeds the largest stable step of the
            fastest mode, or an operational-space task starts near a singularity
            (:mod:`robodyn.sim.stability`).
        JointLimitWarning: With ``limits="warn"``, for the limits the run broke.
    """
    began = perf_counter()
    engine, reason = choose(plan)
    prepared: compiled_backend.Prepared | None = None
    if engine == "compiled":
        try:
            prepared = compiled_backend.prepare(plan)
        except CompileError as error:  # CompilerNotFoundError included
            if plan.engine == "compiled":
                raise
            engine, reason = "pinocchio", f"the compiled engine does not apply: {error}"
    compile_time = 0.0 if plan.engine == "pinocchio" else perf_counter() - began
    law = None if prepared is None else compiled_backend.twin_torque(prepared)  # the screen's feedback in C
    for sentence in (step_warning(plan, law), task_warning(plan)):  # stack level 4: the caller of simulate
        if sentence:
            warnings.warn(RobodynWarning(sentence), stacklevel=4)
    outcome: Outcome = pinocchio_loop.run(plan) if prepared is None else compiled_backend.run(plan, prepared)
    robot = plan.robot
    trajectory = Trajectory(plan.times(), *outcome.arrays[1:], list(robot.joint_names), robot.name)
    violations = [] if plan.limits == "ignore" else _violations(robot, trajectory)
    if violations:  # stack level 4: the caller of simulate / simulate_run
        warnings.warn(JointLimitWarning(warning_text(robot.name, violations), violations), stacklevel=4)
    return trajectory, EngineRun(
        engine, reason, outcome.loop_time, compile_time, plan.control_period, outcome.controller_in_c, outcome.contact,
        outcome.constrained,
    )  # fmt: skip


#: Per robot: its ``dofs`` (the limits' source, a tuple of frozen values) and the screen's
#: thresholds (:func:`_thresholds`), so a run reads them instead of rebuilding them.
_THRESHOLDS: weakref.WeakKeyDictionary[Any, tuple[tuple, tuple[np.ndarray, ...]]] = weakref.WeakKeyDictionary()


def _thresholds(robot: Any) -> tuple[np.ndarray, ...]:
    """The screen's bounds of a robot: position lower and upper (the joints' coordinates),
    speed and effort (per velocity coordinate), each moved outward by half the tolerance
    :meth:`JointLimits.violations` allows (±inf where unlimited). Cached per robot while its
    ``dofs`` are the same object."""
    cached = _THRESHOLDS.get(robot)
    if cached is not None and cached[0] is robot.dofs:
        return cached[1]
    limits = JointLimits(robot)
    slack = [0.5 * TOLERANCE * (1.0 + np.abs(bound)) for bound in (limits.lower, limits.upper, limits.velocity, limits.effort)]
    found = (limits.lower - slack[0], limits.upper + slack[1], limits.velocity + slack[2], limits.effort + slack[3])
    _THRESHOLDS[robot] = (robot.dofs, found)
    return found


def _violations(robot: Any, trajectory: Trajectory) -> list:
    """``JointLimits(robot).violations(trajectory)``, skipped (``[]``) when a whole-array
    screen finds nothing beyond any threshold of :func:`_thresholds` (half the tolerance the
    violations allow, so everything they would report passes the screen)."""
    lower, upper, speed, effort = _thresholds(robot)
    joints = trajectory.q[:, trajectory.q.shape[1] - lower.size :]
    beyond = bool((joints < lower).any() or (joints > upper).any() or (np.abs(trajectory.v) > speed).any())
    if not beyond and trajectory.tau is not None:
        beyond = bool((np.abs(trajectory.tau) > effort).any())
    return JointLimits(robot).violations(trajectory) if beyond else []
