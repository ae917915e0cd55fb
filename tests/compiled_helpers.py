"""Shared by the compiled-engine tests: the comparison with Pinocchio, and compiled robots."""

from __future__ import annotations

import atexit
import os
import shutil
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager

import numpy as np

import robodyn
from robodyn.compiled import compile

#: The issue's bar: compiled results within 1e-12 of Pinocchio's, relative to their size.
RTOL = 1e-12
QUANTITIES = ("inverse_dynamics", "mass_matrix", "nonlinear_effects", "gravity", "forward_dynamics")


def relative_error(ours: np.ndarray, theirs: np.ndarray) -> float:
    """``max |ours − theirs| / max |theirs|`` (the scale of the whole result)."""
    ours, theirs = np.asarray(ours, float), np.asarray(theirs, float)
    assert ours.shape == theirs.shape, (ours.shape, theirs.shape)
    scale = max(float(np.abs(theirs).max(initial=0.0)), np.finfo(float).tiny)
    return float(np.abs(ours - theirs).max(initial=0.0)) / scale


def arguments(robot, rng: np.random.Generator, count: int | None = None) -> dict[str, tuple]:
    """Random states for each quantity (within limits; torques that make the accelerations)."""
    shape = (robot.nv,) if count is None else (count, robot.nv)
    q = robot.random_configuration(rng, count)
    v, a = rng.normal(size=shape), rng.normal(size=shape)
    tau = robot.inverse_dynamics(q, v, a)
    return {
        "inverse_dynamics": (q, v, a),
        "mass_matrix": (q,),
        "nonlinear_effects": (q, v),
        "gravity": (q,),
        "forward_dynamics": (q, v, tau),
    }


def compare(compiled, robot, rng: np.random.Generator, count: int | None = None, rtol: float = RTOL) -> dict[str, float]:
    """Every compiled quantity against the Robot's on the same random states.

    Returns:
        The relative error of each quantity.

    Raises:
        AssertionError: Naming the quantities beyond ``rtol`` (for forward dynamics,
            beyond ``max(rtol, 64 eps cond(M))``).
    """
    errors, tolerances = {}, {}
    states = arguments(robot, rng, count)
    for name, args in states.items():
        errors[name] = relative_error(getattr(compiled, name)(*args), getattr(robot, name)(*args))
        tolerances[name] = rtol
    # Forward dynamics solves with M: both engines are accurate to ~cond(M) eps only (kinova,
    # cond 1.4e4: Pinocchio's ABA is 7e-12 from the true accelerations, the compiled LDLᵀ
    # 7e-13), so their difference is allowed to grow with the conditioning.
    masses = np.reshape(robot.mass_matrix(states["mass_matrix"][0]), (-1, robot.nv, robot.nv))
    condition = max(float(np.linalg.cond(mass)) for mass in masses)
    tolerances["forward_dynamics"] = max(rtol, 64 * np.finfo(float).eps * condition)
    bad = {name: error for name, error in errors.items() if not error <= tolerances[name]}
    assert not bad, f"{robot.name}: compiled differs from Pinocchio: {bad}"
    return errors


def compiled_pair(source, **load_options):
    """``(robot, compiled)`` for a source."""
    robot = robodyn.load(source, **load_options)
    return robot, compile(robot, threads=2)


#: The environment variable naming the session's compile cache: set by tests/conftest.py in
#: the process that starts the session, so every pytest-xdist worker it starts compiles a
#: robot into the same folder once (the cache's writes are atomic and its builds locked).
SESSION_CACHE = "ROBODYN_TEST_SESSION_CACHE"


def _session_cache() -> str:
    """The session's folder, or one of this process's own (removed at exit) outside a session."""
    folder = os.environ.get(SESSION_CACHE)
    if folder:
        return folder
    folder = tempfile.mkdtemp(prefix="robodyn-test-cache-")
    atexit.register(shutil.rmtree, folder, True)
    return folder


#: One compile cache for every compiled-engine test of a session, shared by its workers
#: (never the user's cache).
_SHARED_CACHE = _session_cache()


@contextmanager
def shared_cache() -> Iterator[str]:
    """Point ``ROBODYN_CACHE`` at the session's test cache while the block runs."""
    previous = os.environ.get("ROBODYN_CACHE")
    os.environ["ROBODYN_CACHE"] = _SHARED_CACHE
    try:
        yield _SHARED_CACHE
    finally:
        if previous is None:
            os.environ.pop("ROBODYN_CACHE", None)
        else:
            os.environ["ROBODYN_CACHE"] = previous
