"""Dynamics-based controllers: the lecture's loop and the ones a textbook pairs with it.

Each controller is a callable ``controller(t, q, v) -> tau`` for :func:`robodyn.simulate`
and holds its **own** model of the robot, which may differ from the simulated plant
(a wrong payload, another material): that is how model mismatch is studied.

- :class:`PDGravity` — ``tau = Kp (q_d − q) − Kd v + G(q)``: settles at a joint target.
- :class:`ComputedTorque` — feedback linearisation along a joint trajectory,
  ``tau = M(q) (a_d + Kd (v_d − v) + Kp (q_d − q)) + C(q, v) v + G(q)``: with a perfect
  model the error obeys ``ë + Kd ė + Kp e = 0``.
- :class:`TaskSpace` — the lecture's slide 37: drives a frame's origin to a target
  position. The task error goes through a PD law to a desired task acceleration, which is
  mapped to joint accelerations (damped least squares of the frame Jacobian) and then to
  torques through the model, ``tau = M a* + C v + G``.

Gains are scalars or per-joint arrays, in SI units (``Kp`` in [1/s²], ``Kd`` in [1/s] for
the computed-torque and task-space laws; [N m/rad] and [N m s/rad] for PD).

Floating base (solo12, a1): a joint-space target (:class:`PDGravity`, :class:`ComputedTorque`)
is the joints' positions only, ``nq − 7`` values (:func:`joint_target` checks it); the base
stays free and gets no torque (computed torque solves for the base acceleration the joints'
motion causes).

What the models compensate: every controller uses its own rigid-body model (armature
included). The model-based laws (:class:`ComputedTorque`, :class:`TaskSpace`, operational
space, impedance; a floating base's computed torque on its joints) add ``b ∘ v``, the model's
viscous joint damping (:attr:`robodyn.Robot.joint_damping`), when ``compensate_damping`` is
on, so their closed-loop law holds on a plant that applies it; off (the classes' default, and
``run_simulation(joint_friction=False)``) they are the rigid-body laws. Turn it on exactly when
the run applies the joints' dynamics (:func:`robodyn.simulate`'s ``joint_friction=True``, as
``run_simulation`` does). PD + gravity compensates no velocity term; no law compensates
Coulomb friction, so with it a PD or task-space law stops inside the stiction band.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, ClassVar

import numpy as np

from robodyn.common.text import quoted
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError
from robodyn.sim.twin import compiled_model, law_refusal, viscous_compensation, viscous_params

if TYPE_CHECKING:
    from robodyn.compiled.controllers import CompiledComputedTorque, CompiledPDGravity, CompiledTaskSpace

#: A joint reference: time in [s] -> (q_d, v_d, a_d).
JointReference = Callable[[float], tuple[np.ndarray, np.ndarray, np.ndarray]]


@dataclass
class PDGravity:
    """PD control with gravity compensation, to a fixed joint target (no velocity term is
    model-based: the joints' damping is not compensated, it adds to ``kd``).

    Attributes:
        model: The controller's model of the robot.
        target: Joint target, shape (nq,) (a floating base: its joints' only, (nq − 7,);
            the base gets no torque).
        kp: Stiffness, in [N m/rad] or [N/m] (scalar or shape (nv,); floating: (nv − 6,)).
        kd: Damping, in [N m s/rad] or [N s/m].
    """

    model: Robot
    target: np.ndarray
    kp: float | np.ndarray = 100.0
    kd: float | np.ndarray = 20.0

    def __call__(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        if self.model.floating_base:
            return _floating_pd(self, q, v)
        return self.kp * (self.target - q) - self.kd * v + self.model.gravity(q)

    def twin_refusal(self) -> str | None:
        """Why this controller has no compiled twin (``None``: it has one; floating bases too)."""
        return law_refusal(self, PDGravity)

    def compiled(self) -> CompiledPDGravity:
        """The same law in C (:class:`~robodyn.compiled.controllers.CompiledPDGravity`)."""
        from robodyn.compiled.controllers import CompiledPDGravity

        return CompiledPDGravity(compiled_model(self.model, self.twin_refusal()), self.target, self.kp, self.kd)


@dataclass
class ComputedTorque:
    """Joint-space computed torque (feedback linearisation) along a reference.

    Attributes:
        model: The controller's model of the robot.
        reference: ``reference(t) -> (q_d, v_d, a_d)`` (a floating base: of its joints
            only, each shape (nv − 6,); the base is free, its acceleration the one the
            joints' motion causes, and gets no torque).
        kp: Position gain in [1/s²] (scalar or shape (nv,)).
        kd: Velocity gain in [1/s].
        compensate_damping: Add ``b ∘ v`` (the model's joint damping; see the module's note).
    """

    model: Robot
    reference: JointReference
    kp: float | np.ndarray = 400.0
    kd: float | np.ndarray = 40.0
    compensate_damping: bool = False

    def __call__(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        q_d, v_d, a_d = self.reference(t)
        if self.model.floating_base:
            command = a_d + self.kd * (v_d - v[6:]) + self.kp * (q_d - q[7:])
            return free_base_torques(self.model, q, v, command) + viscous_compensation(self.model, self.compensate_damping, v)
        command = a_d + self.kd * (v_d - v) + self.kp * (q_d - q)
        return self.model.inverse_dynamics(q, v, command) + viscous_compensation(self.model, self.compensate_damping, v)

    def twin_refusal(self) -> str | None:
        """Why this controller has no compiled twin: a reference other than a
        :class:`QuinticReference` (whose formulas the C loop has), or a changed law."""
        if not isinstance(self.reference, QuinticReference):
            return "computed torque compiles along a quintic_reference only"
        return law_refusal(self, ComputedTorque)

    def compiled(self) -> CompiledComputedTorque:
        """The same law in C along the same quintic (:class:`~robodyn.compiled.controllers.CompiledComputedTorque`)."""
        from robodyn.compiled.controllers import CompiledComputedTorque

        model, reference = compiled_model(self.model, self.twin_refusal()), self.reference
        assert isinstance(reference, QuinticReference)  # twin_refusal checked it
        viscous = viscous_params(self.model, self.compensate_damping, reference.q_start.size)
        return CompiledComputedTorque(model, reference.q_start, reference.q_end, reference.duration, self.kp, self.kd, viscous)


@dataclass
class TaskSpace:
    """Drive a frame's origin to a target position through the robot's dynamics.

    The frame must be one some joint moves (:class:`~robodyn.exceptions.StaticFrameError`
    otherwise: a target for a frame fixed to the world can never be reached).

    Attributes:
        model: The controller's model of the robot.
        frame: The controlled frame (e.g. ``"end_effector"``); ``None`` for the model's
            default end effector.
        target: Desired position of its origin, world frame, in [m], shape (3,).
        kp: Task stiffness in [1/s²].
        kd: Task damping in [1/s].
        damping: Damped-least-squares regularisation of the Jacobian inverse (handles
            directions the frame cannot move in, e.g. out of the RP arm's plane).
        joint_damping: Damping in [1/s] of the joint motion the task leaves free (the
            null space), so that redundant arms come to rest.
        compensate_damping: Add ``b ∘ v`` (the model's joint damping; see the module's note).
    """

    model: Robot
    frame: str | None
    target: np.ndarray
    kp: float = 100.0
    kd: float = 20.0
    damping: float = 1e-6
    joint_damping: float = 5.0
    compensate_damping: bool = False
    #: The compiled twin's frame kinematics model fixed bases.
    twin_fixed_base: ClassVar[bool] = True

    def __post_init__(self) -> None:
        self.frame = self._frame = self.model.task_frame(self.frame, "task-space control")
        self.target = np.asarray(self.target, dtype=float)
        if self.target.shape != (3,) or not np.isfinite(self.target).all():
            raise InputError("target", "3 finite values X, Y, Z in [m]", f"shape {self.target.shape}")

    def task_error(self, q: np.ndarray) -> np.ndarray:
        """Target minus the frame's position, shape (3,), in [m].

        Args:
            q: Configuration, shape (nq,), in [rad] / [m].
        """
        return np.asarray(self.target, float) - self.model.frame_position(q, self._frame)

    def __call__(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        jacobian = self.model.frame_jacobian(q, self._frame)[:3]
        velocity = jacobian @ v
        desired = self.kp * self.task_error(q) - self.kd * velocity - self.model.frame_bias_acceleration(q, v, self._frame)
        gram = jacobian @ jacobian.T + self.damping * np.eye(3)
        pseudo_inverse = jacobian.T @ np.linalg.solve(gram, np.eye(3))
        null_space = np.eye(self.model.nv) - pseudo_inverse @ jacobian
        command = pseudo_inverse @ desired - null_space @ (self.joint_damping * v)
        return self.model.inverse_dynamics(q, v, command) + viscous_compensation(self.model, self.compensate_damping, v)

    def twin_refusal(self) -> str | None:
        """Why this controller has no compiled twin (a floating base: its frame kernels model fixed bases)."""
        return law_refusal(self, TaskSpace)

    def compiled(self) -> CompiledTaskSpace:
        """The same law in C (:class:`~robodyn.compiled.controllers.CompiledTaskSpace`)."""
        from robodyn.compiled.controllers import CompiledTaskSpace

        model = compiled_model(self.model, self.twin_refusal())
        args = (self.target, self.kp, self.kd, self.damping, self.joint_damping)
        return CompiledTaskSpace(model, self._frame, *args, viscous_params(self.model, self.compensate_damping, self.model.nv))


@dataclass(frozen=True)
class QuinticReference:
    """A rest-to-rest joint motion with zero velocity and acceleration at both ends.

    ``reference(t) -> (q_d, v_d, a_d)``; after ``duration`` it holds ``q_end``. Plain data,
    so the compiled engine can run the same formulas in C.

    Attributes:
        q_start, q_end: Start and end configurations, shape (n,).
        duration: Motion time in [s].
    """

    q_start: np.ndarray
    q_end: np.ndarray
    duration: float

    def __call__(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        duration, delta = self.duration, self.q_end - self.q_start
        s = min(max(t / duration, 0.0), 1.0)
        position = 10 * s**3 - 15 * s**4 + 6 * s**5
        speed = (30 * s**2 - 60 * s**3 + 30 * s**4) / duration if 0 < t < duration else 0.0
        acceleration = (60 * s - 180 * s**2 + 120 * s**3) / duration**2 if 0 < t < duration else 0.0
        return self.q_start + position * delta, speed * delta, acceleration * delta


def quintic_reference(q_start: np.ndarray, q_end: np.ndarray, duration: float) -> QuinticReference:
    """A rest-to-rest joint motion from ``q_start`` to ``q_end`` in ``duration`` [s] (:class:`QuinticReference`).

    Args:
        q_start: Start joint positions, shape (n,), in [rad] / [m].
        q_end: End joint positions, shape (n,), in [rad] / [m].
        duration: Duration of the motion in [s].
    """
    return QuinticReference(np.asarray(q_start, float), np.asarray(q_end, float), float(duration))


def joint_target(robot: Robot, target: np.ndarray | list[float], controller: str = "joint-space") -> np.ndarray:
    """A joint-space target, checked: ``nq`` values, or for a floating base its joints'
    ``nq − 7`` (the base is not a target of joint-space control).

    Args:
        robot: The controlled robot.
        target: The target joint positions in [rad] / [m]: ``nq`` values, or ``nq − 7`` for a floating base.
        controller: The controller's name, for the error.

    Raises:
        InputError: For another number of values (naming the count and the joints) or
            values that are not finite.
    """
    values = np.asarray(target, dtype=float).reshape(-1)
    names = [dof.name for dof in robot.dofs if not dof.is_base]
    if values.size != len(names) or not np.isfinite(values).all():
        listed = ", ".join(quoted(name) for name in names[:20]) + (", …" if len(names) > 20 else "")
        base = " (the floating base stays free: its joints only)" if robot.floating_base else ""
        received = f"{values.size} values" if values.size != len(names) else "values that are not finite"
        raise InputError("target", f"{len(names)} joint values for the {controller} controller{base}: {listed}", received)
    return values


def free_base_torques(model: Robot, q: np.ndarray, v: np.ndarray, joint_accelerations: np.ndarray) -> np.ndarray:
    """Joint torques giving a floating robot's joints the accelerations ``joint_accelerations``
    (shape (nv − 6,)) with no torque on its free base, shape (nv,) (the first six zero).

    The base's acceleration is the one that motion causes: the base rows of
    ``M a + h = tau`` with ``tau_base = 0`` give ``a_base = −M_bb⁻¹ (M_bj a_j + h_b)``.

    Args:
        model: The controller's model of the robot (floating base).
        q: Configuration, shape (nq,), in [rad] / [m].
        v: Velocity, shape (nv,), in [rad/s] / [m/s].
        joint_accelerations: The joints' accelerations, shape (nv − 6,), in [rad/s²] / [m/s²].
    """
    mass, effects = model.mass_matrix(q), model.nonlinear_effects(q, v)
    base = -np.linalg.solve(mass[:6, :6], mass[:6, 6:] @ joint_accelerations + effects[:6])
    torques = model.inverse_dynamics(q, v, np.concatenate([base, joint_accelerations]))
    torques[:6] = 0.0
    return torques


def _floating_pd(law: PDGravity, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """PD + gravity on a floating robot's joints, none on its base. The gravity term is the
    torque that holds the joints still under gravity with the base free
    (:func:`free_base_torques` at rest): a free base falls with the whole robot, so it is
    zero to rounding, not the joints' rows of ``G(q)`` (those hold a robot whose base is held)."""
    holding = free_base_torques(law.model, q, np.zeros(len(v)), np.zeros(len(v) - 6))
    torques = np.zeros(len(v))
    torques[6:] = law.kp * (law.target - q[7:]) - law.kd * v[6:] + holding[6:]
    return torques


# Operational-space and impedance control, and the linear-quadratic regulator, live in their
# own modules; re-exported here.
from robodyn.sim.lqr import LQR as LQR  # noqa: E402
from robodyn.sim.lqr import lqr_gain as lqr_gain  # noqa: E402
from robodyn.sim.operational_space import Impedance as Impedance  # noqa: E402
from robodyn.sim.operational_space import OperationalSpace as OperationalSpace  # noqa: E402
