"""The compiled backend: a run plan on a robot's compiled kernels (:mod:`robodyn.compiled`).

Passive runs and controllers that own a compiled twin (``twin_refusal()`` is ``None``,
evaluated at every stage or once a step) run wholly in C; a Python controller sampled every
control period is called from Python between C stretches; one evaluated at every stage is
called from Python around the compiled forward dynamics (the loop of
:mod:`robodyn.sim.python_loop`). :func:`unsupported` names what it does not model; the
engine choice (:mod:`robodyn.sim.engine`) adds :func:`not_ready` for ``engine="auto"``,
which never starts a cold compile. Nothing here imports the code generator until a run is
prepared (:func:`prepare`).
"""

from __future__ import annotations

import functools
import os
import shutil
from collections.abc import Callable
from dataclasses import dataclass
from time import perf_counter
from typing import TYPE_CHECKING

import numpy as np

from robodyn.common.text import quoted
from robodyn.compiled.build import is_compiled, loaded
from robodyn.compiled.controllers import CompiledLaw, HasTwin
from robodyn.compiled.loop_rules import damped
from robodyn.compiled.simulation import SimulationArrays, law_torque, simulate_checked
from robodyn.dynamics.robot import Robot
from robodyn.sim.plan import Outcome, RunPlan
from robodyn.sim.python_loop import Forward, Stepper, integrate
from robodyn.sim.twin import fixed_base_only

if TYPE_CHECKING:
    from robodyn.compiled.robot import CompiledRobot


class Reason(str):
    """One thing the compiled engine does not model in a plan: a phrase (a ``str``) that
    knows the plan parameter asking for it (``parameter``), so ``engine="compiled"`` is
    refused naming that parameter."""

    parameter: str

    def __new__(cls, text: str, parameter: str) -> Reason:
        reason = super().__new__(cls, text)
        reason.parameter = parameter
        return reason


def unsupported(plan: RunPlan) -> list[str]:
    """What the compiled engine does not model in a plan, each one phrase (a :class:`Reason`
    naming its parameter; empty: it runs it).

    Args:
        plan: The checked simulation request (robot, controller, options).
    """
    controller, robot = plan.controller, plan.robot
    reasons: list[str] = []
    if robot.floating_base and fixed_base_only(controller) and plan.every in (None, 1):
        reasons.append(
            Reason(f"a floating base under {type(controller).__name__} (its compiled twin models fixed bases)", "controller")
        )
    refusals = [
        (bool(plan.external), "external wrenches", "external"),
        (plan.observer is not None, "a momentum observer", "observer"),
        (plan.limits == "enforce", "limits enforced", "limits"),
        (plan.ground is not None, "contact with a ground", "ground"),
    ]
    reasons += [Reason(f"{what} (the compiled engine models none)", name) for refused, what, name in refusals if refused]
    if plan.coulomb:
        joints = [dof.name for dof in robot.dofs if dof.friction]
        listed = ", ".join(quoted(name) for name in joints[:8]) + (", …" if len(joints) > 8 else "")
        text = (
            f"joint Coulomb friction ({listed}: the compiled loop has the damping, not stick-slip; "
            "joint_friction=False simulates the rigid-body motion compiled)"
        )
        reasons.append(Reason(text, "joint_friction"))
    if robot.constraints:
        reasons.append(Reason("closed loops or welds (robot.constraints: the compiled engine models none)", "engine"))
    if robot.massless_joints or robot.nv == 0:
        reasons.append(Reason("no moving mass to compile (the compiled engine models none)", "engine"))
    return reasons


def twin_runs(plan: RunPlan) -> bool:
    """Whether the plan's controller runs in C: it owns a twin and is evaluated at every
    stage or sampled once a step.

    Args:
        plan: The checked simulation request (robot, controller, options).
    """
    controller = plan.controller
    return (
        controller is not None
        and isinstance(controller, HasTwin)
        and plan.every in (None, 1)
        and controller.twin_refusal() is None
    )


def not_ready(plan: RunPlan) -> list[str]:
    """Why ``engine="auto"`` would not choose the compiled engine for a plan it can run:
    a Python controller (the same stage-by-stage calls in either engine), no C compiler, or
    the robot not compiled before (a cache lookup: no code generator is loaded).

    Args:
        plan: The checked simulation request (robot, controller, options).
    """
    if plan.controller is not None and not twin_runs(plan):
        return ["a Python controller (called from Python at every stage in either engine)"]
    candidates = (os.environ["CC"],) if os.environ.get("CC") else ("cc", "gcc", "clang")
    if not _compiler_on_path(candidates, os.environ.get("PATH")):
        return [f"no C compiler (none of {', '.join(candidates)} on the PATH)"]
    model = getattr(plan.controller, "model", None)
    models = [plan.robot] if not isinstance(model, Robot) else [plan.robot, model]
    if not all(loaded(each) is not None or is_compiled(each) for each in models):
        return ["not compiled yet (engine='compiled' builds it once, in seconds to minutes; auto uses it from then on)"]
    return []


@functools.lru_cache(maxsize=8)
def _compiler_on_path(candidates: tuple[str, ...], path: str | None) -> bool:
    """Whether one of the compilers is on the PATH (a search of the folders, remembered for
    this PATH: every ``engine="auto"`` run asks)."""
    return any(shutil.which(candidate, path=path) for candidate in candidates)


def ready_reason(plan: RunPlan) -> str:
    """Why auto chose the compiled engine, one phrase.

    Args:
        plan: The checked simulation request (robot, controller, options).
    """
    what = "passive" if plan.controller is None else f"{type(plan.controller).__name__} in C"
    return f"{'floating' if plan.robot.floating_base else 'fixed'} base, {what}, compiled before (cached)"


@dataclass(frozen=True)
class Prepared:
    """The compiled plant and the controller's twin (``None``: passive, or a Python controller)."""

    plant: CompiledRobot
    twin: CompiledLaw | None


def prepare(plan: RunPlan) -> Prepared:
    """Compile (or load from the cache) the plant and the controller's twin.

    Args:
        plan: The checked simulation request (robot, controller, options).

    Raises:
        CompileError: If a build fails (``CompilerNotFoundError``: no C compiler).
    """
    from robodyn.compiled.robot import compile

    plant = compile(plan.robot)
    twin = plan.controller.compiled() if twin_runs(plan) else None  # type: ignore[union-attr]
    return Prepared(plant, twin)


def twin_torque(prepared: Prepared) -> Callable[[np.ndarray, np.ndarray], np.ndarray] | None:
    """The prepared controller's torque ``tau(0, q, v)`` by its twin in C (``None``: no twin
    runs), for the step check's screen (:func:`robodyn.sim.stability.step_warning`).

    Args:
        prepared: The plant and the twin, from :func:`prepare`.
    """
    return None if prepared.twin is None else law_torque(prepared.plant, prepared.twin)


def run(plan: RunPlan, prepared: Prepared) -> Outcome:
    """Integrate the plan on the compiled kernels (prepared by :func:`prepare`).

    Args:
        plan: The checked simulation request (robot, controller, options).
        prepared: The compiled plant and twin (:func:`prepare`).

    Raises:
        SimulationError: If the state stops being finite.
    """
    began = perf_counter()
    if plan.controller is not None and prepared.twin is None and plan.every is None:
        arrays = _stage_by_stage(plan, prepared.plant)
    else:
        law = prepared.twin if prepared.twin is not None else plan.controller
        sampled = prepared.twin is None and plan.controller is not None
        damping = plan.damping  # Coulomb friction: unsupported, refused before
        arrays = simulate_checked(
            prepared.plant, plan.q0, plan.v0, plan.steps, plan.dt, integrator=plan.integrator, controller=law,
            control_period=plan.control_period if sampled else None, hold=plan.every is not None,
            damping=None if damping is None else np.ascontiguousarray(damping, dtype=float),
        )  # fmt: skip
    return Outcome(arrays, perf_counter() - began, prepared.twin is not None)


def _stage_by_stage(plan: RunPlan, plant: CompiledRobot) -> SimulationArrays:
    """A Python controller called at every stage around the compiled forward dynamics."""
    forward = _accelerator(plant)
    damping = plan.damping
    if damping is not None:  # − b v as JointFriction adds it
        undamped = forward
        forward = lambda t, q, v, tau: undamped(t, q, v, damped(tau, damping, v))  # noqa: E731
    stepper = Stepper(plan.robot, forward, plan.controller, hold=False, rk4=plan.rk4)
    arrays = integrate(plan.robot, stepper, plan.q0, plan.v0, plan.steps, plan.dt, None)
    return SimulationArrays(plan.times(), *arrays)


def _accelerator(plant: CompiledRobot) -> Forward:
    """``a(t, q, v, tau)`` by the compiled forward dynamics: straight to C on float64
    contiguous finite arrays, else the checked call (its errors)."""
    fd, checked = plant.module.fd, plant.forward_dynamics

    def forward(t: float, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        a = fd(q, v, tau, 1)
        return a if a.__class__ is np.ndarray else checked(q, v, tau)

    return forward
