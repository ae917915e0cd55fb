"""Exceptions raised by robodyn.

Every error robodyn raises on purpose derives from :class:`RobodynError`, so a caller (and
the CLI) can catch them all at once. Each subclass carries the offending values as
attributes and a one-sentence message naming the thing and the rule it broke.

This package is the one import path of every error and warning class
(``from robodyn.exceptions import URDFError``); its modules group them by concern:
:mod:`~robodyn.exceptions.base` (the roots, the CLI's one-line warnings),
:mod:`~robodyn.exceptions.inputs` (what a caller or a file gave),
:mod:`~robodyn.exceptions.computation` (a computation that cannot answer right) and
:mod:`~robodyn.exceptions.environment` (extras, tools, outputs, services). Each class says
it belongs to ``robodyn.exceptions`` (its ``__module__``), as before the split: tracebacks,
``repr`` and pickles name that path.
"""

from __future__ import annotations

from robodyn.exceptions.base import RobodynError, RobodynWarning, one_line_warnings
from robodyn.exceptions.computation import (
    CompileError,
    CompilerNotFoundError,
    ControllerFailedError,
    DerivationTooExpensiveError,
    IdentificationError,
    NonFiniteResultError,
    OptimizationError,
    SimulationError,
    SingularMassMatrixError,
)
from robodyn.exceptions.environment import (
    MissingExtraError,
    MissingToolError,
    OutputError,
    SchedulerError,
    TypesettingError,
    ViewerError,
)
from robodyn.exceptions.inputs import (
    AmbiguousEndEffectorError,
    FrameError,
    InputError,
    JointLimitWarning,
    MeshFileError,
    MeshPathError,
    MeshWarning,
    StaticFrameError,
    TrajectoryError,
    UnknownRobotError,
    URDFError,
)

__all__ = [
    "AmbiguousEndEffectorError",
    "CompileError",
    "CompilerNotFoundError",
    "ControllerFailedError",
    "DerivationTooExpensiveError",
    "FrameError",
    "IdentificationError",
    "InputError",
    "JointLimitWarning",
    "MeshFileError",
    "MeshPathError",
    "MeshWarning",
    "MissingExtraError",
    "MissingToolError",
    "NonFiniteResultError",
    "OptimizationError",
    "OutputError",
    "RobodynError",
    "RobodynWarning",
    "SchedulerError",
    "SimulationError",
    "SingularMassMatrixError",
    "StaticFrameError",
    "TrajectoryError",
    "TypesettingError",
    "URDFError",
    "UnknownRobotError",
    "ViewerError",
    "one_line_warnings",
]

for _name in __all__:
    globals()[_name].__module__ = __name__
del _name
