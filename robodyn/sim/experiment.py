"""A simulation experiment: a robot, a controller aiming at a target, and what came of it.

:func:`run_simulation` builds the chosen controller (on its own copy of the model),
simulates, and returns the trajectory with a :class:`~robodyn.sim.report.SimulationSummary`:
final error, peak torque, energy change, real-time factor, and every joint limit the run
broke (joint, first time, worst value, limit; ``limits="enforce"`` saturates torques and stops joints,
see :mod:`robodyn.sim.limits`). Used by ``robodyn simulate``.

The sequel's controllers (:mod:`robodyn.sim.operational_space`): ``"osc"`` drives the
frame to a position or a full pose (``target`` X,Y,Z[,ROLL,PITCH,YAW]) with an optional
``posture`` in the null space; ``"impedance"`` holds it there as a spring of ``stiffness``.
``force_at`` pushes (``T:FX,FY,FZ[@FRAME]``) become
:class:`~robodyn.sim.simulation.ExternalWrench` es; the summary reports the final pose
error (by the robot's forward kinematics) and, for the impedance under a push, the
deflection against ``K⁻¹ F``. ``observer_gain`` runs a
:class:`~robodyn.sim.observer.MomentumObserver` along the simulation.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import replace
from typing import Any, Literal

import numpy as np

from robodyn.common.text import counted
from robodyn.dynamics.loading import rebuild
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError, JointLimitWarning
from robodyn.sim.contact_checks import start_above
from robodyn.sim.contact_run import ground_lines
from robodyn.sim.control import LQR, ComputedTorque, PDGravity, TaskSpace, joint_target, quintic_reference
from robodyn.sim.gains import LQR_ACCELERATION as LQR_ACCELERATION
from robodyn.sim.gains import computed_torque_gains, lqr_weights, pd_defaults, pd_gains
from robodyn.sim.ground import Ground, resolve_ground
from robodyn.sim.limits import LimitMode, check_mode, limit_violations
from robodyn.sim.observer import MomentumObserver, TorqueMode
from robodyn.sim.operational_space import Impedance, OperationalSpace
from robodyn.sim.reach import check_reach
from robodyn.sim.report import Push, SimulationSummary
from robodyn.sim.requests import TrajectoryReference, check_planar, pose_target, push_wrenches, task_target, tracked
from robodyn.sim.requests import applied_torques as applied_torques  # robodyn.viz.experiment imports it here
from robodyn.sim.requests import observer_outcome as observer_outcome
from robodyn.sim.simulation import Engine, Integrator, simulate_run
from robodyn.sim.stand_run import RecordedStand, stand_law, stand_outcome
from robodyn.sim.task_outcome import REACHED as REACHED  # re-exported, as frame_pose
from robodyn.sim.task_outcome import frame_pose as frame_pose
from robodyn.sim.task_outcome import pose_outcome, task_outcome
from robodyn.sim.twin import compensate
from robodyn.sim.underactuated import UnderactuatedComputedTorque, UnderactuatedPD, driven_dofs
from robodyn.trajectory import Trajectory

#: The controllers a run can use, by name.
ControllerName = Literal["passive", "pd", "computed-torque", "task-space", "osc", "impedance", "lqr", "stand"]
CONTROLLERS: tuple[ControllerName, ...] = ("passive", "pd", "computed-torque", "task-space", "osc", "impedance", "lqr", "stand")
#: The controllers of a frame's pose (position, or position and attitude).
POSE_CONTROLLERS = ("osc", "impedance")
#: The controllers that drive a frame (``frame`` applies to them).
FRAME_CONTROLLERS = ("task-space", *POSE_CONTROLLERS)


def controller_model(robot: Robot) -> Robot:
    """An independent copy of the robot for a controller (same URDF, its own data).

    Args:
        robot: The simulated robot.
    """
    return rebuild(robot)


def run_simulation(
    robot: Robot,
    *,
    controller: ControllerName = "passive",
    target: list[float] | None = None,
    frame: str | None = None,
    q0: list[float] | None = None,
    duration: float = 3.0,
    dt: float = 1e-3,
    integrator: Integrator | None = None,
    limits: LimitMode = "warn",
    engine: Engine = "auto",
    posture: list[float] | None = None,
    stiffness: list[float] | None = None,
    damping: list[float] | None = None,
    force_at: Sequence[str | Push] = (),
    observer_gain: float | None = None,
    actuated: list[str] | None = None,
    reference: Trajectory | None = None,
    control_period: float | None = None,
    joint_friction: bool = True,
    kp: float | list[float] | None = None,
    kd: float | list[float] | None = None,
    ground: Ground | str | None = None,
    contacts: str | Sequence[str] = "collision",
) -> tuple[Trajectory, SimulationSummary]:
    """Simulate ``robot`` under a named controller and summarise.

    Args:
        robot: The plant.
        controller: ``"passive"``, ``"pd"`` (PD + gravity to a joint target, gains scaled
            to each joint's inertia (its largest at ``q0`` and the target), :func:`robodyn.sim.gains.pd_gains`),
            ``"computed-torque"`` (quintic from ``q0`` to a joint target in half the
            duration), ``"task-space"`` (drive ``frame`` to a position target), ``"osc"``
            (operational-space control of ``frame``'s position or pose) or
            ``"impedance"`` (Cartesian impedance about the target pose) or ``"lqr"``
            (:class:`~robodyn.sim.control.LQR` about the joint target held still, gain of
            the continuous Riccati equation, weights :func:`lqr_weights`) or ``"stand"``
            (a floating robot on ``ground`` held by the whole-body QP, started on its feet;
            ``target``: its centre of mass's shift DX,DY,DZ, :mod:`robodyn.sim.stand_run`).
        target: Joint target (nq values; a floating base's joints only, nq − 7: the base
            stays free and gets no torque; pd: default the start's), task target (X,Z or X,Y,Z in [m]) or, for osc
            and impedance, X,Y,Z in [m] with optionally ROLL,PITCH,YAW in [rad].
        frame: Controlled frame for task-space, osc and impedance control (default the
            robot's end effector; it must be a frame some joint moves); under the other
            controllers it only names the path a recording draws.
        q0: Initial configuration; default :meth:`Robot.default_configuration` (the
            file's base pose, the joints at zero clipped into their limits).
        duration, dt, integrator, limits, engine: As for :func:`robodyn.simulate` (the
            controller is evaluated at every integrator stage in either engine).
        posture: osc only: a configuration (nq) drawn toward in the task's null space.
        stiffness: impedance only: ``K``, 3 values [N/m] (or 6, then [N m/rad]).
        damping: impedance only: ``D``, [N s/m] (then [N m s/rad]).
        force_at: Pushes, each a :class:`~robodyn.sim.report.Push` or ``T:FX,FY,FZ[@FRAME]``
            (default frame: the controlled frame, or the end effector).
        observer_gain: ``K_O`` in [1/s]: run a momentum observer along (``None``: none).
        actuated: pd, computed-torque and lqr: the actuated joints (default: those whose
            :attr:`~robodyn.dynamics.dofs.Dof.actuated`, i.e. the file's actuators, else all);
            the others get zero torque (pd and computed torque then hold or drive the
            actuated joints with the others free, :mod:`robodyn.sim.underactuated`).
        reference: computed-torque only: a motion to track instead of the quintic
            (:class:`TrajectoryReference`; e.g. ``robodyn optimize``'s); it starts at its first
            sample (unless ``q0`` is given) and its last configuration is the target.
        control_period: Sample the controller every ``control_period`` [s] and hold its
            torque (zero-order hold; the summary says so); ``None``: every stage.
        joint_friction: As for :func:`robodyn.simulate`: the joints' damping and friction
            act (``False``: the rigid-body motion); the model-based controllers compensate the
            viscous damping exactly when it acts (``compensate_damping``).
        kp, kd: pd: stiffness and damping, a scalar or one value a joint, in [N m/rad] and
            [N m s/rad] (default: scaled to each joint's inertia,
            :func:`~robodyn.sim.gains.pd_gains`); computed-torque: in [1/s²] and [1/s]
            (default 400 and 40). Refused with the other controllers.
        ground, contacts: As for :func:`robodyn.simulate`: the robot on a plane with
            friction (docs/contact.md); the summary gives its contact lines.

    Returns:
        The trajectory and its :class:`~robodyn.sim.report.SimulationSummary`
        (``violations``: every broken limit, none with ``limits="ignore"``).

    Raises:
        InputError: Naming the parameter (``controller``, ``target``, ``frame``, ...).
    """
    if reference is not None:
        reference, target, q0 = tracked(robot, controller, reference, target, q0)
    _check_request(robot, controller, target, frame, limits)
    if observer_gain is not None and not (np.isfinite(observer_gain) and observer_gain > 0):
        raise InputError("observer_gain", "a positive gain in [1/s]", repr(observer_gain))
    options = _options(robot, controller, posture, stiffness, damping, actuated, kp, kd)
    ground = resolve_ground(robot, ground)  # "file": the plane the robot's file states
    start, lifted = _start(robot, controller, q0, ground, contacts)
    target, options["gains"] = pd_defaults(robot, controller, target, start, options["gains"], ground, contacts)
    law: Any
    if controller == "stand":  # started on its feet (gap 0), stand_run's docstring
        law, start, placed = stand_law(robot, controller_model(robot), start, target, ground, contacts)
        lifted, task, controlled = (placed,), None, ""
    else:
        law, task, controlled = _control_law(robot, controller, target, frame, start, duration, options)
    if reference is not None:
        law = ComputedTorque(controller_model(robot), TrajectoryReference(reference))
    compensate(law, joint_friction)
    pushes, external = push_wrenches(robot, force_at, controlled or None)
    # held: a controller sampled every control_period holds its torque through each step
    torque: TorqueMode = "held" if control_period is not None else "sampled"
    observer = None if observer_gain is None else MomentumObserver(controller_model(robot), observer_gain, torque=torque)
    with warnings.catch_warnings():  # the summary reports the violations; the caller warns
        warnings.simplefilter("ignore", JointLimitWarning)
        trajectory, run = simulate_run(
            robot, start, np.zeros(robot.nv), duration, dt, controller=law, integrator=integrator, limits=limits,
            engine=engine, external=external, observer=observer, control_period=control_period,
            joint_friction=joint_friction, ground=ground, contacts=contacts,
        )  # fmt: skip
    settings = {
        "controller": controller,
        "integrator": integrator or ("semi-implicit-euler" if ground is not None else "rk4"),
        "limits": limits,
        "engine": run.engine,
        "duration": duration,
        "dt": dt,
    }
    summary = replace(
        _summary(robot, trajectory, settings, run.loop_time), pushes=pushes, engine_reason=run.reason,
        control_period=run.control_period, controller_in_c=run.controller_in_c, loop_time=run.loop_time,
        compile_time=run.compile_time, ground=lifted + ground_lines(robot, run.contact), contact=run.contact,
        constrained=run.constrained,
    )  # fmt: skip
    if observer is not None:
        summary = replace(summary, observer=observer_outcome(robot, trajectory, observer, external))
    if isinstance(law, OperationalSpace | Impedance):
        return trajectory, replace(summary, task=pose_outcome(robot, trajectory, law, pushes))
    if isinstance(law, RecordedStand):
        return trajectory, replace(summary, **stand_outcome(robot, law, run.contact))
    if task is not None:
        return trajectory, replace(summary, task=task_outcome(robot, trajectory, controlled, task))
    if controller != "passive":
        joints = np.asarray(target, float)
        missed = np.abs(trajectory.q[-1][robot.nq - joints.size :] - joints)
        driven = options["driven"][6:] if robot.floating_base else options["driven"]
        if driven.size == missed.size and driven.any():  # the joints no actuator drives have no target to reach
            missed = missed[driven]
        return trajectory, replace(summary, final_joint_error=float(missed.max()))
    return trajectory, summary


def _start(
    robot: Robot, controller: str, q0: list[float] | None, ground: Ground | None, contacts: Any
) -> tuple[np.ndarray, tuple[str, ...]]:
    """The start and its summary line (a floating robot in the floor is lifted 5 cm above it; stand: :func:`stand_law`)."""
    start = robot.default_configuration() if q0 is None else np.asarray(q0, dtype=float)
    if q0 is None and ground is not None and robot.floating_base and controller != "stand":
        lifted, lift = start_above(robot, start, ground, contacts, clearance=0.05)
        line = f"start: the base moved {lift:.6g} m along the ground's normal (its lowest contact point 5 cm above it)"
        if lift > 0.05:  # a contact point in the ground (else the file's start, as MuJoCo's)
            return lifted, (line,)
    return start, ()


def _summary(robot: Robot, trajectory: Trajectory, settings: dict[str, Any], elapsed: float) -> SimulationSummary:
    """The summary every run has (no task, no joint error); ``settings``: the run's
    controller, integrator, limits, engine, duration and dt."""
    torques = trajectory.tau
    assert torques is not None  # simulate records the applied torques
    duration, limits = settings["duration"], settings["limits"]
    energy = np.atleast_1d(robot.kinetic_energy(trajectory.q, trajectory.v)) + np.atleast_1d(robot.potential_energy(trajectory.q))
    return SimulationSummary(
        robot=robot.name, **settings, steps=len(trajectory) - 1,
        real_time_factor=duration / elapsed if elapsed > 0 else None,
        joint_names=tuple(robot.joint_names),
        dof_names=tuple(dof.name for dof in robot.dofs),
        final_q=tuple(trajectory.q[-1].tolist()),
        peak_abs_torque=tuple(np.abs(torques).max(axis=0).tolist()),
        torque_units=tuple(dof.effort_unit for dof in robot.dofs),
        energy_change=float(energy[-1] - energy[0]),
        violations=() if limits == "ignore" else tuple(limit_violations(robot, trajectory)),
    )  # fmt: skip


def _check_request(robot: Robot, controller: str, target: list[float] | None, frame: str | None, limits: str) -> None:
    """Refuse an unknown controller or limits mode, and a target or frame it does not take."""
    if controller not in CONTROLLERS:
        raise InputError("controller", f"one of {', '.join(CONTROLLERS)}", repr(controller))
    check_mode(limits)
    if controller not in ("passive", "stand", "pd") and target is None:  # pd: holds the start
        raise InputError("target", f"given for the {controller} controller", "nothing")
    if controller == "passive" and target is not None:
        raise InputError(
            "target", "given only with a controller (the passive run has no target)", counted(np.size(target), "value")
        )
    # Under the other controllers a frame names only the path a recording draws (checked by it).


def _options(
    robot: Robot, controller: str, posture: Any, stiffness: Any, damping: Any, actuated: Any, kp: Any, kd: Any
) -> dict[str, Any]:
    """The controllers' options; refused (naming it) where the controller takes none."""
    _check_pose_options(controller, posture, stiffness, damping)
    if actuated is not None and controller not in ("pd", "computed-torque", "lqr"):
        raise InputError("actuated", "given only with the pd, computed-torque or lqr controller", f"{len(actuated)} joints")
    if (kp is not None or kd is not None) and controller not in ("pd", "computed-torque"):
        raise InputError(
            "kp" if kp is not None else "kd", "given only with the pd or computed-torque controller", repr(controller)
        )
    return {"posture": posture, "stiffness": stiffness, "damping": damping, "driven": driven_dofs(robot, actuated),
            "actuated": actuated, "gains": {"kp": kp, "kd": kd}}  # fmt: skip


def _check_pose_options(controller: str, posture: Any, stiffness: Any, damping: Any) -> None:
    """Refuse a posture without osc, and impedance gains without the impedance controller."""
    if posture is not None and controller != "osc":
        raise InputError("posture", "given only with the osc controller", counted(np.size(posture), "value"))
    for name, value in (("stiffness", stiffness), ("damping", damping)):
        if value is not None and controller != "impedance":
            raise InputError(name, "given only with the impedance controller", counted(np.size(value), "value"))


def _control_law(
    robot: Robot,
    controller: str,
    target: list[float] | None,
    frame: str | None,
    start: np.ndarray,
    duration: float,
    options: dict[str, Any],
) -> tuple[PDGravity | ComputedTorque | TaskSpace | OperationalSpace | Impedance | LQR | None, np.ndarray | None, str]:
    """The controller (on its own model), the task target in [m] and the controlled frame
    (task-space, osc and impedance control only: ``None`` and ``""`` otherwise)."""
    law: PDGravity | ComputedTorque | TaskSpace | OperationalSpace | Impedance | LQR | None = None
    task, controlled = None, ""
    if controller in ("pd", "computed-torque", "lqr"):  # the joints' positions (a floating base stays free)
        assert target is not None  # checked by _check_request
        joints = joint_target(robot, target, controller)
    gains, driven = options["gains"], options["driven"]
    every_joint = bool(driven[6:].all() if robot.floating_base else driven.all())
    if controller == "pd":
        goal = start.copy()
        goal[robot.nq - joints.size :] = joints  # the inertia at the start and at the target
        pd = pd_gains(robot, np.array([start, goal]), driven=driven, **gains)
        model = controller_model(robot)
        law = PDGravity(model, joints, *pd) if every_joint else UnderactuatedPD(model, joints, *pd, driven=driven)
    elif controller == "computed-torque":
        reference = quintic_reference(start[robot.nq - joints.size :], joints, duration / 2)
        ct, model = computed_torque_gains(joints.size, **gains), controller_model(robot)
        law = (
            ComputedTorque(model, reference, *ct)
            if every_joint
            else UnderactuatedComputedTorque(model, reference, *ct, driven=driven)
        )
    elif controller == "lqr":
        names = [dof.joint for dof in robot.dofs if driven[dof.index]]
        law = _lqr_law(robot, joints, options["actuated"] if every_joint or options["actuated"] else names)
    elif controller == "task-space":
        assert target is not None  # checked by _check_request
        task = task_target(target)
        controlled = robot.task_frame(frame, "task-space control")
        check_planar(robot, controlled, start, len(target))
        check_reach(robot, controlled, task, parameter="target")
        law = TaskSpace(controller_model(robot), controlled, task)
    elif controller in POSE_CONTROLLERS:
        assert target is not None  # checked by _check_request
        task, rpy = pose_target(target)
        controlled = robot.task_frame(frame, f"{controller} control")
        check_reach(robot, controlled, task, parameter="target")
        law = _pose_law(robot, controller, controlled, task, rpy, options)
    return law, task, controlled


def _lqr_law(robot: Robot, target: np.ndarray, actuated: list[str] | None) -> LQR:
    """The LQR controller about ``target`` held still (on its own model)."""
    Q, R = lqr_weights(robot, target, actuated)
    return LQR(controller_model(robot), target, np.zeros(robot.nv), Q, R, actuated=actuated)


def _pose_law(
    robot: Robot, controller: str, frame: str, position: np.ndarray, rpy: np.ndarray | None, options: dict[str, Any]
) -> OperationalSpace | Impedance:
    """The operational-space or impedance controller of ``frame`` (on its own model)."""
    if controller == "osc":
        posture = options["posture"]
        if posture is not None and np.size(posture) != robot.nq:
            raise InputError("posture", f"{robot.nq} joint values", counted(np.size(posture), "value"))
        return OperationalSpace(
            controller_model(robot),
            frame,
            position,
            orientation=rpy,
            posture=None if posture is None else np.asarray(posture, float),
        )
    gains: dict[str, Any] = {n: np.asarray(options[n], float) for n in ("stiffness", "damping") if options[n] is not None}
    for name, values in gains.items():
        if values.size not in (1, 3, 6):
            raise InputError(name, "1, 3 or 6 values", counted(values.size, "value"))
    return Impedance(controller_model(robot), frame, position, orientation=rpy, **gains)
