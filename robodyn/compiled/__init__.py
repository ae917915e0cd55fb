"""Compiled dynamics: a robot's equations (fixed or floating base) as generated C, built and cached.

- :func:`compile` gives a :class:`CompiledRobot` with the :class:`robodyn.Robot` methods
  ``inverse_dynamics``, ``mass_matrix``, ``nonlinear_effects``, ``gravity`` and
  ``forward_dynamics`` (same shapes, checks and errors), batches on native threads.
- :func:`simulate_compiled` integrates in C (RK4 or semi-implicit Euler), passive or under a
  controller's compiled twin (:mod:`robodyn.compiled.controllers`: PD, computed torque, task
  space, operational space, impedance, LQR), or a Python controller sampled every control
  period (zero-order hold); :func:`compiled_controller` asks a controller for its twin.
- ``CompiledRobot.frame_position`` / ``frame_rotation`` / ``frame_jacobian`` /
  ``frame_bias_acceleration``: a frame's kinematics as generated C (:mod:`robodyn.compiled.kinematics`).

The names load on first use: importing this package (or its loop rules, controllers'
layouts and C loop wrapper) does not load the code generator (sympy); :func:`compile` does.
See docs/compiled.md for the cache folder (``$ROBODYN_CACHE``) and the numbers.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from robodyn.compiled.build import cache_dir
    from robodyn.compiled.robot import CompiledRobot, compile
    from robodyn.compiled.simulation import (
        CompiledComputedTorque,
        CompiledPDGravity,
        compiled_controller,
        has_twin,
        simulate_compiled,
    )

_LAZY = {
    "cache_dir": "robodyn.compiled.build",
    "CompiledRobot": "robodyn.compiled.robot",
    "compile": "robodyn.compiled.robot",
    "CompiledComputedTorque": "robodyn.compiled.controllers",
    "CompiledPDGravity": "robodyn.compiled.controllers",
    "compiled_controller": "robodyn.compiled.simulation",
    "has_twin": "robodyn.compiled.simulation",
    "simulate_compiled": "robodyn.compiled.simulation",
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
    if name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'robodyn.compiled' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
