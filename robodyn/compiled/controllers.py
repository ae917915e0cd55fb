"""Compiled twins of the frame controllers (task space, operational space, impedance) and LQR.

Each holds its **own** compiled model (like :class:`~robodyn.compiled.simulation.CompiledPDGravity`)
and a frame whose kinematics is generated C (:mod:`robodyn.compiled.kinematics`); the C loop
(``runtime.c``, kinds 3–5) evaluates the same formulas as the Python controllers of
:mod:`robodyn.sim.control` and :mod:`robodyn.sim.operational_space`, at every integration
stage. :func:`robodyn.compiled.simulation.compiled_controller` builds them from the Python
controllers; they can also be made directly.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from robodyn.common.inputs import as_state
from robodyn.compiled.robot import CompiledRobot
from robodyn.exceptions import InputError


def _vector(value: np.ndarray | float, name: str, size: int) -> np.ndarray:
    array = np.broadcast_to(np.asarray(value, dtype=float), (size,)) if np.ndim(value) == 0 else np.asarray(value, float)
    if array.shape != (size,) or not np.isfinite(array).all():
        raise InputError(name, f"{size} finite values", f"shape {np.shape(value)}")
    return np.array(array)


def _scalar(value: float, name: str) -> float:
    number = float(value)
    if not np.isfinite(number):
        raise InputError(name, "a finite number", repr(value))
    return number


def _rotation(rotation: np.ndarray | None) -> tuple[int, np.ndarray]:
    """Task rows (3 without a target attitude, 6 with) and the target rotation (9, row-major)."""
    if rotation is None:
        return 3, np.eye(3).reshape(-1)
    matrix = np.asarray(rotation, dtype=float)
    if matrix.shape != (3, 3) or not np.isfinite(matrix).all():
        raise InputError("rotation", "a 3 × 3 rotation matrix", f"shape {matrix.shape}")
    return 6, matrix.reshape(-1)


@dataclass(frozen=True)
class CompiledFrameController:
    """What the frame twins share: the controller's compiled model and its frame.

    Attributes:
        model: The controller's model (may differ from the plant).
        frame: The controlled frame (a link or joint name of ``model``).
    """

    model: CompiledRobot
    frame: str
    kind: ClassVar[int] = 0

    def frame_kernels(self) -> object:
        """The frame's C kernels (a capsule for the C loop; compiled on first use)."""
        return self.model.frame_module(self.frame)._frame

    def params(self, nv: int) -> np.ndarray:  # pragma: no cover - every twin overrides it
        raise NotImplementedError


@dataclass(frozen=True)
class CompiledTaskSpace(CompiledFrameController):
    """:class:`robodyn.sim.control.TaskSpace` in C (same attributes and formulas)."""

    target: np.ndarray = field(default_factory=lambda: np.zeros(3))
    kp: float = 100.0
    kd: float = 20.0
    damping: float = 1e-6
    joint_damping: float = 5.0
    kind: ClassVar[int] = 3

    def params(self, nv: int) -> np.ndarray:
        gains = [_scalar(getattr(self, name), name) for name in ("kp", "kd", "damping", "joint_damping")]
        return np.concatenate([_vector(self.target, "target", 3), gains])


@dataclass(frozen=True)
class CompiledOperationalSpace(CompiledFrameController):
    """:class:`robodyn.sim.operational_space.OperationalSpace` in C, for a fixed target.

    Attributes:
        position: Target position in [m], shape (3,).
        rotation: Target attitude as a rotation matrix (3, 3); ``None``: position only.
        kp, kd, posture, posture_kp, posture_kd, damping: As the Python controller's.
    """

    position: np.ndarray = field(default_factory=lambda: np.zeros(3))
    rotation: np.ndarray | None = None
    kp: float = 100.0
    kd: float = 20.0
    posture: np.ndarray | None = None
    posture_kp: float = 25.0
    posture_kd: float = 10.0
    damping: float = 1e-8
    kind: ClassVar[int] = 4

    def params(self, nv: int) -> np.ndarray:
        rows, rotation = _rotation(self.rotation)
        gains = [_scalar(getattr(self, name), name) for name in ("kp", "kd", "damping", "posture_kp", "posture_kd")]
        posture = np.zeros(nv) if self.posture is None else as_state(self.posture, "posture", nv)
        return np.concatenate(
            [[rows], _vector(self.position, "position", 3), rotation, gains, [float(self.posture is not None)], posture]
        )


@dataclass(frozen=True)
class CompiledImpedance(CompiledFrameController):
    """:class:`robodyn.sim.operational_space.Impedance` in C.

    Attributes:
        position: Rest position in [m], shape (3,).
        rotation: Rest attitude (3, 3); ``None`` leaves it free.
        stiffness: [N/m] then [N m/rad], shape (3,) or (6,) (as many as the task's rows).
        damping: [N s/m] then [N m s/rad], same shape.
        null_damping: In [N m s/rad].
    """

    position: np.ndarray = field(default_factory=lambda: np.zeros(3))
    rotation: np.ndarray | None = None
    stiffness: np.ndarray = field(default_factory=lambda: np.array([500.0] * 3))
    damping: np.ndarray = field(default_factory=lambda: np.array([50.0] * 3))
    null_damping: float = 1.0
    kind: ClassVar[int] = 5

    def params(self, nv: int) -> np.ndarray:
        rows, rotation = _rotation(self.rotation)
        stiffness = np.zeros(6)
        damping = np.zeros(6)
        stiffness[:rows] = _vector(self.stiffness, "stiffness", rows)
        damping[:rows] = _vector(self.damping, "damping", rows)
        return np.concatenate(
            [
                [rows],
                _vector(self.position, "position", 3),
                rotation,
                stiffness,
                damping,
                [_scalar(self.null_damping, "null_damping")],
            ]
        )


@dataclass(frozen=True)
class CompiledLQR:
    """:class:`robodyn.sim.control.LQR` in C: ``tau = S_act (u_eq − K (x − x_eq))``,
    ``x = (q, v)`` (kind 6 of the C loop).

    Attributes:
        model: The controller's compiled model (fixed base; the law itself is linear).
        gain: ``K``, shape (nu, 2 nv).
        u_eq: The holding input, shape (nu,).
        actuation: ``S_act``, shape (nv, nu): the actuated joints' columns of the identity.
        x_eq: The equilibrium ``(q_eq, v_eq)``, shape (2 nv,).
    """

    model: CompiledRobot
    gain: np.ndarray
    u_eq: np.ndarray
    actuation: np.ndarray
    x_eq: np.ndarray
    kind: ClassVar[int] = 6

    def params(self, nv: int) -> np.ndarray:
        actuation = np.asarray(self.actuation, dtype=float)
        inputs = actuation.shape[1] if actuation.ndim == 2 else -1
        gain = np.asarray(self.gain, dtype=float)
        if actuation.shape != (nv, inputs) or gain.shape != (inputs, 2 * nv) or not np.isfinite(gain).all():
            raise InputError(
                "gain and actuation", f"K (nu, {2 * nv}) and S_act ({nv}, nu), finite", f"{gain.shape}, {actuation.shape}"
            )
        u_eq, x_eq = _vector(self.u_eq, "u_eq", inputs), _vector(self.x_eq, "x_eq", 2 * nv)
        # S_act selects: S u and S K are the actuated rows, the others zero (exact products)
        return np.concatenate([actuation @ u_eq, (actuation @ gain).reshape(-1), x_eq])
