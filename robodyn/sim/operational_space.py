"""Operational-space and impedance control of a frame's pose (the lecture's sequel).

Both are controllers ``controller(t, q, v) -> tau`` for :func:`robodyn.simulate`, built on
their **own** model of the robot like those of :mod:`robodyn.sim.control`.

- :class:`OperationalSpace` — Khatib's operational-space control. With the frame Jacobian
  ``J`` (6 × nv, or its 3 position rows), the task inertia ``Λ = (J M⁻¹ Jᵀ)⁻¹``, the
  dynamically consistent inverse ``J̄ = M⁻¹ Jᵀ Λ`` and ``N = I − J̄ J``::

      tau = Jᵀ Λ (ẍ* − J̇ v) + C v + G + Nᵀ τ₀

  where ``ẍ*`` makes the task error obey ``ë + Kd ė + Kp e = 0`` (position: ``e = x_d − x``;
  orientation: ``e`` is the SO(3) logarithm of the rotation from the frame to the target,
  see :func:`robodyn.sim.attitude.orientation_error`) and ``τ₀ = M (Kp₀ (q₀ − q) − Kd₀ v)`` is the posture task,
  which ``Nᵀ`` confines to the null space: it never changes the task's acceleration.
- :class:`Impedance` — Cartesian impedance with gravity compensation::

      tau = G + Jᵀ (K e − D J v) − N_Jᵀ d₀ v

  so a steady external wrench ``F`` at the frame moves it by ``K⁻¹ F``. The last term
  damps the joint motion the task leaves free (``N_J = I − J⁺ J``); it is zero at rest.

Near singularities ``Λ`` is damped (:mod:`robodyn.sim.task_damping`): ``Λ = U diag(s / (s² +
λ²)) Uᵀ`` from ``J M⁻¹ Jᵀ = U S Uᵀ``, with a constant floor of 1e-8 and a variable damping
that is exactly zero unless the task's smallest singular value (rotation rows scaled by the
chain's length, so every row is in [m]) falls below 5 % of that length, growing smoothly to
1e-2 of the largest eigenvalue at the singularity: the plain law away from singularities,
bounded torques from a stretched start.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import KW_ONLY, dataclass, field
from typing import TYPE_CHECKING, ClassVar

import numpy as np
import pinocchio as pin

from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError
from robodyn.sim.attitude import orientation_error as orientation_error  # re-exported (sim/viz experiment import both)
from robodyn.sim.attitude import target_rotation as target_rotation
from robodyn.sim.reach import check_reach
from robodyn.sim.so3_log import log_jacobian, log_jacobian_rate
from robodyn.sim.task_damping import (
    FLOOR,
    MAX_DAMPING,
    THRESHOLD,
    characteristic_length,
    damped_task_inertia,
    generic_rank,
    relative_singular_value,
    total_damping,
    variable_damping,
)
from robodyn.sim.twin import compiled_model, law_refusal, viscous_compensation, viscous_params

if TYPE_CHECKING:
    from robodyn.compiled.controllers import CompiledImpedance, CompiledOperationalSpace

#: The constant floor of the task inertia's damping (:data:`robodyn.sim.task_damping.FLOOR`).
TASK_DAMPING = FLOOR
#: Damping of the Jacobian's pseudo-inverse in the impedance law's null space, in [m²].
PSEUDO_INVERSE_DAMPING = 1e-8

#: A task reference: time in [s] -> (x_d in [m], ẋ_d in [m/s], ẍ_d in [m/s²]), each (3,).
TaskReference = Callable[[float], tuple[np.ndarray, np.ndarray, np.ndarray]]


@dataclass
class _FrameState:
    """A frame's pose, Jacobian and ``J̇ v`` at one state (world-aligned axes)."""

    position: np.ndarray  # (3,) [m]
    rotation: np.ndarray  # (3, 3)
    jacobian: np.ndarray  # (6, nv): linear rows, then angular
    bias: np.ndarray  # (6,): classical linear [m/s²], angular [rad/s²]


def _frame_state(robot: Robot, frame_id: int, q: np.ndarray, v: np.ndarray) -> _FrameState:
    model, data = robot.model, robot.data
    pin.computeJointJacobians(model, data, q)
    pin.forwardKinematics(model, data, q, v, np.zeros(robot.nv))
    placement = pin.updateFramePlacement(model, data, frame_id)
    jacobian = pin.getFrameJacobian(model, data, frame_id, pin.LOCAL_WORLD_ALIGNED)
    bias = pin.getFrameClassicalAcceleration(model, data, frame_id, pin.LOCAL_WORLD_ALIGNED).vector
    # reshape: Pinocchio hands a 6×1 Jacobian (one degree of freedom) back as a vector
    return _FrameState(placement.translation.copy(), placement.rotation.copy(), jacobian.reshape(6, robot.nv).copy(), bias.copy())


def _reference(position: np.ndarray | TaskReference, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(x_d, ẋ_d, ẍ_d) at a time, each shape (3,)."""
    if callable(position):
        x_d, dx_d, ddx_d = position(t)
        return np.asarray(x_d, float), np.asarray(dx_d, float), np.asarray(ddx_d, float)
    return position, np.zeros(3), np.zeros(3)


def _checked_position(robot: Robot, frame: str, position: np.ndarray | TaskReference) -> np.ndarray | TaskReference:
    """The target position (checked, as floats) or the reference function (its start checked)."""
    start = _reference(position, 0.0)[0] if callable(position) else np.asarray(position, dtype=float)
    if start.shape != (3,) or not np.isfinite(start).all():
        raise InputError(
            "position", "3 finite values X, Y, Z in [m] (or a function of time returning them)", f"shape {start.shape}"
        )
    check_reach(robot, frame, start, parameter="position")
    return position if callable(position) else start


@dataclass
class OperationalSpace:
    """Khatib's operational-space control of a frame's position or pose.

    Attributes:
        model: The controller's model of the robot.
        frame: The controlled frame; ``None`` for the model's default end effector.
        position: Target position of the frame's origin in [m], world axes, shape (3,), or a
            function of time ``t -> (x_d, ẋ_d, ẍ_d)`` for a path (its start is checked).
        orientation: Target attitude (rotation matrix, quaternion ``(x, y, z, w)`` or
            roll-pitch-yaw in [rad]); ``None`` controls the position only.
        kp: Task stiffness in [1/s²]. kd: Task damping in [1/s].
        posture: A configuration (nq,) the arm is drawn toward in the task's null space;
            ``None`` for damping alone there.
        posture_kp: Posture stiffness in [1/s²]. posture_kd: Posture damping in [1/s]
            (also applied without a posture, so that a redundant arm comes to rest).
        damping: The constant floor ``λ₀`` of ``Λ``'s damping, relative to the largest
            eigenvalue of ``J M⁻¹ Jᵀ`` (:mod:`robodyn.sim.task_damping`).
        singular_damping: ``λ_max``: the variable damping at a singularity, relative to the
            same eigenvalue; 0 turns it off (the plain law everywhere: unbounded torques
            at a singularity).
        singular_threshold: ``ε``: the variable damping acts where the task's smallest
            singular value is below this fraction of the chain's length.
        compensate_damping: Add ``b ∘ v``, the model's joint damping (on exactly when the
            run applies it: :mod:`robodyn.sim.control`'s note).

    Raises:
        FrameError: Unknown frame, or one no joint moves.
        InputError: A bad position or orientation, a target outside the frame's reach, a
            posture of the wrong size.
    """

    model: Robot
    frame: str | None
    position: np.ndarray | TaskReference
    _: KW_ONLY
    orientation: np.ndarray | None = None
    kp: float = 100.0
    kd: float = 20.0
    posture: np.ndarray | None = None
    posture_kp: float = 25.0
    posture_kd: float = 10.0
    damping: float = TASK_DAMPING
    singular_damping: float = MAX_DAMPING
    singular_threshold: float = THRESHOLD
    compensate_damping: bool = False
    _frame_id: int = field(init=False, repr=False)
    _rotation: np.ndarray | None = field(init=False, repr=False)
    _length: float = field(init=False, repr=False)
    _rank: int = field(init=False, repr=False)
    #: The compiled twin's frame kinematics model fixed bases.
    twin_fixed_base: ClassVar[bool] = True

    def __post_init__(self) -> None:
        self.frame = self.model.task_frame(self.frame, "operational-space control")
        self._frame_id = self.model.frame_id(self.frame)
        self.position = _checked_position(self.model, self.frame, self.position)
        self._rotation = None if self.orientation is None else target_rotation(self.orientation)
        for name in ("damping", "singular_damping", "singular_threshold"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0):
                raise InputError(name, "a finite value >= 0", repr(value))
        self._length = characteristic_length(self.model, self.frame)
        self._rank = generic_rank(self.model, self.frame, 3 if self._rotation is None else 6)
        if self.posture is not None:
            (self.posture,), _ = self.model.validate(q=self.posture)
            if self.posture.ndim != 1:
                raise InputError("posture", f"one configuration ({self.model.nq} values)", f"shape {self.posture.shape}")

    def singular_value(self, q: np.ndarray) -> float:
        """``σ``: the task's smallest singular value at ``q`` relative to the chain's length
        (:mod:`robodyn.sim.task_damping`); below ``singular_threshold`` the damping acts.

        Args:
            q: A configuration, shape (nq,).
        """
        rows = 3 if self._rotation is None else 6
        jacobian = _frame_state(self.model, self._frame_id, q, np.zeros(self.model.nv)).jacobian
        return relative_singular_value(jacobian[:rows], self._length, self._rank)

    def task_error(self, t: float, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The task error ``e`` and its rate ``ė`` ([m], [m/s], then with an attitude [rad], [rad/s]), each (3,) or (6,).

        Args:
            t: Time in [s] (a moving target's).
            q: Configuration, shape (nq,), in [rad] / [m].
            v: Velocity, shape (nv,), in [rad/s] / [m/s].
        """
        state = _frame_state(self.model, self._frame_id, q, v)
        error, rate, _ = self._error(t, state, v)
        return error, rate

    def _error(self, t: float, state: _FrameState, v: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``e``, ``ė`` and the task acceleration ``ẍ*`` that gives ``ë = −Kd ė − Kp e``."""
        x_d, dx_d, ddx_d = _reference(self.position, t)
        velocity = state.jacobian @ v
        error, rate = x_d - state.position, dx_d - velocity[:3]
        command = ddx_d + self.kd * rate + self.kp * error
        if self._rotation is None:
            return error, rate, command
        # φ = log(R_dᵀ R) = −e_o moves as φ̇ = Jr⁻¹(φ) ω_b with the body angular velocity
        # ω_b = Rᵀ ω, so φ̈ = Jr⁻¹ ω̇_b + (d Jr⁻¹/dt) ω_b: solve for the ω̇ = R ω̇_b that
        # gives ë_o = −Kd ė_o − Kp e_o.
        angle_error = orientation_error(state.rotation, self._rotation)
        body = state.rotation.T @ velocity[3:]
        inverse_jacobian = log_jacobian(-angle_error)
        angle_rate = -inverse_jacobian @ body
        wanted = -self.kd * angle_rate - self.kp * angle_error
        rate_term = log_jacobian_rate(-angle_error, -angle_rate) @ body
        body_acceleration = np.linalg.solve(inverse_jacobian, -wanted - rate_term)
        angular = state.rotation @ body_acceleration
        return np.concatenate([error, angle_error]), np.concatenate([rate, angle_rate]), np.concatenate([command, angular])

    def __call__(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        model = self.model
        state = _frame_state(model, self._frame_id, q, v)
        rows = 3 if self._rotation is None else 6
        jacobian, bias = state.jacobian[:rows], state.bias[:rows]
        _, _, command = self._error(t, state, v)
        mass = model.mass_matrix(q)
        mass_inv_jt = np.linalg.solve(mass, jacobian.T)
        sigma = relative_singular_value(jacobian, self._length, self._rank)
        extra = variable_damping(sigma, self.singular_threshold, self.singular_damping)
        inertia = damped_task_inertia(jacobian @ mass_inv_jt, total_damping(self.damping, extra))
        null_space = np.eye(model.nv) - mass_inv_jt @ inertia @ jacobian  # N = I − J̄ J
        posture_error = np.zeros(model.nv) if self.posture is None else pin.difference(model.model, q, self.posture)
        posture = mass @ (self.posture_kp * posture_error - self.posture_kd * v)
        task = jacobian.T @ (inertia @ (command - bias))
        compensation = viscous_compensation(model, self.compensate_damping, v)
        return task + model.nonlinear_effects(q, v) + null_space.T @ posture + compensation

    def twin_refusal(self) -> str | None:
        """Why this controller has no compiled twin: a path target, a floating base, or a changed law."""
        if callable(self.position):
            return f"{type(self).__name__} compiles with a fixed target, not a path"
        return law_refusal(self, OperationalSpace)

    def compiled(self) -> CompiledOperationalSpace:
        """The same law in C for the same fixed target (:class:`~robodyn.compiled.controllers.CompiledOperationalSpace`)."""
        from robodyn.compiled.controllers import CompiledOperationalSpace

        model = compiled_model(self.model, self.twin_refusal())
        assert self.frame is not None and not callable(self.position)  # resolved; twin_refusal checked
        viscous = viscous_params(self.model, self.compensate_damping, self.model.nv)
        return CompiledOperationalSpace(
            model, self.frame, self.position, self._rotation, self.kp, self.kd, self.posture, self.posture_kp,
            self.posture_kd, self.damping, viscous, self.singular_damping, self.singular_threshold, self._length, self._rank,
        )  # fmt: skip


def _gains(value: float | np.ndarray | list[float], rows: int, name: str, units: str) -> np.ndarray:
    """Impedance gains as a (rows,) array: a scalar, ``rows`` values, or 6 when ``rows`` is 3
    (the rotational three unused)."""
    gains = np.asarray(value, dtype=float)
    if gains.ndim == 0:
        gains = np.full(rows, float(gains))
    elif gains.shape == (6,) and rows == 3:
        gains = gains[:3]
    if gains.shape != (rows,) or not (np.isfinite(gains).all() and (gains >= 0).all()):
        raise InputError(name, f"a non-negative scalar or {rows} values ({units})", f"{np.asarray(value).size} values")
    return gains


@dataclass
class Impedance:
    """Cartesian impedance with gravity compensation: the frame as a spring–damper.

    Attributes:
        model: The controller's model of the robot.
        frame: The controlled frame; ``None`` for the model's default end effector.
        position: Rest position of the frame's origin in [m], world axes, shape (3,).
        orientation: Rest attitude (as for :class:`OperationalSpace`); ``None`` leaves the
            attitude free (only the first three stiffness and damping values are used).
        stiffness: ``K``: [N/m] along x, y, z, then [N m/rad] about them (scalar, (3,)
            or (6,)).
        damping: ``D``: [N s/m], then [N m s/rad].
        null_damping: ``d₀`` in [N m s/rad] (or [N s/m]): damps the joint motion the task
            leaves free; zero at rest.
        compensate_damping: Add ``b ∘ v`` (the model's joint damping).

    Raises:
        FrameError: Unknown frame, or one no joint moves.
        InputError: Bad position, orientation or gains; a target outside the frame's reach.
    """

    model: Robot
    frame: str | None
    position: np.ndarray
    _: KW_ONLY
    orientation: np.ndarray | None = None
    stiffness: float | np.ndarray = field(default_factory=lambda: np.array([500.0] * 3 + [50.0] * 3))
    damping: float | np.ndarray = field(default_factory=lambda: np.array([50.0] * 3 + [5.0] * 3))
    null_damping: float = 1.0
    compensate_damping: bool = False
    _frame_id: int = field(init=False, repr=False)
    _rotation: np.ndarray | None = field(init=False, repr=False)
    #: The compiled twin's frame kinematics model fixed bases.
    twin_fixed_base: ClassVar[bool] = True

    def __post_init__(self) -> None:
        self.frame = self.model.task_frame(self.frame, "impedance control")
        self._frame_id = self.model.frame_id(self.frame)
        position = _checked_position(self.model, self.frame, self.position)
        if callable(position):
            raise InputError("position", "a fixed rest position X, Y, Z in [m]", "a function")
        self.position = position
        self._rotation = None if self.orientation is None else target_rotation(self.orientation)
        rows = 3 if self._rotation is None else 6
        self.stiffness = _gains(self.stiffness, rows, "stiffness", "[N/m], then [N m/rad]")
        self.damping = _gains(self.damping, rows, "damping", "[N s/m], then [N m s/rad]")

    def deflection(self, q: np.ndarray) -> np.ndarray:
        """The frame's displacement from rest, shape (3,) or (6,): position in [m], then (with an orientation)
        the rotation from rest as a rotation vector in world axes in [rad]. A steady wrench ``F`` there gives ``K⁻¹ F``.

        Args:
            q: Configuration, shape (nq,), in [rad] / [m].
        """
        state = _frame_state(self.model, self._frame_id, q, np.zeros(self.model.nv))
        shift = state.position - np.asarray(self.position)
        if self._rotation is None:
            return shift
        return np.concatenate([shift, -state.rotation @ orientation_error(state.rotation, self._rotation)])

    def __call__(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        model = self.model
        state = _frame_state(model, self._frame_id, q, v)
        rows = 3 if self._rotation is None else 6
        jacobian = state.jacobian[:rows]
        error = np.asarray(self.position) - state.position
        if self._rotation is not None:  # the spring's torque about the world axes
            error = np.concatenate([error, state.rotation @ orientation_error(state.rotation, self._rotation)])
        wrench = self.stiffness * error - self.damping * (jacobian @ v)
        gram = jacobian @ jacobian.T + PSEUDO_INVERSE_DAMPING * np.eye(rows)
        null_space = np.eye(model.nv) - jacobian.T @ np.linalg.solve(gram, jacobian)
        compensation = viscous_compensation(model, self.compensate_damping, v)
        return model.gravity(q) + jacobian.T @ wrench - null_space.T @ (self.null_damping * v) + compensation

    def twin_refusal(self) -> str | None:
        """Why this controller has no compiled twin (a floating base, or a changed law)."""
        return law_refusal(self, Impedance)

    def compiled(self) -> CompiledImpedance:
        """The same law in C (:class:`~robodyn.compiled.controllers.CompiledImpedance`)."""
        from robodyn.compiled.controllers import CompiledImpedance

        model = compiled_model(self.model, self.twin_refusal())
        assert self.frame is not None  # resolved by __post_init__
        viscous = viscous_params(self.model, self.compensate_damping, self.model.nv)
        gains = np.asarray(self.stiffness), np.asarray(self.damping), self.null_damping
        return CompiledImpedance(model, self.frame, self.position, self._rotation, *gains, viscous)
