"""robodyn: rigid-body robot dynamics from any URDF, through Pinocchio, verified.

Load a robot with :func:`load` and ask for its equations of motion
``tau = M(q) a + C(q, v) v + G(q)``::

    import robodyn
    robot = robodyn.load("rp_arm")          # or "panda", a URDF path, URDF text
    tau = robot.inverse_dynamics(q, v, a)
    M = robot.mass_matrix(q)

Names that need Pinocchio are imported on first use, so that the independent reference
(:mod:`robodyn.reference`) can run in a process without Pinocchio.
"""

from __future__ import annotations

import importlib
from typing import Any

from robodyn.exceptions import (
    AmbiguousEndEffectorError,
    CompileError,
    CompilerNotFoundError,
    ControllerFailedError,
    DerivationTooExpensiveError,
    FrameError,
    IdentificationError,
    InputError,
    JointLimitWarning,
    MissingExtraError,
    MissingToolError,
    OutputError,
    RobodynError,
    RobodynWarning,
    SimulationError,
    SingularMassMatrixError,
    StaticFrameError,
    TrajectoryError,
    UnknownRobotError,
    URDFError,
)
from robodyn.urdf.models import RPArmParameters, rp_arm_urdf
from robodyn.urdf.sources import robot_names

# Registers the compiled kernels as the engine of robots loaded with engine="auto" when they
# are built already (robodyn.dynamics.engines; no sympy, no Pinocchio, never a build).
importlib.import_module("robodyn.compiled.engine")

__version__ = "0.1.0"

# Public name -> module that defines it (imported lazily: these modules import Pinocchio).
_LAZY = {
    "load": "robodyn.dynamics.loading",
    "Robot": "robodyn.dynamics.robot",
    "JointInfo": "robodyn.dynamics.joints",
    "simulate": "robodyn.sim.simulation",
    "Trajectory": "robodyn.trajectory",
    "ExternalWrench": "robodyn.sim.simulation",
    "estimate_external_torques": "robodyn.sim.observer",
    "attach_payload": "robodyn.dynamics.payload",
    "record": "robodyn.viz.viewer",
    "check_robot": "robodyn.verify.check",
    "derive_equations": "robodyn.equations.derive",
    "compile": "robodyn.compiled.robot",
    "CompiledRobot": "robodyn.compiled.robot",
    "recording": "robodyn.viz.recording",
    "base_parameters": "robodyn.ident",
    "excite": "robodyn.ident",
    "identify": "robodyn.ident",
    "Recording": "robodyn.viz.recording",
    "linearize": "robodyn.sim.linearize",
    "casadi_functions": "robodyn.export",
    "jax_functions": "robodyn.export",
    "point_to_point": "robodyn.optimize",
}

__all__ = [
    "AmbiguousEndEffectorError",
    "CompileError",
    "CompiledRobot",
    "CompilerNotFoundError",
    "ControllerFailedError",
    "DerivationTooExpensiveError",
    "ExternalWrench",
    "FrameError",
    "IdentificationError",
    "InputError",
    "JointInfo",
    "JointLimitWarning",
    "MissingExtraError",
    "MissingToolError",
    "OutputError",
    "RPArmParameters",
    "Recording",
    "RobodynError",
    "RobodynWarning",
    "Robot",
    "SimulationError",
    "SingularMassMatrixError",
    "StaticFrameError",
    "Trajectory",
    "TrajectoryError",
    "URDFError",
    "UnknownRobotError",
    "__version__",
    "attach_payload",
    "base_parameters",
    "casadi_functions",
    "check_robot",
    "compile",
    "derive_equations",
    "estimate_external_torques",
    "excite",
    "identify",
    "jax_functions",
    "linearize",
    "load",
    "point_to_point",
    "record",
    "recording",
    "robot_names",
    "rp_arm_urdf",
    "simulate",
]


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'robodyn' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
