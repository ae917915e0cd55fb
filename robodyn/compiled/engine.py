"""The compiled kernels as the engine of a :class:`robodyn.Robot`'s single calls, when they are built.

Importing this module registers :func:`built_module` with :mod:`robodyn.dynamics.engines`
(``import robodyn`` imports it), so a robot loaded with ``engine="auto"`` (the default)
answers ``tau``, ``M``, ``G``, ``C v + G`` and the forward dynamics with its compiled
kernels when they are built already: in this process (a dictionary look-up) or in the cache
folder (the key and one ``stat``, no sympy, no code generator: :func:`build.lookup`). It never
builds anything: ``robodyn.compile(robot)`` does (and leaves ``robot`` as it was: robots
loaded afterwards get the kernels).
"""

from __future__ import annotations

from types import ModuleType
from typing import TYPE_CHECKING

from robodyn.compiled import build
from robodyn.compiled.cache import robot_key
from robodyn.dynamics import engines
from robodyn.exceptions import RobodynError

if TYPE_CHECKING:
    from robodyn.dynamics.robot import Robot


class _NotBuiltError(Exception):
    """The module vanished between the look-up and the import (a cleared cache)."""


def _no_build() -> str:
    raise _NotBuiltError


def built_module(robot: Robot) -> ModuleType | None:
    """The robot's compiled kernels if they are built (this process, else the cache folder),
    else ``None``; never builds, never raises (a cache it cannot read is no kernels).

    Args:
        robot: The robot whose kernels are looked up (by its cache key).
    """
    try:
        module = build.loaded(robot)
        if module is None:
            if build.lookup(robot) is None:
                return None
            module = build.robot_module(robot_key(robot), _no_build, label=robot.name)
        if module.info()["nv"] != robot.nv:
            return None
    except (_NotBuiltError, RobodynError, ImportError, OSError):
        return None
    return module


engines.register(built_module)

__all__ = ["built_module"]
