"""Which engine answers a robot's single calls: Pinocchio, or its compiled kernels when they are built.

The dynamics layer sits below the compiled engine and never imports it. The compiled engine
registers a *finder* here instead (:func:`register`, done by :mod:`robodyn.compiled.engine`
when it is imported: ``robodyn.load`` imports it): a function of a robot that returns the
robot's compiled kernels' module when it is already built (in this process or in the cache
folder), else ``None``, and never builds anything. :func:`attach` asks the finders for a
robot loaded with ``engine="auto"`` (the default of :func:`robodyn.load`, unless
``$ROBODYN_ENGINE`` says ``pinocchio``); ``engine="pinocchio"`` never asks.

An attached module answers ``tau``, ``M``, ``G``, ``C v + G`` and the forward dynamics
(:func:`compiled_calls`): a call whose arguments are float64 C-contiguous arrays of the
right shape, finite (and a floating base's quaternion unit) goes to C, one state or a
batch (on the robot's ``threads``); other arguments (lists, other dtypes, strided arrays)
go through the robot's input boundary and then to C, so the numbers do not depend on the
arguments' type. What the boundary refuses, and any result the C code does not return (a
non-finite result, a singular mass matrix), goes to the Pinocchio call the kernels
replaced, which checks, names the argument and raises the same errors as before.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from types import ModuleType
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from robodyn.exceptions import InputError

if TYPE_CHECKING:
    from robodyn.dynamics.robot import Robot

#: The values of ``load(..., engine=)``: ``"auto"`` uses the compiled kernels when they
#: are built already (never builds them), ``"pinocchio"`` always Pinocchio.
ENGINES = ("auto", "pinocchio")

Finder = Callable[["Robot"], ModuleType | None]
_finders: list[Finder] = []


#: The environment variable that sets the default of ``engine=`` (``"auto"`` when unset).
ENVIRONMENT = "ROBODYN_ENGINE"


def check_engine(engine: object) -> str:
    """The ``engine=`` option of :func:`robodyn.load`, checked; ``None``: ``$ROBODYN_ENGINE``,
    else ``"auto"``.

    Raises:
        InputError: If it is not one of :data:`ENGINES` (naming ``$ROBODYN_ENGINE`` if it came from there).
    """
    if engine is None:
        engine = os.environ.get(ENVIRONMENT, "").strip() or "auto"
        if engine not in ENGINES:
            raise InputError(ENVIRONMENT, " or ".join(repr(name) for name in ENGINES), repr(engine))
    if engine not in ENGINES:
        raise InputError("engine", " or ".join(repr(name) for name in ENGINES), repr(engine))
    return str(engine)


def register(finder: Finder) -> None:
    """Add a finder of compiled kernels (see the module docstring); registering twice is a no-op.

    Args:
        finder: ``finder(robot) -> module or None``: the robot's built kernels, never building them.
    """
    if finder not in _finders:
        _finders.append(finder)


def find(robot: Robot) -> ModuleType | None:
    """The robot's compiled kernels from the first finder that has them, or ``None``.

    Args:
        robot: The robot whose kernels are looked for.
    """
    for finder in _finders:
        module = finder(robot)
        if module is not None:
            return module
    return None


def attach(robot: Robot) -> bool:
    """Route the single calls of a robot loaded with ``engine="auto"`` through its compiled
    kernels, if a finder has them built. Returns whether it did.

    Args:
        robot: A robot just built (its ``options.engine`` says whether it may be routed).
    """
    if robot.options.engine != "auto":
        return False
    module = find(robot)
    if module is None:
        return False
    robot.handle.accelerate(module)
    return True


class Calls(NamedTuple):
    """The one-state calls (the fields of :class:`robodyn.dynamics.handle.SingleCalls`)."""

    tau: Callable[..., np.ndarray]
    a: Callable[..., np.ndarray]
    M: Callable[..., np.ndarray]
    G: Callable[..., np.ndarray]
    nle: Callable[..., np.ndarray]


def compiled_calls(module: ModuleType, pinocchio: Any, kernels: Any, validate: Callable[..., Any], threads: int) -> Calls:
    """The single calls of a compiled module, each falling back to Pinocchio's.

    Args:
        module: The robot's compiled kernels (``tau``, ``mass``, ``gravity``, ``nle``, ``fd``
            of ``(*states, threads)``: an array, or ``None`` / a status for what they refuse).
        pinocchio: The Pinocchio single calls they replace (same fields as :class:`Calls`).
        kernels: The robot's :class:`~robodyn.dynamics.kernels.DynamicsKernels` (the
            arguments' names).
        validate: The robot's input boundary (:meth:`robodyn.dynamics.handle.ModelHandle.validate`).
        threads: Native threads for batches.
    """

    def wrap(compiled: Callable[..., Any], fallback: Callable[..., np.ndarray], names: tuple[str, ...]) -> Any:
        return _WRAPPERS[len(names)](compiled, _Converted(compiled, fallback, names, validate, threads), threads)

    return Calls(
        tau=wrap(module.tau, pinocchio.tau, kernels.tau.names),
        a=wrap(module.fd, pinocchio.a, kernels.a.names),
        M=wrap(module.mass, pinocchio.M, kernels.M.names),
        G=wrap(module.gravity, pinocchio.G, kernels.G.names),
        nle=wrap(module.nle, pinocchio.nle, kernels.nle.names),
    )


_ndarray = np.ndarray


class _Converted:
    """The path of arguments the kernels do not take as they are (lists, other dtypes,
    strided arrays, NaN, wrong shapes): the robot's boundary checks and converts them and
    the kernels run on the result, so the numbers do not depend on the arguments' type;
    what the boundary refuses, and what the kernels refuse after it (a non-finite result,
    a singular mass matrix), goes to the Pinocchio call, which raises as before."""

    def __init__(self, compiled: Callable[..., Any], fallback: Callable[..., np.ndarray], names, validate, threads: int):
        self.compiled, self.fallback, self.names, self.validate, self.threads = compiled, fallback, names, validate, threads

    def __call__(self, *values: Any) -> np.ndarray:
        try:
            arrays, _ = self.validate(**dict(zip(self.names, values, strict=True)))
        except InputError:
            return self.fallback(*values)
        result = self.compiled(*[np.ascontiguousarray(array, dtype=np.float64) for array in arrays], self.threads)
        return result if result.__class__ is _ndarray else self.fallback(*values)


def _one(compiled: Callable[..., Any], slow: Callable[..., np.ndarray], threads: int) -> Callable[..., np.ndarray]:
    def of_q(q: np.ndarray) -> np.ndarray:
        result = compiled(q, threads)
        return result if result.__class__ is _ndarray else slow(q)

    return of_q


def _two(compiled: Callable[..., Any], slow: Callable[..., np.ndarray], threads: int) -> Callable[..., np.ndarray]:
    def of_q_v(q: np.ndarray, v: np.ndarray) -> np.ndarray:
        result = compiled(q, v, threads)
        return result if result.__class__ is _ndarray else slow(q, v)

    return of_q_v


def _three(compiled: Callable[..., Any], slow: Callable[..., np.ndarray], threads: int) -> Callable[..., np.ndarray]:
    def of_q_v_x(q: np.ndarray, v: np.ndarray, x: np.ndarray) -> np.ndarray:
        result = compiled(q, v, x, threads)
        return result if result.__class__ is _ndarray else slow(q, v, x)

    return of_q_v_x


_WRAPPERS = {1: _one, 2: _two, 3: _three}


__all__ = ["ENGINES", "ENVIRONMENT", "Calls", "attach", "check_engine", "compiled_calls", "find", "register"]
