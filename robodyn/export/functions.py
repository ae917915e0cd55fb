"""``casadi_functions``, ``jax_functions`` and ``module_source``: a robot's dynamics for optimisers.

Each derives the robot's programs (:mod:`robodyn.export.programs`, once per robot: the
compiled engine's derivation), prints them as the standalone module
(:mod:`robodyn.export.source`, once per robot and options, kept in the compiled cache) and,
for the functions, runs that module's ``functions()`` (once per process): the library's
functions and a written module are the same code.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from robodyn.common.extras import require
from robodyn.compiled.programs import derived
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError
from robodyn.export.programs import export_programs
from robodyn.export.source import Backend, module_text

#: The dynamics every export has (frames add ``frame_position:<frame>`` and ``frame_jacobian:<frame>``).
FUNCTIONS = ("inverse_dynamics", "mass_matrix", "nonlinear_effects", "gravity", "forward_dynamics")


def module_source(
    robot: Robot,
    backend: Backend,
    *,
    frames: Sequence[str] | None = None,
    keep_params: bool = False,
    progress: Callable[[str, int, int], None] | None = None,
) -> str:
    """A standalone Python module (imports only ``casadi``, or only ``jax``) whose
    ``functions()`` returns what :func:`casadi_functions` / :func:`jax_functions` return.

    Args:
        robot: From :func:`robodyn.load` (fixed base).
        backend: ``"casadi"`` or ``"jax"``.
        frames: Frames to export (``None``: every frame of :attr:`robodyn.Robot.frame_names`).
        keep_params: Masses, centres of mass, inertias, joint offsets and gravity as a last
            input ``p`` (``PARAMETER_NAMES``, ``PARAMETER_VALUES`` in the module).
        progress: Called as ``progress(stage, done, total)`` during the derivation.

    Raises:
        InputError: For an unknown backend, a floating base or a robot without moving joints.
        FrameError: For a frame the robot does not have.
    """
    if backend not in ("casadi", "jax"):
        raise InputError("backend", "casadi or jax", repr(backend))
    names = None if frames is None else [str(frame) for frame in frames]

    def text() -> str:
        return module_text(export_programs(robot, frames=names, keep_params=keep_params, progress=progress), backend)

    # Printed once per robot, backend, frames and keep_params (robodyn.compiled.programs: kept
    # in memory and in the compiled cache under the robot's key, like the programs).
    return derived(robot, f"export text {backend} keep_params={keep_params} frames={names!r}", text)


#: The functions this process built, by the module text they ran (CasADi functions are immutable).
_BUILT: dict[str, dict[str, Any]] = {}


def _run(source: str) -> dict[str, Any]:
    """The module's ``functions()`` (the text is generated: names only as ``ascii()`` literals),
    built once per text in a process (a new dictionary of the same functions each call)."""
    built = _BUILT.get(source)
    if built is None:
        namespace: dict[str, Any] = {"__name__": "robodyn_export"}
        exec(compile(source, "<robodyn export>", "exec"), namespace)
        built = _BUILT[source] = namespace["functions"]()
    return dict(built)


def casadi_functions(robot: Robot, *, frames: Sequence[str] | None = None, keep_params: bool = False) -> dict[str, Any]:
    """The robot's dynamics and kinematics as ``casadi.Function`` (SX graphs of robodyn's
    compact equations), by name.

    ``"inverse_dynamics"(q, v, a) -> tau``, ``"mass_matrix"(q) -> M``,
    ``"nonlinear_effects"(q, v) -> C v + G``, ``"gravity"(q) -> G``,
    ``"forward_dynamics"(q, v, tau) -> a`` (the compiled engine's tree-structured LDLᵀ of
    ``M``, no dense inverse), and per frame ``"frame_position:<frame>"(q) -> (3, 1)`` in [m]
    and ``"frame_jacobian:<frame>"(q) -> (6, nv)`` (linear rows then angular, world-aligned,
    as :meth:`robodyn.Robot.frame_jacobian`). ``q``, ``v``, ``a``, ``tau`` are (nv, 1) in the
    order of :attr:`robodyn.Robot.joint_names`, SI units; mimic joints, locked joints and
    gravity as the robot was loaded.

    Args:
        robot: From :func:`robodyn.load` (fixed base).
        frames: Frames to export (``None``: every frame of :attr:`robodyn.Robot.frame_names`).
        keep_params: Every function takes a last input ``p``: the kept masses, centres of
            mass, inertias, joint offsets and gravity (:func:`parameters` gives their names
            and values).

    Raises:
        MissingExtraError: Without casadi (``robodyn[optimize]``).
        InputError: For a floating base or a robot without moving joints.
        FrameError: For a frame the robot does not have.
    """
    require("casadi", extra="optimize", purpose="CasADi functions")
    return _run(module_source(robot, "casadi", frames=frames, keep_params=keep_params))


def jax_functions(robot: Robot, *, frames: Sequence[str] | None = None, keep_params: bool = False) -> dict[str, Callable]:
    """The same functions as :func:`casadi_functions`, as pure ``jax.numpy`` functions of one
    state (1-D arrays; ``jax.vmap`` for batches; ``jax.jit`` and ``jax.grad`` work), in float64.

    JAX computes in float32 unless ``jax.config.update("jax_enable_x64", True)`` was called:
    robodyn does not change that global setting for you, and refuses without it.

    Raises:
        MissingExtraError: Without jax (``robodyn[jax]``).
        InputError: Without float64 in JAX, for a floating base or a robot without moving joints.
        FrameError: For a frame the robot does not have.
    """
    jax = require("jax", extra="jax", purpose="JAX functions")
    if not jax.config.jax_enable_x64:
        raise InputError("jax_enable_x64", "True for float64 (jax.config.update('jax_enable_x64', True))", "False")
    return _run(module_source(robot, "jax", frames=frames, keep_params=keep_params))
