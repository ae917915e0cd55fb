"""Compiled dynamics: a robot's equations (fixed or floating base) as generated C, built and cached.

- :func:`compile` gives a :class:`CompiledRobot` with the :class:`robodyn.Robot` methods
  ``inverse_dynamics``, ``mass_matrix``, ``nonlinear_effects``, ``gravity``,
  ``coriolis_matrix`` and ``forward_dynamics`` (same shapes, checks and errors; the protocol
  :class:`robodyn.dynamics.protocol.Dynamics`), batches on native threads.
- :func:`simulate_compiled` integrates in C (RK4 or semi-implicit Euler), passive or under a
  compiled joint-space controller (:class:`CompiledPDGravity`, :class:`CompiledComputedTorque`),
  or a Python controller sampled every control period (zero-order hold);
  :func:`compiled_controller` turns ``TaskSpace``, ``OperationalSpace``, ``Impedance``, PD and
  computed torque into their C twins (:mod:`robodyn.compiled.controllers`), run at every stage.
- ``CompiledRobot.frame_position`` / ``frame_rotation`` / ``frame_jacobian`` /
  ``frame_bias_acceleration``: a frame's kinematics as generated C (:mod:`robodyn.compiled.kinematics`).
- :func:`robodyn.compiled.build.lookup` / :func:`~robodyn.compiled.build.is_compiled`: whether a
  robot's module is cached, without sympy or the code generator.

The names are imported on first use (this package's ``__init__`` imports no sympy), so
``robodyn.compiled.build`` and ``robodyn.compiled.cache`` load without the code generator.
See docs/compiled.md for the cache folder (``$ROBODYN_CACHE``) and the numbers.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from robodyn.compiled.cache import cache_dir
    from robodyn.compiled.robot import CompiledRobot, compile
    from robodyn.compiled.simulation import (
        CompiledComputedTorque,
        CompiledPDGravity,
        compiled_controller,
        has_twin,
        simulate_compiled,
    )

_WHERE = {
    "CompiledComputedTorque": "simulation",
    "CompiledPDGravity": "simulation",
    "CompiledRobot": "robot",
    "cache_dir": "cache",
    "compile": "robot",
    "compiled_controller": "simulation",
    "has_twin": "simulation",
    "simulate_compiled": "simulation",
}

__all__ = [
    "CompiledComputedTorque",
    "CompiledPDGravity",
    "CompiledRobot",
    "cache_dir",
    "compile",
    "compiled_controller",
    "has_twin",
    "simulate_compiled",
]


def __getattr__(name: str) -> Any:
    """A public name, imported from its module on first use (then kept in this package)."""
    if name not in _WHERE:
        raise AttributeError(f"module 'robodyn.compiled' has no attribute {name!r}")
    value = getattr(importlib.import_module(f"robodyn.compiled.{_WHERE[name]}"), name)
    globals()[name] = value
    return value
