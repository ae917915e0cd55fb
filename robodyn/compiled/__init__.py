"""Compiled dynamics: a robot's equations (fixed or floating base) as generated C, built and cached.

- :func:`compile` gives a :class:`CompiledRobot` with the :class:`robodyn.Robot` methods
  ``inverse_dynamics``, ``mass_matrix``, ``nonlinear_effects``, ``gravity`` and
  ``forward_dynamics`` (same shapes, checks and errors), batches on native threads.
- :func:`simulate_compiled` integrates in C (RK4 or semi-implicit Euler), passive or under a
  compiled joint-space controller (:class:`CompiledPDGravity`, :class:`CompiledComputedTorque`),
  or a Python controller sampled every control period (zero-order hold);
  :func:`compiled_controller` turns ``TaskSpace``, ``OperationalSpace``, ``Impedance``, PD and
  computed torque into their C twins (:mod:`robodyn.compiled.controllers`), run at every stage.
- ``CompiledRobot.frame_position`` / ``frame_rotation`` / ``frame_jacobian`` /
  ``frame_bias_acceleration``: a frame's kinematics as generated C (:mod:`robodyn.compiled.kinematics`).

See docs/compiled.md for the cache folder (``$ROBODYN_CACHE``) and the numbers.
"""

from __future__ import annotations

from robodyn.compiled.build import cache_dir
from robodyn.compiled.robot import CompiledRobot, compile
from robodyn.compiled.simulation import (
    CompiledComputedTorque,
    CompiledPDGravity,
    compiled_controller,
    has_twin,
    simulate_compiled,
)

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
