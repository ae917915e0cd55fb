"""What every computation on a Pinocchio model shares: the model, per-thread data, and the input boundary.

A :class:`ModelHandle` is what the functions of :mod:`robodyn.dynamics.kinematics`,
:mod:`robodyn.dynamics.configurations` and :mod:`robodyn.dynamics.regressor` take, Pinocchio
style (``frame_position(handle, q, frame)``); a :class:`robodyn.Robot` holds one
(:attr:`robodyn.Robot.handle`) and delegates to them. The handle owns the one rule by which
robodyn accepts numbers (:meth:`ModelHandle.validate`) and the fast path that tries
Pinocchio directly first (:meth:`ModelHandle.evaluate`).

Thread safety: Pinocchio's ``Data`` is scratch memory that every algorithm overwrites. A
handle keeps one ``Data`` per thread (:attr:`ModelHandle.data`), so one robot may be used
from several threads at once; the model itself is only read.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from types import ModuleType
from typing import Any, NamedTuple

import numpy as np
import pinocchio as pin

from robodyn.common.inputs import as_states
from robodyn.dynamics.batch import ParallelRunner, PerThreadData
from robodyn.dynamics.engines import compiled_calls
from robodyn.dynamics.kernels import Kernel, dynamics_kernels
from robodyn.dynamics.mimic import MimicExpansion
from robodyn.exceptions import InputError, NonFiniteResultError

#: Largest accepted deviation of a floating base's quaternion norm from 1.
QUATERNION_TOLERANCE = 1e-6
#: What Pinocchio raises for arguments it refuses (wrong size, type, unsupported joint).
PINOCCHIO_ERRORS = (TypeError, ValueError, RuntimeError, AttributeError)
_isfinite = math.isfinite


class ModelHandle:
    """A Pinocchio model with per-thread data, its dynamics kernels and robodyn's input checks.

    Args:
        model: The Pinocchio model.
        name: Robot name, for messages.
        floating_base: Whether the root is a free-flyer joint.
        mimic: For a model with mimic joints, its expansion (:mod:`robodyn.dynamics.mimic`).
        threads: Native threads for batches (``None``: every available core).

    Attributes:
        model: The Pinocchio model (read only).
        name: Robot name, for messages.
        nq, nv: Sizes of a configuration and of a velocity.
        floating_base: Whether the root is a free-flyer joint (``q[3:7]`` a quaternion).
        mimic: The expansion of a model with mimic joints, or ``None``.
        frames: Pinocchio index of every frame, by name.
        parallel: Runs Pinocchio's parallel algorithms on batches.
        kernels: The equations of motion as Pinocchio calls (:mod:`robodyn.dynamics.kernels`).
        calls: The single calls :class:`robodyn.Robot` makes (:class:`SingleCalls`):
            Pinocchio's, or the compiled kernels' (:meth:`accelerate`).
    """

    def __init__(
        self,
        model: pin.Model,
        *,
        name: str,
        floating_base: bool,
        mimic: MimicExpansion | None = None,
        threads: int | None = None,
    ) -> None:
        self.model = model
        self.name = name
        self.floating_base = floating_base
        self.mimic = mimic
        self.nq: int = model.nq
        self.nv: int = model.nv
        self.frames: dict[str, int] = {frame.name: index for index, frame in enumerate(model.frames)}
        self._data = PerThreadData(model)
        self.parallel = ParallelRunner(model, threads=threads)
        self.kernels = dynamics_kernels(model, self._data.get, self.parallel.run, mimic, name=name)
        kernels = self.kernels
        self.calls = SingleCalls(
            tau=self.single_call(kernels.tau, pin.rnea),
            a=self.single_call(kernels.a, pin.aba),
            M=self.single_call(kernels.M, pin.crba, symmetric=True),
            G=self.single_call(kernels.G, pin.computeGeneralizedGravity),
            nle=self.single_call(kernels.nle, pin.nonLinearEffects),
        )
        #: Pinocchio's single calls (what :attr:`calls` are until :meth:`accelerate`).
        self.pinocchio_calls = self.calls
        #: The engine of :attr:`calls`: ``"pinocchio"``, or ``"compiled"`` after :meth:`accelerate`.
        self.engine = "pinocchio"

    def accelerate(self, module: ModuleType) -> None:
        """Answer the single calls (and their batches) with a robot's compiled kernels,
        falling back to Pinocchio's calls for anything the kernels refuse (so errors stay
        the same): see :mod:`robodyn.dynamics.engines`. The model is then read-only (the
        kernels are built from the robot's URDF text and load options, not from it).

        Args:
            module: The robot's compiled extension module (:mod:`robodyn.compiled.engine`).
        """
        self.calls = SingleCalls(
            *compiled_calls(module, self.pinocchio_calls, self.kernels, self.validate, self.parallel.threads)
        )
        self.engine = "compiled"

    @property
    def data(self) -> pin.Data:
        """This thread's Pinocchio data for :attr:`model` (created on first use)."""
        return self._data.get()

    # ----------------------------------------------------------------------------------
    # The input boundary
    # ----------------------------------------------------------------------------------
    def validate(self, **named: object) -> tuple[list[np.ndarray], bool]:
        """Check state arguments by name (``q`` has nq entries, the others nv).

        Returns:
            The arguments as float64 arrays, and whether they are a batch (2-D).

        Raises:
            InputError: Naming the argument: wrong type, shape or size, NaN or inf, a
                complex value, or a floating base's quaternion that is not unit.
        """
        arrays, batch = as_states({name: (value, self.nq if name == "q" else self.nv) for name, value in named.items()})
        if self.floating_base and "q" in named:
            norms = np.atleast_1d(np.linalg.norm(arrays[0][..., 3:7], axis=-1))
            worst = int(np.argmax(np.abs(norms - 1.0))) if norms.size else 0
            if norms.size and abs(norms[worst] - 1.0) >= QUATERNION_TOLERANCE:
                raise InputError("q[3:7]", "a unit quaternion (x, y, z, w) for the floating base", f"norm {norms[worst]:.9g}")
        return arrays, batch

    def accept(self, result: np.ndarray, q: np.ndarray) -> bool:
        """Whether a fast-path result can be returned as it is.

        A NaN or inf anywhere in the inputs makes a result non-finite (detected by one dot
        product; ``q`` is checked too since some algorithms do not propagate it), and a
        floating base needs a unit quaternion. Anything else is re-done through
        :meth:`validate`, which names the offending argument.

        Args:
            result: The fast path's result.
            q: The configuration it was computed at, as given.
        """
        if not (_all_finite(result) and _all_finite(q)):
            return False
        if self.floating_base:
            quaternion = q[3:7]
            return abs(quaternion.dot(quaternion) - 1.0) < QUATERNION_TOLERANCE
        return True

    def finite(self, result: np.ndarray, what: str) -> np.ndarray:
        """Refuse a non-finite result of finite inputs (an overflow), never return it.

        Args:
            result: The result.
            what: The quantity's name, for the error.
        """
        if not np.isfinite(result).all():
            raise NonFiniteResultError(self.name, what)
        return result

    def single_call(
        self, kernel: Kernel, raw: Callable[..., np.ndarray], *, symmetric: bool = False
    ) -> Callable[..., np.ndarray]:
        """The thinnest checked call of a quantity: :meth:`evaluate` with its fast path fused.

        On a fixed-base robot (with mimic joints: for tau, G and C v + G only),
        ``raw(model, data, *values)`` runs on this
        thread's data (read from a ``threading.local`` without a call: thread-safe) and its
        result is returned when it and ``q`` are finite (one ``isfinite`` of two sums);
        ``M(q)`` and ``G(q)`` of a model that keeps them finite for every finite ``q``
        (:func:`bounded_for_finite_q`) check ``q`` alone. Anything else (other inputs, a first call in a thread, a non-finite value, a floating
        base, mimic joints) goes to :meth:`evaluate`, which checks and names the argument.

        Args:
            kernel: The quantity's kernel (the checked path).
            raw: The Pinocchio function ``raw(model, data, *values)`` of one state.
            symmetric: Whether ``raw`` returns a matrix (CRBA's M: Pinocchio's Python
                binding fills both triangles).
        """
        evaluate, model, local = self.evaluate, self.model, self._data.local
        if self.floating_base or (self.mimic is not None and (symmetric or raw is pin.aba)):
            # a floating base's quaternion needs its own check; with mimic joints, M and the
            # accelerations are not one Pinocchio call (kernels.py)
            return lambda *values: evaluate(kernel, *values)
        if len(kernel.names) == 1 and bounded_for_finite_q(model):
            return _configuration_call(kernel, raw, model, local, evaluate)
        if symmetric:
            return _matrix_call(kernel, raw, model, local, evaluate)
        return _vector_call(kernel, raw, model, local, evaluate)

    def evaluate(self, kernel: Kernel, *values: np.ndarray) -> np.ndarray:
        """Fast path, then checked path, for one quantity (a :class:`~robodyn.dynamics.kernels.Kernel`).

        Its one-state function runs on the raw arguments if Pinocchio takes them and the
        result passes :meth:`accept`; else the arguments (named ``kernel.names``, for
        messages) go through :meth:`validate` and one state goes to the one-state function,
        a batch to the batch function (or to the one-state function row by row when there
        is none).

        Args:
            kernel: The quantity's kernel (its one-state and batch functions, its arguments' names).

        Raises:
            InputError: For arguments :meth:`validate` refuses.
            NonFiniteResultError: For a non-finite result of finite inputs (an overflow).
        """
        what, names, single, batch = kernel
        try:
            # one state only (Pinocchio takes a (1, 1) array for a vector of one: a batch of
            # one state of a one-joint robot would come back as one state's result)
            if any(value.ndim != 1 for value in values):
                raise ValueError("a batch")
            result = single(*values)
            q = values[0]
            # accept, written out on the hot path: finite result and q, unit quaternion.
            if (
                (_isfinite(sum(result.tolist())) if result.ndim == 1 else _all_finite(result))
                and _isfinite(sum(q.tolist()))
                and (not self.floating_base or self.accept(result, q))
            ):
                return result
        except PINOCCHIO_ERRORS:
            pass
        arrays, is_batch = self.validate(**dict(zip(names, values, strict=True)))
        if not is_batch:
            return self.finite(single(*arrays), what)
        if batch is not None:
            return self.finite(batch(*arrays), what)
        return self.finite(per_state(single, *arrays), what)


#: Pinocchio's joints whose one coordinate is an angle: their placement is a rotation by it.
_ANGLE_JOINTS = frozenset({"JointModelRX", "JointModelRY", "JointModelRZ", "JointModelRevoluteUnaligned"})
#: Bound on the model's constants under which no product CRBA or RNEA forms can overflow.
_SAFE_CONSTANT = 1e50


def bounded_for_finite_q(model: pin.Model) -> bool:
    """Whether ``M(q)`` and ``G(q)`` are finite for every finite ``q``.

    True when every joint is revolute with one angle coordinate (its rotation's entries,
    cos and sin of the angle, lie in [-1, 1] for any finite angle) and the model's
    constants (masses, centres of mass, inertias, joint placements, armature, gravity) stay
    below 1e50 in magnitude: CRBA and RNEA at zero velocity then form sums of products of
    a few such constants and rotation entries, far from overflow. A prismatic joint (a
    translation by ``q``) or a continuous joint's (cos, sin) pair can overflow for large
    finite ``q``, so their results are checked.

    Args:
        model: The Pinocchio model.
    """
    if any(joint.shortname() not in _ANGLE_JOINTS for joint in list(model.joints)[1:]):
        return False
    constants = [model.gravity.linear, model.armature]
    for inertia, placement in zip(list(model.inertias)[1:], list(model.jointPlacements)[1:], strict=True):
        constants += [np.array([inertia.mass]), inertia.lever, inertia.inertia, placement.translation]
    return all(bool(np.all(np.abs(values) < _SAFE_CONSTANT)) for values in constants)


def _configuration_call(
    kernel: Kernel, raw: Callable[..., np.ndarray], model: pin.Model, local: Any, evaluate: Callable[..., np.ndarray]
) -> Callable[..., np.ndarray]:
    """:meth:`ModelHandle.single_call` of ``M(q)`` or ``G(q)`` on a model whose results are
    finite for every finite ``q`` (:func:`bounded_for_finite_q`): ``q`` alone is checked."""
    isfinite = _isfinite

    def of_q(q: np.ndarray) -> np.ndarray:
        try:
            # One sum checks q: NaN or inf make it non-finite (a finite sum that overflows
            # only sends q to the checked path), and a 2-D q (a batch, which Pinocchio
            # would take as one state if it is a column) gives a list of rows that does
            # not sum (TypeError).
            if isfinite(sum(q.tolist())):
                return raw(model, local.data, q)
        except PINOCCHIO_ERRORS:
            pass
        return evaluate(kernel, q)

    return of_q


def _matrix_call(
    kernel: Kernel, raw: Callable[..., np.ndarray], model: pin.Model, local: Any, evaluate: Callable[..., np.ndarray]
) -> Callable[..., np.ndarray]:
    """:meth:`ModelHandle.single_call` of CRBA on any fixed-base model: ``M`` and ``q``
    checked."""
    isfinite = _isfinite
    # CRBA never uses the placement of a joint attached to the world, and M need not move
    # with other joints either (a chain of prismatic joints: M is constant), so q is
    # checked besides M itself. Pinocchio's Python crba returns M whole (its binding
    # mirrors the upper triangle: tests/dynamics/test_single_call.py), so M is returned
    # as it comes.

    def matrix(q: np.ndarray) -> np.ndarray:
        try:
            if q.ndim != 1:  # a batch (Pinocchio would take a (nq, 1) array as one state)
                return evaluate(kernel, q)
            result = raw(model, local.data, q)
            # sums of Python floats: an overflow gives inf without numpy's warning
            if isfinite(sum(result.ravel().tolist()) + sum(q.tolist())):
                return result
        except PINOCCHIO_ERRORS:
            pass
        return evaluate(kernel, q)

    return matrix


def _vector_call(
    kernel: Kernel, raw: Callable[..., np.ndarray], model: pin.Model, local: Any, evaluate: Callable[..., np.ndarray]
) -> Callable[..., np.ndarray]:
    """:meth:`ModelHandle.single_call` of a vector quantity of 1, 2 or 3 state arguments."""
    isfinite = _isfinite

    # One state's q, v, a (tau) reach every entry of RNEA's and ABA's results (a NaN or
    # inf in any of them makes the result non-finite: tests/dynamics/test_single_call.py), so
    # the result alone is checked; CRBA does not use the root joints' q, so M checks q.
    if len(kernel.names) == 1:

        def vector1(q: np.ndarray) -> np.ndarray:
            try:
                if q.ndim != 1:  # a batch (Pinocchio would take a (1, 1) array as one state)
                    return evaluate(kernel, q)
                result = raw(model, local.data, q)
                if isfinite(sum(result.tolist())):
                    return result
            except PINOCCHIO_ERRORS:
                pass
            return evaluate(kernel, q)

        return vector1
    if len(kernel.names) == 2:

        def vector2(q: np.ndarray, v: np.ndarray) -> np.ndarray:
            try:
                if q.ndim != 1 or v.ndim != 1:  # a batch (Pinocchio would take (1, 1) as one state)
                    return evaluate(kernel, q, v)
                result = raw(model, local.data, q, v)
                if isfinite(sum(result.tolist())):
                    return result
            except PINOCCHIO_ERRORS:
                pass
            return evaluate(kernel, q, v)

        return vector2

    def vector3(q: np.ndarray, v: np.ndarray, third: np.ndarray) -> np.ndarray:
        try:
            if q.ndim != 1 or v.ndim != 1 or third.ndim != 1:  # a batch (see vector2)
                return evaluate(kernel, q, v, third)
            result = raw(model, local.data, q, v, third)
            if isfinite(sum(result.tolist())):
                return result
        except PINOCCHIO_ERRORS:
            pass
        return evaluate(kernel, q, v, third)

    return vector3


class SingleCalls(NamedTuple):
    """The one-state calls of the equations of motion (:meth:`ModelHandle.single_call`):
    ``tau(q, v, a)``, ``a(q, v, tau)``, ``M(q)``, ``G(q)``, ``nle(q, v)``; each also takes
    a batch (through :meth:`ModelHandle.evaluate`)."""

    tau: Callable[..., np.ndarray]
    a: Callable[..., np.ndarray]
    M: Callable[..., np.ndarray]
    G: Callable[..., np.ndarray]
    nle: Callable[..., np.ndarray]


def _all_finite(array: np.ndarray) -> bool:
    """Whether an array holds no NaN or inf, by the cheapest exact test for its size: a NaN
    or inf anywhere makes the sum of its entries non-finite; a finite sum that overflows
    (to inf, without a warning: Python floats) only sends the caller to the exact check."""
    return _isfinite(sum(array.ravel().tolist()))


def per_state(function: Callable[..., np.ndarray], *states: np.ndarray) -> np.ndarray:
    """Apply a one-state function to 1-D states, or to each row of 2-D stacks (stacked).

    Args:
        function: The one-state function, of 1-D arrays.
    """
    if states[0].ndim == 1:
        return function(*states)
    results = [function(*row) for row in zip(*states, strict=True)]
    if results:
        return np.stack(results)
    return np.zeros((0, *np.shape(function(*(np.zeros(s.shape[1]) for s in states)))))
