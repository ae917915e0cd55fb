"""Robots that travel: the robots unpickled in this process, built once per source and options.

A :class:`~robodyn.dynamics.robot.Robot` pickles by its source and its complete load
options (never by Pinocchio pointers): :mod:`robodyn.dynamics.loading` registers that with
:mod:`copyreg`, and unpickling calls :func:`robodyn.dynamics.loading.restore`, which asks
:func:`shared` here. The robots built so far are kept, keyed by the source (URDF text,
label, name, file, package folders) and the load options, so a robot sent to 100 tasks of
one worker process is parsed there once, and every task of that process gets the same
(thread-safe) robot. A robot's Pinocchio model changed by hand after loading does not
travel: edits go through its source (:func:`robodyn.dynamics.loading.rebuild`).
"""

from __future__ import annotations

import threading
from collections.abc import Callable

from robodyn.dynamics.options import LoadOptions
from robodyn.dynamics.robot import Robot
from robodyn.urdf.sources import URDFSource

_robots: dict[tuple[URDFSource, LoadOptions], Robot] = {}
_lock = threading.Lock()
#: Number of robots this process built by unpickling (a cache miss each); for tests.
builds = 0


def shared(source: URDFSource, options: LoadOptions, build: Callable[[URDFSource, LoadOptions], Robot]) -> Robot:
    """``build(source, options)``, called once per process and key; later calls get the same object.

    Args:
        source: Where the URDF came from (:attr:`robodyn.Robot.source`).
        options: How it was built (:attr:`robodyn.Robot.options`).
        build: Builds the robot (:func:`robodyn.dynamics.loading.build_robot`).

    Returns:
        The (shared) robot.
    """
    global builds
    key = (source, options)
    with _lock:
        robot = _robots.get(key)
        if robot is None:
            robot = _robots[key] = build(source, options)
            builds += 1
        return robot


def clear() -> None:
    """Forget the robots built so far (the next unpickling builds anew)."""
    with _lock:
        _robots.clear()


__all__ = ["builds", "clear", "shared"]
