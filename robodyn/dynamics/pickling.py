"""Robots that travel: a :class:`~robodyn.dynamics.robot.Robot` pickles by its source and
options (never by Pinocchio pointers) and is rebuilt on the other side.

:func:`restore` is what unpickling calls. It keeps the robots it built in this process,
keyed by the source (URDF text, label, name, file, package folders) and the load options,
so a robot sent to 100 tasks of one worker process is parsed there once, and every task
of that process gets the same (thread-safe) :class:`Robot`. A robot's Pinocchio model
changed by hand after loading does not travel: edits go through its source
(:func:`robodyn.dynamics.loading.rebuild`). ``copy.copy`` and ``copy.deepcopy`` of a robot go
the same way and give the process's shared robot: for an independent copy use ``rebuild(robot)``.
"""

from __future__ import annotations

import threading
from dataclasses import asdict

from robodyn.dynamics.robot import LoadOptions, Robot
from robodyn.urdf.sources import URDFSource

_robots: dict[tuple[URDFSource, LoadOptions], Robot] = {}
_lock = threading.Lock()
#: Number of robots this process built by unpickling (a cache miss each); for tests.
builds = 0


def restore(source: URDFSource, options: LoadOptions) -> Robot:
    """The robot built from ``source`` with ``options``, built once per process.

    Args:
        source: Where the URDF came from (:attr:`Robot.source`).
        options: How it was built (:attr:`Robot.options`).

    Returns:
        The (shared) robot.
    """
    global builds
    key = (source, options)
    with _lock:
        robot = _robots.get(key)
        if robot is None:
            from robodyn.dynamics.loading import build_robot

            robot = build_robot(source, **asdict(options))
            _robots[key] = robot
            builds += 1
        return robot


def clear() -> None:
    """Forget the robots built so far (the next unpickling builds anew)."""
    with _lock:
        _robots.clear()
