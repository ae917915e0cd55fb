"""The compiled twins of the controllers, and their parameter layouts, declared once.

A twin holds its **own** compiled model (which may differ from the plant) and packs its
parameters into one float64 array that the C loop (``runtime.c``'s controller section)
reads at every integration stage. Each twin class declares, in one place:

- ``law``: its name in C (``RD_KIND_<LAW>``, ``RD_<LAW>_<FIELD>(n)``);
- ``layout``: its parameters in order, each ``(field, (a, b, c))``: ``a + b n + c n²`` values,
  ``n`` the law's coordinates (all of them, or a floating base's joints);
- ``params(n)``: the array in that order.

:func:`c_constants` prints the kind numbers (the position in :data:`TWINS`, from 1; kind 0
holds a given torque), each field's offset and each law's size as C macros, prepended to
``runtime.c`` by :mod:`robodyn.compiled.build`; :func:`check_layout` asserts that a twin's
``params`` has the size its layout declares. The Python controllers of :mod:`robodyn.sim`
make their twins (their ``compiled()`` method); this module does not know them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, ClassVar, Protocol, runtime_checkable

import numpy as np

from robodyn.common.inputs import as_state
from robodyn.exceptions import CompileError, InputError

if TYPE_CHECKING:
    from robodyn.compiled.robot import CompiledRobot

#: A parameter: its field name and its size ``(a, b, c)``: ``a + b n + c n²`` values for a law
#: of ``n`` coordinates.
Field = tuple[str, tuple[int, int, int]]


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


def _gain(value: float | np.ndarray, name: str, nv: int) -> np.ndarray:
    return as_state(np.broadcast_to(np.asarray(value, dtype=float), (nv,)) if np.ndim(value) == 0 else value, name, nv)


def _viscous(viscous: np.ndarray | None, n: int) -> np.ndarray:
    """The damping ``b`` the law adds as ``b ∘ v`` (shape (n,), in [N m s/rad] or [N s/m]); zeros: none."""
    return np.zeros(n) if viscous is None else _vector(viscous, "viscous", n)


def _rotation(rotation: np.ndarray | None) -> tuple[int, np.ndarray]:
    """Task rows (3 without a target attitude, 6 with) and the target rotation (9, row-major)."""
    if rotation is None:
        return 3, np.eye(3).reshape(-1)
    matrix = np.asarray(rotation, dtype=float)
    if matrix.shape != (3, 3) or not np.isfinite(matrix).all():
        raise InputError("rotation", "a 3 × 3 rotation matrix", f"shape {matrix.shape}")
    return 6, matrix.reshape(-1)


@dataclass(frozen=True)
class CompiledLaw:
    """What every twin has: the controller's compiled model, its C name and layout.

    Attributes:
        model: The controller's model (may differ from the plant).
    """

    model: CompiledRobot
    law: ClassVar[str] = ""
    layout: ClassVar[tuple[Field, ...]] = ()
    #: Whether the law drives a floating robot's joints (its base free); else fixed bases only.
    floating: ClassVar[bool] = False

    @property
    def kind(self) -> int:
        """The law's kind number in the C loop (its class's position in :data:`TWINS`, from 1)."""
        return next(kind for kind, twin in enumerate(TWINS, start=1) if isinstance(self, twin))

    def frame_kernels(self) -> object | None:
        """The controlled frame's C kernels (a capsule), ``None`` for a joint-space law."""
        return None

    def params(self, n: int) -> np.ndarray:  # pragma: no cover - every twin overrides it
        """The parameters in :attr:`layout`'s order, for a law of ``n`` coordinates.

        Args:
            n: The law's coordinate count: the robot's nv, or nv − 6 (its joints) on a floating
                base.

        Returns:
            The parameters, shape (size(twin, n),) (:func:`size`).
        """
        raise NotImplementedError


@dataclass(frozen=True)
class CompiledPDGravity(CompiledLaw):
    """``tau = Kp (target − q) − Kd v + G(q)``, ``G`` from the controller's own compiled model.

    Attributes:
        target: Joint target, shape (n,).
        kp: Stiffness in [N m/rad] or [N/m], scalar or shape (n,).
        kd: Damping in [N m s/rad] or [N s/m], scalar or shape (n,).
    """

    target: np.ndarray = field(default_factory=lambda: np.zeros(0))
    kp: float | np.ndarray = 100.0
    kd: float | np.ndarray = 20.0
    law: ClassVar[str] = "PD"
    layout: ClassVar[tuple[Field, ...]] = (("target", (0, 1, 0)), ("kp", (0, 1, 0)), ("kd", (0, 1, 0)))
    floating: ClassVar[bool] = True

    def params(self, n: int) -> np.ndarray:
        return np.concatenate([as_state(self.target, "target", n), _gain(self.kp, "kp", n), _gain(self.kd, "kd", n)])


@dataclass(frozen=True)
class CompiledComputedTorque(CompiledLaw):
    """Computed torque along a quintic rest-to-rest reference:
    ``tau = M(q) (a_d + Kd (v_d − v) + Kp (q_d − q)) + C v + G`` on the controller's model.

    Attributes:
        q_start, q_end: Ends of the reference, shape (n,).
        duration: Motion time in [s] (then the reference holds ``q_end``).
        kp: Position gain in [1/s²]; kd: velocity gain in [1/s] (scalars or shape (n,)).
        viscous: The joints' damping ``b`` the law compensates (adds ``b ∘ v``), shape (n,);
            ``None``: the rigid-body law.
    """

    q_start: np.ndarray = field(default_factory=lambda: np.zeros(0))
    q_end: np.ndarray = field(default_factory=lambda: np.zeros(0))
    duration: float = 1.0
    kp: float | np.ndarray = 400.0
    kd: float | np.ndarray = 40.0
    viscous: np.ndarray | None = None
    law: ClassVar[str] = "CT"
    layout: ClassVar[tuple[Field, ...]] = (
        ("q_start", (0, 1, 0)), ("q_end", (0, 1, 0)), ("kp", (0, 1, 0)), ("kd", (0, 1, 0)), ("duration", (1, 0, 0)),
        ("viscous", (0, 1, 0)),
    )  # fmt: skip
    floating: ClassVar[bool] = True

    def params(self, n: int) -> np.ndarray:
        if not (math.isfinite(self.duration) and self.duration > 0):
            raise InputError("duration", "finite and > 0", repr(self.duration))
        ends = [as_state(self.q_start, "q_start", n), as_state(self.q_end, "q_end", n)]
        gains = [_gain(self.kp, "kp", n), _gain(self.kd, "kd", n)]
        return np.concatenate([*ends, *gains, [float(self.duration)], _viscous(self.viscous, n)])


@dataclass(frozen=True)
class CompiledFrameController(CompiledLaw):
    """What the frame twins share: a frame whose kinematics is generated C.

    Attributes:
        frame: The controlled frame (a link or joint name of ``model``).
    """

    frame: str = ""

    def frame_kernels(self) -> object:
        """The frame's C kernels (a capsule for the C loop; compiled on first use)."""
        return self.model.frame_module(self.frame)._frame


@dataclass(frozen=True)
class CompiledTaskSpace(CompiledFrameController):
    """:class:`robodyn.sim.control.TaskSpace` in C (same attributes and formulas; ``viscous``:
    the compensated joint damping ``b``, shape (n,), as for :class:`CompiledComputedTorque`)."""

    target: np.ndarray = field(default_factory=lambda: np.zeros(3))
    kp: float = 100.0
    kd: float = 20.0
    damping: float = 1e-6
    joint_damping: float = 5.0
    viscous: np.ndarray | None = None
    law: ClassVar[str] = "TS"
    layout: ClassVar[tuple[Field, ...]] = (
        ("target", (3, 0, 0)), ("kp", (1, 0, 0)), ("kd", (1, 0, 0)), ("damping", (1, 0, 0)), ("joint_damping", (1, 0, 0)),
        ("viscous", (0, 1, 0)),
    )  # fmt: skip

    def params(self, n: int) -> np.ndarray:
        gains = [_scalar(getattr(self, name), name) for name in ("kp", "kd", "damping", "joint_damping")]
        return np.concatenate([_vector(self.target, "target", 3), gains, _viscous(self.viscous, n)])


@dataclass(frozen=True)
class CompiledOperationalSpace(CompiledFrameController):
    """:class:`robodyn.sim.operational_space.OperationalSpace` in C, for a fixed target.

    Attributes:
        position: Target position in [m], shape (3,).
        rotation: Target attitude as a rotation matrix (3, 3); ``None``: position only.
        kp, kd, posture, posture_kp, posture_kd, damping: As the Python controller's.
        viscous: The compensated joint damping ``b``, shape (n,) (as for :class:`CompiledComputedTorque`).
        singular_damping, singular_threshold: As the Python controller's.
        length: The chain's characteristic length ``ℓ`` in [m]. rank: The task's generic rank
            (:mod:`robodyn.sim.task_damping`).
    """

    position: np.ndarray = field(default_factory=lambda: np.zeros(3))
    rotation: np.ndarray | None = None
    kp: float = 100.0
    kd: float = 20.0
    posture: np.ndarray | None = None
    posture_kp: float = 25.0
    posture_kd: float = 10.0
    damping: float = 1e-8
    viscous: np.ndarray | None = None
    singular_damping: float = 0.0
    singular_threshold: float = 0.0
    length: float = 1.0
    rank: int = 0
    law: ClassVar[str] = "OSC"
    layout: ClassVar[tuple[Field, ...]] = (
        ("rows", (1, 0, 0)), ("position", (3, 0, 0)), ("rotation", (9, 0, 0)), ("kp", (1, 0, 0)), ("kd", (1, 0, 0)), ("damping", (1, 0, 0)),
        ("posture_kp", (1, 0, 0)), ("posture_kd", (1, 0, 0)), ("has_posture", (1, 0, 0)), ("posture", (0, 1, 0)), ("viscous", (0, 1, 0)),
        ("singular_damping", (1, 0, 0)), ("singular_threshold", (1, 0, 0)), ("length", (1, 0, 0)), ("rank", (1, 0, 0)),
    )  # fmt: skip

    def params(self, n: int) -> np.ndarray:
        rows, rotation = _rotation(self.rotation)
        gains = [_scalar(getattr(self, name), name) for name in ("kp", "kd", "damping", "posture_kp", "posture_kd")]
        posture = np.zeros(n) if self.posture is None else as_state(self.posture, "posture", n)
        singular = [_scalar(getattr(self, name), name) for name in ("singular_damping", "singular_threshold", "length")]
        return np.concatenate(
            [[rows], _vector(self.position, "position", 3), rotation, gains, [float(self.posture is not None)], posture,
             _viscous(self.viscous, n), singular, [float(self.rank)]]
        )  # fmt: skip


@dataclass(frozen=True)
class CompiledImpedance(CompiledFrameController):
    """:class:`robodyn.sim.operational_space.Impedance` in C.

    Attributes:
        position: Rest position in [m], shape (3,).
        rotation: Rest attitude (3, 3); ``None`` leaves it free.
        stiffness: [N/m] then [N m/rad], shape (3,) or (6,) (as many as the task's rows).
        damping: [N s/m] then [N m s/rad], same shape.
        null_damping: In [N m s/rad].
        viscous: The compensated joint damping ``b``, shape (n,) (as for :class:`CompiledComputedTorque`).
    """

    position: np.ndarray = field(default_factory=lambda: np.zeros(3))
    rotation: np.ndarray | None = None
    stiffness: np.ndarray = field(default_factory=lambda: np.array([500.0] * 3))
    damping: np.ndarray = field(default_factory=lambda: np.array([50.0] * 3))
    null_damping: float = 1.0
    viscous: np.ndarray | None = None
    law: ClassVar[str] = "IMP"
    layout: ClassVar[tuple[Field, ...]] = (
        ("rows", (1, 0, 0)), ("position", (3, 0, 0)), ("rotation", (9, 0, 0)), ("stiffness", (6, 0, 0)), ("damping", (6, 0, 0)), ("null_damping", (1, 0, 0)),
        ("viscous", (0, 1, 0)),
    )  # fmt: skip

    def params(self, n: int) -> np.ndarray:
        rows, rotation = _rotation(self.rotation)
        stiffness, damping = np.zeros(6), np.zeros(6)
        stiffness[:rows] = _vector(self.stiffness, "stiffness", rows)
        damping[:rows] = _vector(self.damping, "damping", rows)
        null = [_scalar(self.null_damping, "null_damping")]
        return np.concatenate(
            [[rows], _vector(self.position, "position", 3), rotation, stiffness, damping, null, _viscous(self.viscous, n)]
        )


@dataclass(frozen=True)
class CompiledLQR(CompiledLaw):
    """:class:`robodyn.sim.control.LQR` in C: ``tau = S_act (u_eq − K (x − x_eq))``, ``x = (q, v)``.

    Attributes:
        gain: ``K``, shape (nu, 2 n).
        u_eq: The holding input, shape (nu,).
        actuation: ``S_act``, shape (n, nu): the actuated joints' columns of the identity.
        x_eq: The equilibrium ``(q_eq, v_eq)``, shape (2 n,).
    """

    gain: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    u_eq: np.ndarray = field(default_factory=lambda: np.zeros(0))
    actuation: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    x_eq: np.ndarray = field(default_factory=lambda: np.zeros(0))
    law: ClassVar[str] = "LQR"
    layout: ClassVar[tuple[Field, ...]] = (("u", (0, 1, 0)), ("k", (0, 0, 2)), ("x_eq", (0, 2, 0)))

    def params(self, n: int) -> np.ndarray:
        actuation = np.asarray(self.actuation, dtype=float)
        inputs = actuation.shape[1] if actuation.ndim == 2 else -1
        gain = np.asarray(self.gain, dtype=float)
        if actuation.shape != (n, inputs) or gain.shape != (inputs, 2 * n) or not np.isfinite(gain).all():
            raise InputError(
                "gain and actuation", f"K (nu, {2 * n}) and S_act ({n}, nu), finite", f"{gain.shape}, {actuation.shape}"
            )
        u_eq, x_eq = _vector(self.u_eq, "u_eq", inputs), _vector(self.x_eq, "x_eq", 2 * n)
        # S_act selects: S u and S K are the actuated rows, the others zero (exact products)
        return np.concatenate([actuation @ u_eq, (actuation @ gain).reshape(-1), x_eq])


#: The twins the C loop runs, in kind order (kind 0: a held torque). A new law is one more
#: class here and its C function in runtime.c's controller section.
TWINS: tuple[type[CompiledLaw], ...] = (
    CompiledPDGravity, CompiledComputedTorque, CompiledTaskSpace, CompiledOperationalSpace, CompiledImpedance, CompiledLQR,
)  # fmt: skip
CompiledController = CompiledLaw


@runtime_checkable
class HasTwin(Protocol):
    """A controller that owns its compiled form (the controllers of :mod:`robodyn.sim`)."""

    def twin_refusal(self) -> str | None:
        """Why this controller has no compiled twin (one sentence), ``None`` when it has one."""

    def compiled(self) -> CompiledLaw:
        """The twin, on the controller's own model compiled (:class:`CompileError` when it has none)."""


def size(twin: type[CompiledLaw], n: int) -> int:
    """The number of parameters a law of ``n`` coordinates takes (its layout, summed).

    Args:
        twin: The twin's class.
        n: The law's coordinate count: the robot's nv, or nv − 6 (its joints) on a floating
            base.
    """
    return sum(a + b * n + c * n * n for _, (a, b, c) in twin.layout)


def _c_size(a: int, b: int, c: int) -> str:
    """``a + b n + c n²`` as C, of the macro parameter ``n``."""
    terms = (str(a) if a else "", f"{b} * (n)" if b else "", f"{c} * (n) * (n)" if c else "")
    return " + ".join(term for term in terms if term) or "0"


def check_layout(twin: CompiledLaw, n: int) -> np.ndarray:
    """The twin's parameters, checked against its declared layout's size.

    Args:
        twin: The compiled controller.
        n: The law's coordinate count: the robot's nv, or nv − 6 (its joints) on a floating
            base.

    Raises:
        CompileError: The twin's parameters do not have its layout's size.
    """
    params = np.ascontiguousarray(twin.params(n), dtype=float)
    if params.shape != (size(type(twin), n),):  # pragma: no cover - a twin's own bug
        raise CompileError(twin.model.name, f"{type(twin).__name__}.params gives {params.size} values, its layout another count")
    return params


def c_constants() -> str:
    """The C macros of the controllers: ``RD_KIND_<LAW>``, ``RD_<LAW>_<FIELD>(n)`` (offsets),
    ``RD_<LAW>_SIZE(n)``, ``RD_KINDS`` and ``RD_PARAM_SIZE(kind, n, nj)`` (kind 0: n)."""
    lines = ["/* Generated by robodyn.compiled.controllers.c_constants: kinds and parameter layouts. */"]
    sizes = ["(kind) == 0 ? (n)"]
    for kind, twin in enumerate(TWINS, start=1):
        lines.append(f"#define RD_KIND_{twin.law} {kind}")
        offset = (0, 0, 0)
        for name, part in twin.layout:
            lines.append(f"#define RD_{twin.law}_{name.upper()}(n) ({_c_size(*offset)})")
            offset = (offset[0] + part[0], offset[1] + part[1], offset[2] + part[2])
        lines.append(f"#define RD_{twin.law}_SIZE(n) ({_c_size(*offset)})")
        sizes.append(f"(kind) == {kind} ? RD_{twin.law}_SIZE({'nj' if twin.floating else 'n'})")
    lines.append(f"#define RD_KINDS {len(TWINS) + 1}")
    lines.append(f"#define RD_PARAM_SIZE(kind, n, nj) ({' : '.join(sizes)} : -1)")
    return "\n".join(lines) + "\n"
