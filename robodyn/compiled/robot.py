"""``compile(robot)``: a robot's dynamics as native code, with the same API as :class:`robodyn.Robot`.

A :class:`CompiledRobot` computes ``tau``, ``M``, ``C v + G``, ``G`` and the forward
dynamics of a robot in generated C (a floating base is Pinocchio's free flyer: ``q`` starts
with the base position and quaternion x, y, z, w, ``v`` with its linear and angular velocity
in its own frame) (see :mod:`robodyn.compiled.codegen`),
built once and cached (see :mod:`robodyn.compiled.build`). The rules are the
:class:`~robodyn.Robot`'s: one state as 1-D arrays gives one result, a stack (one state a
row) gives a stack; inputs go through the robot's own boundary
(:meth:`robodyn.dynamics.handle.ModelHandle.validate`), so a wrong size, a NaN or a complex
number gets the same :class:`~robodyn.exceptions.InputError`; a non-finite result of
finite inputs is refused. Mimic joints go through the robot's linear map
(``q_bodies = Q q + offset``, ``M = Sᵀ M_bodies S``).

The single call goes straight to C when its arguments already are float64 C-contiguous
arrays of the right shape (the C code also checks they are finite); anything else takes the
checked path. Batches run across rows on ``threads`` native threads, the GIL released.
"""

from __future__ import annotations

from collections.abc import Callable
from types import ModuleType

import numpy as np

from robodyn.compiled import build
from robodyn.compiled.cache import SNAP, robot_key
from robodyn.compiled.robot_frames import CompiledFrames, fixed_base_only
from robodyn.dynamics.batch import check_threads
from robodyn.dynamics.joint_dynamics import friction_torque
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import CompileError, NonFiniteResultError, SingularMassMatrixError

_ndarray = np.ndarray
_QUANTITIES = {"tau": "tau", "mass": "M", "nle": "C v + G", "gravity": "G", "fd": "a"}


def generate_kernels(robot: Robot) -> str:
    """The C kernels of a robot, printed from its programs
    (:func:`robodyn.compiled.programs.dynamics_programs`: the slow part, a sympy derivation,
    done once per robot key).

    A floating base is the tree's body 0, free (:func:`robodyn.equations.newton_euler.floating_tree`).

    Args:
        robot: The loaded robot.

    Raises:
        CompileError: For joints the reference does not map.
    """
    from robodyn.compiled.codegen import KernelWriter  # sympy and the generator: only now
    from robodyn.compiled.programs import dynamics_programs, robot_bodies

    bodies = robot_bodies(robot)
    programs = dynamics_programs(robot)
    return KernelWriter(programs.compact, bodies.selection, bodies.offset, coordinate_parents(robot), programs.tau).source()


def robot_kernels(robot: Robot) -> str:
    """The robot's kernels: cached under its key, else generated (and cached).

    Args:
        robot: The loaded robot (its cache key, :func:`robodyn.compiled.cache.robot_key`).

    Raises:
        CompileError: For joints the reference does not map.
    """
    key = robot_key(robot)
    kernels = build.cached_kernels(key)
    if kernels is None:
        kernels = generate_kernels(robot)
        build.store_kernels(key, kernels)
    return kernels


def coordinate_parents(robot: Robot) -> list[int]:
    """The parent coordinate of each coordinate (-1 at the root), for the tree LDLᵀ.

    With mimic joints ``M = Sᵀ M_bodies S`` need not keep the tree's sparsity, so the chain
    ``i - 1`` (a dense factorisation) is used. A floating base's six coordinates are a chain
    (a dense 6×6 block) and its children hang from the last.

    Args:
        robot: The loaded robot.

    Returns:
        One parent index per velocity coordinate, length nv.
    """
    model = robot.model
    if robot.mimic is not None:
        return list(range(-1, robot.nv - 1))
    parents: list[int] = []
    for joint_id in range(1, model.njoints):
        if model.joints[joint_id].nv == 0:
            continue
        parent = model.parents[joint_id]
        while parent > 0 and model.joints[parent].nv == 0:
            parent = model.parents[parent]
        joint = model.joints[joint_id]
        parents.extend(range(joint.idx_v - 1, joint.idx_v + joint.nv - 1))
        parents[joint.idx_v] = model.joints[parent].idx_v + model.joints[parent].nv - 1 if parent > 0 else -1
    return parents


def compile(robot: Robot, *, threads: int | None = None) -> CompiledRobot:
    """Compile a robot's dynamics to native code (cached: microseconds the second time).

    The module is found by the robot's key (its URDF text, load options and the generator's
    source), without generating any source: from this process's memory (about 10 µs), else
    the cache folder (milliseconds, no sympy imported); only a robot never compiled is
    derived (seconds) and built. ``robot.model`` is read-only to the compiled robot (see
    :class:`CompiledRobot`). ``robot`` itself is left as it is (it may be the Pinocchio
    reference a caller compares with); robots loaded afterwards with ``engine="auto"`` (the
    default) answer their single calls with these kernels (:mod:`robodyn.compiled.engine`).

    Args:
        robot: From :func:`robodyn.load` (mimic joints and a floating base are fine).
        threads: Native threads for batches; ``None`` for every available core.

    Returns:
        The compiled robot.

    Raises:
        CompileError: If the build fails.
        CompilerNotFoundError: If there is no C compiler (``Robot`` keeps working).
        InputError: For a bad ``threads``.
    """
    threads = check_threads(threads)
    if robot.nv == 0:
        raise CompileError(robot.name, "it has no moving joints")
    module = build.robot_module(robot_key(robot), lambda: robot_kernels(robot), label=robot.name)
    if module.info()["nv"] != robot.nv:
        raise CompileError(robot.name, "the cached kernels do not match the robot; clear the cache folder")
    return CompiledRobot(robot, module, threads=threads)


class CompiledRobot(CompiledFrames):
    """A robot's dynamics in compiled C; the methods and shape rules of :class:`robodyn.Robot`
    (both satisfy :class:`robodyn.dynamics.protocol.Dynamics`, with the same signatures).
    Its frame kinematics: :class:`~robodyn.compiled.robot_frames.CompiledFrames`.

    Attributes:
        robot: The Pinocchio-backed robot it was compiled from (names, limits, checks). Its
            ``model`` is read-only here: the kernels come from the robot's URDF text and load
            options (its cache key, :func:`robodyn.compiled.cache.robot_key`), so a change
            made to ``robot.model`` reaches neither the kernels nor the key; load the robot
            again with the change (``robodyn.load(..., armature=..., gravity=...)``) instead.
        name, nq, nv, joint_names: As the robot's.
        threads: Native threads for batches.
        module: The loaded extension module (``tau``, ``mass``, ``nle``, ``gravity``, ``fd``,
            ``simulate``).
    """

    def __init__(self, robot: Robot, module: ModuleType, *, threads: int | None = None):
        self.robot = robot
        self.module = module
        self.name = robot.name
        self.nq = robot.nq
        self.nv = robot.nv
        self.joint_names = list(robot.joint_names)
        self.threads = check_threads(threads)
        self._tau, self._mass, self._nle = module.tau, module.mass, module.nle
        self._gravity, self._fd = module.gravity, module.fd
        # The derivative module's two functions once it is built (a call reads one attribute).
        self._tau_derivatives: Callable[..., object] | None = None
        self._fd_derivatives: Callable[..., object] | None = None

    def __repr__(self) -> str:
        return f"<CompiledRobot {self.name!r}: nv={self.nv}, threads={self.threads}>"

    @property
    def instruction_set(self) -> str:
        """The instruction set the batches run: ``"avx512"``, ``"avx2"``, ``"sse2"`` (blocks of
        8, 4, 2 states) or ``"scalar"``; see :mod:`robodyn.compiled.simd` (``$ROBODYN_SIMD``)."""
        return str(self.module.info()["instruction_set"])

    def _checked(self, kind: str, function, status, **named: object) -> np.ndarray:
        """The checked path: validate, convert, compute again, refuse what is not finite."""
        arrays, _ = self.robot.validate(**named)
        arrays = [np.ascontiguousarray(array, dtype=np.float64) for array in arrays]
        result = function(*arrays, self.threads)
        if result.__class__ is _ndarray:
            return result
        if result == 3 or kind == "fd":
            raise SingularMassMatrixError(self.name, self.robot.massless_joints)
        if result is None or result == 1:  # cannot happen after validate(): refuse rather than guess
            raise CompileError(self.name, f"the compiled {kind} refused checked inputs (status {result})")
        raise NonFiniteResultError(self.name, _QUANTITIES[kind])

    def inverse_dynamics(self, q: np.ndarray, v: np.ndarray, a: np.ndarray, *, joint_friction: bool = False) -> np.ndarray:
        """Joint torques ``tau = M(q) a + C(q, v) v + G(q)``.

        Args:
            q: Configuration, shape (nq,) or (N, nq), in [rad] / [m].
            v: Velocity, shape (nv,) or (N, nv).
            a: Acceleration, shape (nv,) or (N, nv).
            joint_friction: Add the torques the joints' friction takes, ``b v + f sign(v)``
                (as :meth:`robodyn.Robot.inverse_dynamics`, the same formula on the result).

        Returns:
            Torques in [N m] / [N], shape (nv,) or (N, nv).
        """
        result = self._tau(q, v, a, self.threads)
        if result.__class__ is not _ndarray:
            result = self._checked("tau", self._tau, result, q=q, v=v, a=a)
        if joint_friction:
            robot = self.robot
            result = result - friction_torque(robot.joint_damping, robot.joint_friction, np.asarray(v, dtype=float))
        return result

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        """Joint-space inertia matrix ``M(q)``, symmetric, shape (nv, nv) or (N, nv, nv), in [kg m²] / [kg].

        Args:
            q: Configuration, shape (nq,) or (N, nq), in [rad] / [m] (a floating base: position
                in [m], then its unit quaternion).
        """
        result = self._mass(q, self.threads)
        if result.__class__ is _ndarray:
            return result
        return self._checked("mass", self._mass, result, q=q)

    def nonlinear_effects(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``C(q, v) v + G(q)``, shape (nv,) or (N, nv), in [N m] / [N].

        Args:
            q: Configuration, shape (nq,) or (N, nq), in [rad] / [m] (a floating base: position
                in [m], then its unit quaternion).
            v: Velocity, shape (nv,) or (N, nv), in [rad/s] / [m/s].
        """
        result = self._nle(q, v, self.threads)
        if result.__class__ is _ndarray:
            return result
        return self._checked("nle", self._nle, result, q=q, v=v)

    def coriolis_matrix(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Coriolis and centrifugal matrix ``C(q, v)`` with ``dM/dt = C + Cᵀ``, shape (nv, nv)
        or (N, nv, nv): the robot's own (:meth:`robodyn.Robot.coriolis_matrix`, Pinocchio; the
        compiled programs give ``C v``, not ``C``)."""
        return self.robot.coriolis_matrix(q, v)

    def gravity(self, q: np.ndarray) -> np.ndarray:
        """Generalised gravity ``G(q)``, shape (nv,) or (N, nv), in [N m] / [N].

        Args:
            q: Configuration, shape (nq,) or (N, nq), in [rad] / [m] (a floating base: position
                in [m], then its unit quaternion).
        """
        result = self._gravity(q, self.threads)
        if result.__class__ is _ndarray:
            return result
        return self._checked("gravity", self._gravity, result, q=q)

    def forward_dynamics(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """Joint accelerations ``a = M(q)⁻¹ (tau − C(q, v) v − G(q))`` (LDLᵀ of ``M`` in C).

        Args:
            q: Configuration, shape (nq,) or (N, nq).
            v: Velocity, shape (nv,) or (N, nv).
            tau: Torques in [N m] / [N], shape (nv,) or (N, nv).

        Returns:
            Accelerations, shape (nv,) or (N, nv).

        Raises:
            SingularMassMatrixError: If ``M(q)`` is singular (massless moving bodies).
        """
        result = self._fd(q, v, tau, self.threads)
        if result.__class__ is _ndarray:
            return result
        return self._checked("fd", self._fd, result, q=q, v=v, tau=tau)

    # ---- derivatives (issue 25): kernels of their own, generated and built on first use ----
    def _derivatives(self) -> ModuleType:
        """The derivative module (:mod:`robodyn.compiled.derivatives`), built on first use
        and kept in the instance's ``__dict__``, its two functions as attributes (so a call
        reads one attribute: no look-up of the module or in it)."""
        module = self.__dict__.get("_derivative_module")
        if module is None:
            fixed_base_only(self.robot, "derivatives")
            from robodyn.compiled import derivatives  # the generator: only when first asked for

            module = derivatives.derivative_module(self.robot, kernels=lambda: robot_kernels(self.robot))
            self.__dict__["_derivative_module"] = module
            self._tau_derivatives, self._fd_derivatives = module.tau_derivatives, module.fd_derivatives
        return module

    def inverse_dynamics_derivatives(
        self, q: np.ndarray, v: np.ndarray, a: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``∂τ/∂q``, ``∂τ/∂v`` and ``∂τ/∂a = M`` of the inverse dynamics (generated C).

        The first call on a robot generates and builds its derivative kernels (seconds; then
        cached like the robot's kernels).

        Args:
            q: Configuration, shape (nq,) or (N, nq), in [rad] / [m].
            v: Velocity, shape (nv,) or (N, nv).
            a: Acceleration, shape (nv,) or (N, nv).

        Returns:
            ``(dtau_dq, dtau_dv, M)``, each (nv, nv) or (N, nv, nv); entry ``[i, j]`` is
            ``∂τ_i/∂x_j`` (in [N m/rad], [N m s/rad], [kg m²], or per [m] for prismatic joints).
        """
        function = self._tau_derivatives or self._derivatives().tau_derivatives
        result = function(q, v, a, self.threads)
        if result.__class__ is tuple:
            return result
        return _derivatives_checked(function, self.robot, self.threads, "tau", q=q, v=v, a=a)

    def forward_dynamics_derivatives(
        self, q: np.ndarray, v: np.ndarray, tau: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``∂q̈/∂q``, ``∂q̈/∂v`` and ``∂q̈/∂τ = M⁻¹`` of the forward dynamics (generated C).

        ``∂q̈/∂x = −M⁻¹ ∂τ/∂x`` at ``a = q̈``, with one LDLᵀ of ``M``. The first call on a
        robot builds its derivative kernels (see :meth:`inverse_dynamics_derivatives`).

        Args:
            q: Configuration, shape (nq,) or (N, nq).
            v: Velocity, shape (nv,) or (N, nv).
            tau: Torques in [N m] / [N], shape (nv,) or (N, nv).

        Returns:
            ``(dqdd_dq, dqdd_dv, Minv)``, each (nv, nv) or (N, nv, nv).

        Raises:
            SingularMassMatrixError: If ``M(q)`` is singular (massless moving bodies).
        """
        function = self._fd_derivatives or self._derivatives().fd_derivatives
        result = function(q, v, tau, self.threads)
        if result.__class__ is tuple:
            return result
        return _derivatives_checked(function, self.robot, self.threads, "fd", q=q, v=v, tau=tau)


def _derivatives_checked(function, robot: Robot, threads: int, kind: str, **named: np.ndarray):
    """:func:`robodyn.compiled.derivatives.checked` (its module imported only on this path)."""
    from robodyn.compiled import derivatives

    return derivatives.checked(function, robot, threads, kind, **named)


__all__ = ["SNAP", "CompiledRobot", "compile", "coordinate_parents", "generate_kernels", "robot_kernels", "robot_key"]
