"""Force control in contact: hybrid force/motion control and explicit force control.

Controllers ``controller(t, q, v) -> tau`` built on their **own** model of the robot, like
those of :mod:`robodyn.sim.control` and :mod:`robodyn.sim.operational_space`; simulate
them with the contact as a constraint (:func:`robodyn.sim.constrained.simulate_constrained`).

:class:`HybridForceMotion` — Khatib's operational-space hybrid law. A frame's origin
touches a flat surface with outward normal ``n`` (world axes). The **selection** is made
in the surface's frame: ``Ω = I − n nᵀ`` picks the motion directions (along the surface),
``Ω̃ = n nᵀ`` the force direction. With the frame's position Jacobian ``J`` (3 × nv), the
task inertia ``Λ = (J M⁻¹ Jᵀ)⁻¹`` and ``J̄ = M⁻¹ Jᵀ Λ``::

    tau = Jᵀ (Λ (Ω ẍ* − J̇ v) − F n) + C v + G + b ∘ v + (I − J̄ J)ᵀ τ₀

with ``ẍ* = ẍ_d + Kd ė + Kp e`` (``e = x_d − x``) and ``F`` the commanded normal force in
[N] (the frame pushes the surface with ``F``; the surface pushes back ``λ n``). With the
contact ``nᵀ ẍ = 0`` the task acceleration is ``ẍ = Ω ẍ* + Λ⁻¹ n (λ − F)``, so
``nᵀ Λ⁻¹ n (λ − F) = 0``: **the contact force is the command, at every instant**, and the
motion error obeys ``ë + Kd ė + Kp e = 0`` along the surface, undisturbed by the force
(the decoupling). The commanded force ``−F n`` has no component along the surface
(``Ω n = 0``): it does no work on the motion. ``τ₀ = M (Kp₀ (q₀ − q) − Kd₀ v)`` is a
posture for a redundant arm, kept out of the task by the dynamically consistent null space.
``b ∘ v`` cancels the joints' viscous damping (the model's :attr:`~robodyn.Robot.joint_damping`)
when ``compensate_damping`` is on (what a run that applies it sets,
:func:`robodyn.sim.twin.compensate`), else 0: uncancelled, the damping of the sliding
motion biases the force by ``nᵀ J M⁻¹ b v / nᵀ Λ⁻¹ n``.

``decoupled=False`` replaces ``Λ`` by a scalar mass (the mean of its eigenvalues over the
directions the frame can move in): the classical law without dynamic decoupling, whose
force transient leaks into the motion (the negative control of the tests).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import KW_ONLY, dataclass, field

import numpy as np
import pinocchio as pin

from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError
from robodyn.sim.operational_space import TASK_DAMPING, TaskReference, damped_task_inertia
from robodyn.sim.twin import viscous_compensation

#: Eigenvalues of ``Λ`` below this times the largest are directions the frame cannot move in.
DIRECTION_TOLERANCE = 1e-6


def unit_normal(normal: np.ndarray | Sequence[float], name: str = "normal") -> np.ndarray:
    """A surface normal as a unit 3-vector.

    Args:
        normal: The normal in world axes, 3 finite numbers, not all zero (any length).
        name: The parameter's name, for the error.

    Raises:
        InputError: For another shape, non-finite values or a zero vector.
    """
    value = vector(normal, name, 3, "world axes")
    if not np.linalg.norm(value) > 1e-12:
        raise InputError(name, "a non-zero 3-vector in world axes", "a zero vector")
    return value / np.linalg.norm(value)


def _reference(motion: np.ndarray | TaskReference, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(x_d, ẋ_d, ẍ_d) at a time, each (3,) [m], [m/s], [m/s²]."""
    if callable(motion):
        x_d, dx_d, ddx_d = motion(t)
        return np.asarray(x_d, float), np.asarray(dx_d, float), np.asarray(ddx_d, float)
    return np.asarray(motion, float), np.zeros(3), np.zeros(3)


def vector(value: object, name: str, size: int = 3, unit: str = "[m]") -> np.ndarray:
    """``value`` as ``size`` finite floats.

    Args:
        value: The value given.
        name: The parameter's name, for the error.
        size: The number of entries expected.
        unit: Its unit or axes as the error states them (e.g. ``"[m]"``).

    Raises:
        InputError: Naming ``name``, for anything else.
    """
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(name, f"{size} finite numbers in {unit}", repr(value)[:80]) from None
    if array.shape != (size,) or not np.isfinite(array).all():
        raise InputError(
            name, f"{size} finite numbers in {unit}", f"shape {array.shape}" if array.shape != (size,) else "non-finite values"
        )
    return array


def scalar(value: object, name: str, expected: str) -> float:
    """``value`` as a finite float ≥ 0.

    Args:
        value: The value given.
        name: The parameter's name, for the error.
        expected: What the error says is expected (e.g. ``"a finite gain ≥ 0 in [1/s²]"``).

    Raises:
        InputError: Naming ``name``, for anything else.
    """
    try:
        number = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise InputError(name, expected, repr(value)[:80]) from None
    if not (np.isfinite(number) and number >= 0):
        raise InputError(name, expected, repr(value)[:80])
    return number


def _checked_motion(motion: np.ndarray | TaskReference) -> np.ndarray | TaskReference:
    try:
        start = _reference(motion, 0.0)
    except (TypeError, ValueError):
        raise InputError("motion", "3 finite values in [m] (or a function t -> (x_d, ẋ_d, ẍ_d))", repr(motion)[:80]) from None
    if any(part.shape != (3,) or not np.isfinite(part).all() for part in start):
        raise InputError("motion", "3 finite values in [m] (or a function t -> (x_d, ẋ_d, ẍ_d))", "another value")
    return motion if callable(motion) else start[0]


def _frame_terms(model: Robot, frame_id: int, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The frame origin's position (3,), position Jacobian (3, nv) and ``J̇ v`` (3,), world axes."""
    data = model.data
    pin.computeJointJacobians(model.model, data, q)
    pin.forwardKinematics(model.model, data, q, v, np.zeros(model.nv))
    placement = pin.updateFramePlacement(model.model, data, frame_id)
    jacobian = pin.getFrameJacobian(model.model, data, frame_id, pin.LOCAL_WORLD_ALIGNED).reshape(6, model.nv)[:3]
    bias = pin.getFrameClassicalAcceleration(model.model, data, frame_id, pin.LOCAL_WORLD_ALIGNED).linear
    return placement.translation.copy(), jacobian.copy(), np.asarray(bias).copy()


@dataclass
class HybridForceMotion:
    """Hybrid force/motion control of a frame on a flat surface, in operational space.

    Attributes:
        model: The controller's model of the robot.
        frame: The frame whose origin touches the surface; ``None``: the end effector.
        normal: The surface's outward normal (toward the robot), world axes, (3,).
        force: The commanded normal force in [N] (> 0: pressing).
        motion: The target position of the frame's origin in [m], world axes (3,), or a
            function ``t -> (x_d, ẋ_d, ẍ_d)``; only its part along the surface is used.
        kp: Motion stiffness in [1/s²]. kd: Motion damping in [1/s].
        posture: A configuration (nq,) the arm is drawn toward in the task's null space
            (``None``: damping alone). posture_kp [1/s²], posture_kd [1/s].
        decoupled: ``False`` for the law without dynamic decoupling (module docstring).
        damping: Damping of ``Λ`` relative to the largest eigenvalue of ``J M⁻¹ Jᵀ``.
        compensate_damping: Add ``b ∘ v`` (the model's joint damping; module docstring).

    Raises:
        FrameError: Unknown frame. InputError: A bad normal, force, motion or posture.
    """

    model: Robot
    frame: str | None
    normal: np.ndarray | Sequence[float]
    force: float
    motion: np.ndarray | TaskReference
    _: KW_ONLY
    kp: float = 400.0
    kd: float = 40.0
    posture: np.ndarray | None = None
    posture_kp: float = 25.0
    posture_kd: float = 10.0
    decoupled: bool = True
    damping: float = TASK_DAMPING
    compensate_damping: bool = False
    _frame_id: int = field(init=False, repr=False)
    _normal: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self.frame = self.model.task_frame(self.frame, "hybrid force/motion control")
        self._frame_id = self.model.frame_id(self.frame)
        self._normal = unit_normal(self.normal)
        self.normal = self._normal
        self.force = scalar(self.force, "force", "a finite normal force >= 0 in [N] (pressing)")
        self.motion = _checked_motion(self.motion)
        for name in ("kp", "kd", "posture_kp", "posture_kd"):
            setattr(self, name, scalar(getattr(self, name), name, "a finite gain >= 0"))
        if self.posture is not None:
            (self.posture,), batch = self.model.validate(q=self.posture)
            if batch:
                raise InputError("posture", f"one configuration ({self.model.nq} values)", f"shape {self.posture.shape}")

    @property
    def motion_selection(self) -> np.ndarray:
        """``Ω = I − n nᵀ``: the directions along the surface, (3, 3)."""
        return np.eye(3) - np.outer(self._normal, self._normal)

    @property
    def force_selection(self) -> np.ndarray:
        """``Ω̃ = n nᵀ``: the direction of the force, (3, 3)."""
        return np.outer(self._normal, self._normal)

    @property
    def force_command(self) -> np.ndarray:
        """The force the frame applies to the surface, ``−F n``, in [N], world axes (3,)."""
        return -self.force * self._normal

    def motion_error(self, t: float, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``Ω e`` and ``Ω ė`` (``e = x_d − x``), in [m] and [m/s], world axes, each (3,).

        Args:
            t: Time in [s] (the reference ``x_d(t)``).
            q: Configuration, shape (nq,).
            v: Velocity, shape (nv,).
        """
        position, jacobian, _ = _frame_terms(self.model, self._frame_id, q, v)
        x_d, dx_d, _ = _reference(self.motion, t)
        selection = self.motion_selection
        return selection @ (x_d - position), selection @ (dx_d - jacobian @ v)

    def _task_inertia(self, inertia: np.ndarray) -> np.ndarray:
        """``Λ``, or without decoupling the mean of its eigenvalues where the frame can move."""
        if self.decoupled:
            return inertia
        values = np.linalg.eigvalsh(inertia)
        moving = values[values > DIRECTION_TOLERANCE * values[-1]]
        return float(moving.mean()) * np.eye(3)

    def __call__(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        model = self.model
        position, jacobian, bias = _frame_terms(model, self._frame_id, q, v)
        x_d, dx_d, ddx_d = _reference(self.motion, t)
        command = ddx_d + self.kd * (dx_d - jacobian @ v) + self.kp * (x_d - position)
        mass = model.mass_matrix(q)
        mass_inv_jt = np.linalg.solve(mass, jacobian.T)
        inertia = damped_task_inertia(jacobian @ mass_inv_jt, self.damping)
        null_space = np.eye(model.nv) - mass_inv_jt @ inertia @ jacobian  # N = I − J̄ J
        posture_error = np.zeros(model.nv) if self.posture is None else pin.difference(model.model, q, self.posture)
        posture = mass @ (self.posture_kp * posture_error - self.posture_kd * v)
        task = self._task_inertia(inertia) @ (self.motion_selection @ command - bias) + self.force_command
        compensation = viscous_compensation(model, self.compensate_damping, v)
        return jacobian.T @ task + model.nonlinear_effects(q, v) + compensation + null_space.T @ posture


def circle(
    center: np.ndarray | Sequence[float], radius: float, normal: np.ndarray | Sequence[float], period: float
) -> TaskReference:
    """A path around a circle at constant speed, starting at ``center + radius · u``.

    Args:
        center: The circle's centre in [m], world axes (3,).
        radius: In [m] (> 0).
        normal: The circle's plane normal (3,); ``u``, ``w`` complete it to a right-handed frame.
        period: Time of one turn in [s] (> 0).

    Returns:
        ``t -> (x_d, ẋ_d, ẍ_d)``, each (3,).
    """
    axis = unit_normal(normal)
    if not scalar(radius, "radius", "a finite radius > 0 in [m]") > 0:
        raise InputError("radius", "a finite radius > 0 in [m]", repr(radius))
    if not scalar(period, "period", "a finite time > 0 in [s]") > 0:
        raise InputError("period", "a finite time > 0 in [s]", repr(period))
    seed = np.eye(3)[int(np.argmin(np.abs(axis)))]
    u = np.cross(axis, seed)
    u /= np.linalg.norm(u)
    w = np.cross(axis, u)
    middle, rate = vector(center, "center"), 2 * np.pi / float(period)

    def reference(t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        c, s = np.cos(rate * t), np.sin(rate * t)
        return (
            middle + radius * (c * u + s * w),
            radius * rate * (-s * u + c * w),
            -radius * rate**2 * (c * u + s * w),
        )

    return reference


__all__ = ["DIRECTION_TOLERANCE", "HybridForceMotion", "circle", "scalar", "unit_normal", "vector"]
