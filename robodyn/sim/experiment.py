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
import pinocchio as pin

from robodyn.common.text import counted
from robodyn.dynamics.loading import rebuild
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError, JointLimitWarning
from robodyn.sim.control import LQR, ComputedTorque, PDGravity, TaskSpace, joint_target, quintic_reference
from robodyn.sim.gains import LQR_ACCELERATION as LQR_ACCELERATION
from robodyn.sim.gains import computed_torque_gains, lqr_weights, pd_gains
from robodyn.sim.limits import LimitMode, check_mode, limit_violations
from robodyn.sim.observer import MomentumObserver
from robodyn.sim.operational_space import Impedance, OperationalSpace, orientation_error, target_rotation
from robodyn.sim.reach import check_reach
from robodyn.sim.report import ObserverOutcome, Push, SimulationSummary, TaskOutcome
from robodyn.sim.simulation import Engine, ExternalWrench, Integrator, external_torques, simulate_run
from robodyn.sim.underactuated import UnderactuatedComputedTorque, UnderactuatedPD, driven_dofs
from robodyn.trajectory import Trajectory

#: The controllers a run can use, by name.
ControllerName = Literal["passive", "pd", "computed-torque", "task-space", "osc", "impedance", "lqr"]
CONTROLLERS: tuple[ControllerName, ...] = ("passive", "pd", "computed-torque", "task-space", "osc", "impedance", "lqr")
#: The controllers of a frame's pose (position, or position and attitude).
POSE_CONTROLLERS = ("osc", "impedance")
#: The controllers that drive a frame (``frame`` applies to them).
FRAME_CONTROLLERS = ("task-space", *POSE_CONTROLLERS)
#: Final task error below which a target counts as reached, in [m] (and [rad]).
REACHED = 1e-3


def controller_model(robot: Robot) -> Robot:
    """An independent copy of the robot for a controller (same URDF, its own data)."""
    return rebuild(robot)


def task_target(values: list[float] | np.ndarray) -> np.ndarray:
    """A task-space target from ``X,Z`` (planar arms, ``Y = 0``) or ``X,Y,Z``, in [m]."""
    values = np.asarray(values, dtype=float)
    if values.shape == (2,):
        return np.array([values[0], 0.0, values[1]])
    if values.shape == (3,):
        return values
    raise InputError("target", "X,Z or X,Y,Z in [m] for task-space control", counted(values.size, "value"))


def pose_target(values: list[float] | np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
    """A pose target from ``X,Y,Z`` (position only) or ``X,Y,Z,ROLL,PITCH,YAW``.

    Returns:
        The position in [m], shape (3,), and roll, pitch, yaw in [rad], shape (3,) (``None``
        for a position target).
    """
    values = np.asarray(values, dtype=float)
    if values.shape not in ((3,), (6,)) or not np.isfinite(values).all():
        raise InputError("target", "X,Y,Z in [m] or X,Y,Z,ROLL,PITCH,YAW (rad) for pose control", counted(values.size, "value"))
    return values[:3], (values[3:] if values.size == 6 else None)


def parse_push(text: str) -> Push:
    """A push from ``T:FX,FY,FZ`` or ``T:FX,FY,FZ@FRAME`` (time in [s], force in [N])."""
    head, _, frame = text.partition("@")
    start, _, force = head.partition(":")
    try:
        time_ = float(start)
        values = [float(value) for value in force.replace(",", " ").split()]
    except ValueError:
        values, time_ = [], float("nan")
    if len(values) != 3 or not np.isfinite([time_, *values]).all() or time_ < 0:
        raise InputError("force_at", "T:FX,FY,FZ[@FRAME] (a time >= 0 in [s], a force in [N])", repr(text))
    return Push(time_, (values[0], values[1], values[2]), frame.strip() or None)


class _StepForce:
    """A force that starts at a time: zero before, constant after (a callable wrench)."""

    def __init__(self, start: float, force: tuple[float, ...]) -> None:
        self.start, self.force, self.zero = start, np.asarray(force, dtype=float), np.zeros(3)

    def __call__(self, t: float) -> np.ndarray:
        return self.force if t >= self.start else self.zero


def push_wrenches(
    robot: Robot, pushes: Sequence[str | Push], frame: str | None = None
) -> tuple[tuple[Push, ...], list[ExternalWrench]]:
    """The pushes (frames resolved: ``frame`` when a push names none, then the robot's end
    effector) and their wrenches."""
    resolved = []
    for push in pushes:
        push = parse_push(push) if isinstance(push, str) else push
        resolved.append(replace(push, frame=robot.task_frame(push.frame or frame, "a push")))
    return tuple(resolved), [ExternalWrench(push.frame, _StepForce(push.time, push.force)) for push in resolved]  # type: ignore[arg-type]


def run_simulation(
    robot: Robot,
    *,
    controller: ControllerName = "passive",
    target: list[float] | None = None,
    frame: str | None = None,
    q0: list[float] | None = None,
    duration: float = 3.0,
    dt: float = 1e-3,
    integrator: Integrator = "rk4",
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
            the continuous Riccati equation, weights :func:`lqr_weights`).
        target: Joint target (nq values; a floating base's joints only, nq − 7: the base
            stays free and gets no torque), task target (X,Z or X,Y,Z in [m]) or, for osc
            and impedance, X,Y,Z in [m] with optionally ROLL,PITCH,YAW in [rad].
        frame: Controlled frame for task-space, osc and impedance control (default the
            robot's end effector; it must be a frame some joint moves); under the other
            controllers it only names the path a recording draws.
        q0: Initial configuration; default :meth:`Robot.default_configuration` (the
            neutral one clipped into the joint limits).
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
            act (``False``: the rigid-body motion). The controllers' models are rigid-body.
        kp, kd: pd: stiffness and damping, a scalar or one value a joint, in [N m/rad] and
            [N m s/rad] (default: scaled to each joint's inertia,
            :func:`~robodyn.sim.gains.pd_gains`); computed-torque: in [1/s²] and [1/s]
            (default 400 and 40). Refused with the other controllers.

    Returns:
        The trajectory and its :class:`~robodyn.sim.report.SimulationSummary`
        (``violations``: every broken limit, none with ``limits="ignore"``).

    Raises:
        InputError: Naming the parameter (``controller``, ``target``, ``frame``, ...).
    """
    if reference is not None:
        reference, target, q0 = _tracked(robot, controller, reference, target, q0)
    _check_request(robot, controller, target, frame, limits)
    _check_pose_options(controller, posture, stiffness, damping)
    if observer_gain is not None and not (np.isfinite(observer_gain) and observer_gain > 0):
        raise InputError("observer_gain", "a positive gain in [1/s]", repr(observer_gain))
    start = robot.default_configuration() if q0 is None else np.asarray(q0, dtype=float)
    options: dict[str, Any] = {"posture": posture, "stiffness": stiffness, "damping": damping}
    if actuated is not None and controller not in ("pd", "computed-torque", "lqr"):
        raise InputError("actuated", "given only with the pd, computed-torque or lqr controller", f"{len(actuated)} joints")
    options["driven"] = driven_dofs(robot, actuated)
    options["actuated"] = actuated
    if (kp is not None or kd is not None) and controller not in ("pd", "computed-torque"):
        raise InputError(
            "kp" if kp is not None else "kd", "given only with the pd or computed-torque controller", repr(controller)
        )
    options["gains"] = {"kp": kp, "kd": kd}
    law, task, controlled = _control_law(robot, controller, target, frame, start, duration, options)
    if reference is not None:
        law = ComputedTorque(controller_model(robot), TrajectoryReference(reference))
    pushes, external = push_wrenches(robot, force_at, controlled or None)
    observer = None if observer_gain is None else MomentumObserver(controller_model(robot), observer_gain, torque="sampled")
    with warnings.catch_warnings():  # the summary reports the violations; the caller warns
        warnings.simplefilter("ignore", JointLimitWarning)
        trajectory, run = simulate_run(
            robot, start, np.zeros(robot.nv), duration, dt, controller=law, integrator=integrator, limits=limits,
            engine=engine, external=external, observer=observer, control_period=control_period,
            joint_friction=joint_friction,
        )  # fmt: skip
    settings = {
        "controller": controller,
        "integrator": integrator,
        "limits": limits,
        "engine": run.engine,
        "duration": duration,
        "dt": dt,
    }
    summary = replace(
        _summary(robot, trajectory, settings, run.loop_time), pushes=pushes, engine_reason=run.reason,
        control_period=run.control_period, controller_in_c=run.controller_in_c, loop_time=run.loop_time,
        compile_time=run.compile_time,
    )  # fmt: skip
    if observer is not None:
        summary = replace(summary, observer=_observer_outcome(robot, trajectory, observer, external))
    if isinstance(law, OperationalSpace | Impedance):
        return trajectory, replace(summary, task=_pose_outcome(robot, trajectory, law, pushes))
    if task is not None:
        return trajectory, replace(summary, task=_task_outcome(robot, trajectory, controlled, task))
    if controller != "passive":
        joints = np.asarray(target, float)
        missed = np.abs(trajectory.q[-1][robot.nq - joints.size :] - joints)
        driven = options["driven"][6:] if robot.floating_base else options["driven"]
        if driven.size == missed.size and driven.any():  # the joints no actuator drives have no target to reach
            missed = missed[driven]
        return trajectory, replace(summary, final_joint_error=float(missed.max()))
    return trajectory, summary


class TrajectoryReference:
    """A recorded motion as a joint reference ``t -> (q_d, v_d, a_d)`` for computed torque:
    each column interpolated linearly between samples; before the first sample its state,
    after the last one at rest there.

    Args:
        trajectory: The motion (fixed base: ``q`` and ``v`` of the same size), in the
            robot's joint order.
    """

    def __init__(self, trajectory: Trajectory) -> None:
        self.t, self.q, self.v, self.a = trajectory.t, trajectory.q, trajectory.v, trajectory.a
        self.rest = np.zeros(trajectory.v.shape[1])

    def __call__(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        if t >= self.t[-1]:
            return self.q[-1], self.rest, self.rest
        t = max(float(t), float(self.t[0]))
        k = int(np.clip(np.searchsorted(self.t, t, side="right") - 1, 0, len(self.t) - 2))
        s = (t - self.t[k]) / (self.t[k + 1] - self.t[k])
        return tuple((1 - s) * x[k] + s * x[k + 1] for x in (self.q, self.v, self.a))


def _tracked(
    robot: Robot, controller: str, reference: Trajectory, target: list[float] | None, q0: list[float] | None
) -> tuple[Trajectory, list[float], list[float]]:
    """The reference in the robot's joint order, its goal as the target and its start as ``q0``
    (unless given); refused with another controller, a target, a floating base or one sample."""
    if controller != "computed-torque":
        raise InputError("reference", "given only with the computed-torque controller", repr(controller))
    if target is not None:
        raise InputError("target", "left out with a reference (its last sample is the target)", counted(np.size(target), "value"))
    reference = reference.for_robot(robot)
    if robot.floating_base or len(reference) < 2:
        raise InputError("reference", "a fixed-base robot's motion of at least two samples", f"{len(reference)} samples")
    return reference, list(reference.q[-1]), list(reference.q[0]) if q0 is None else q0


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
    if controller != "passive" and target is None:
        raise InputError("target", f"given for the {controller} controller", "nothing")
    if controller == "passive" and target is not None:
        raise InputError(
            "target", "given only with a controller (the passive run has no target)", counted(np.size(target), "value")
        )
    # Under the other controllers a frame names only the path a recording draws (checked by it).


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


def _task_outcome(robot: Robot, trajectory: Trajectory, frame: str, task: np.ndarray) -> TaskOutcome:
    """Where the run left ``frame``, against the target ``task`` in [m]."""
    position = robot.frame_position(trajectory.q[-1], frame)
    error = float(np.linalg.norm(position - task))
    return TaskOutcome(frame, tuple(task.tolist()), tuple(position.tolist()), error, error < REACHED)


def frame_pose(robot: Robot, q: np.ndarray, frame: str) -> tuple[np.ndarray, np.ndarray]:
    """A frame's position in [m] (3,) and attitude (3, 3), by the robot's forward kinematics."""
    model, data = robot.model, robot.data
    pin.framesForwardKinematics(model, data, np.asarray(q, dtype=float))
    placement = data.oMf[robot.frame_id(frame)]
    return placement.translation.copy(), placement.rotation.copy()


def _pose_outcome(
    robot: Robot, trajectory: Trajectory, law: OperationalSpace | Impedance, pushes: tuple[Push, ...]
) -> TaskOutcome:
    """Where an osc or impedance run left its frame (the plant's forward kinematics), and an
    impedance's deflection against ``K⁻¹ F`` when every push acts at that frame."""
    frame = str(law.frame)
    target = np.asarray(law.position, dtype=float)
    position, rotation = frame_pose(robot, trajectory.q[-1], frame)
    error = float(np.linalg.norm(position - target))
    rpy = None if law.orientation is None else np.asarray(law.orientation, dtype=float)
    angle = None if rpy is None else float(np.linalg.norm(orientation_error(rotation, target_rotation(rpy))))
    outcome = TaskOutcome(
        frame, tuple(target.tolist()), tuple(position.tolist()), error, error < REACHED and (angle or 0.0) < REACHED,
        None if rpy is None else tuple(rpy.tolist()), angle,
    )  # fmt: skip
    end = float(trajectory.t[-1])
    acting = [push for push in pushes if push.time <= end]
    if not isinstance(law, Impedance) or not acting or any(push.frame != frame for push in acting):
        return outcome
    force = np.sum([push.force for push in acting], axis=0)
    expected = force / np.asarray(law.stiffness, dtype=float)[:3]
    deflection = position - target
    relative = float(np.linalg.norm(deflection - expected) / max(float(np.linalg.norm(expected)), 1e-300))
    return replace(
        outcome, deflection=tuple(deflection.tolist()), expected_deflection=tuple(expected.tolist()), deflection_error=relative
    )


def applied_torques(robot: Robot, trajectory: Trajectory, external: Sequence[ExternalWrench]) -> np.ndarray:
    """The joint torques external wrenches applied at each sample, ``Σ J(q)ᵀ w(t)``, shape (N, nv)."""
    return np.array([external_torques(robot, q, float(t), external) for t, q in zip(trajectory.t, trajectory.q, strict=True)])


def _observer_outcome(
    robot: Robot, trajectory: Trajectory, observer: MomentumObserver, external: list[ExternalWrench]
) -> ObserverOutcome:
    """The observer's residual at every sample, against the external torques applied there."""
    residual = np.array(observer.residuals)
    applied = applied_torques(robot, trajectory, external)
    gain = float(np.max(np.asarray(observer.gain, dtype=float)))
    error = float(np.abs(residual[-1] - applied[-1]).max())
    return ObserverOutcome(gain, tuple(residual[-1].tolist()), tuple(applied[-1].tolist()), error, residual, applied)
