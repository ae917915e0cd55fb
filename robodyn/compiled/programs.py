"""A robot's symbolic programs, derived once and cached: what the kernels and the export print.

The equations layer derives, for a robot's bodies (mimic joints as bodies of their own; a
floating base as a free body 0):

- the compact program (:func:`robodyn.equations.compact.derive_compact`: ``M``, ``C v``,
  ``G``) and the Newton–Euler program (:func:`robodyn.equations.newton_euler.derive_newton_euler`:
  ``tau`` in O(n)), together: :func:`dynamics_programs`;
- anything else a printer needs (the export's ``C v + G`` in one pass, its frames), through
  :func:`derived` under a name of its own.

Each is derived once per robot key (:func:`robodyn.compiled.cache.robot_key`: the URDF text,
the options and the generator's source) and kept twice: in this process (a dictionary) and in
the cache folder (``prog-<hash>.pickle``, the sympy objects pickled), so the compiled kernels,
their derivatives and the CasADi/JAX export (:mod:`robodyn.export`) print from one
derivation, and a second process does not derive again. A pickle that does not load (another
sympy, a truncated file) is derived again and replaced.
"""

from __future__ import annotations

import contextlib
import dataclasses
import os
import pickle
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TypeVar, cast

import numpy as np

from robodyn.compiled.cache import SNAP, cache_dir, digest, robot_key
from robodyn.dynamics.robot import Robot
from robodyn.equations.compact import CompactDynamics, derive_compact
from robodyn.equations.newton_euler import BaseSymbols, derive_newton_euler, floating_tree
from robodyn.equations.program import Program
from robodyn.exceptions import CompileError
from robodyn.reference.numeric import ReferenceRobot
from robodyn.reference.tree import KinematicTree, build_tree

T = TypeVar("T")
_DERIVED: dict[tuple[str, str], object] = {}


@dataclass(frozen=True)
class Bodies:
    """A robot's bodies as the programs see them.

    Attributes:
        tree: The reference tree (a floating base: its free body 0 first).
        reference: The bodies, one coordinate each (the programs' inputs).
        selection: ``S``, shape (n_bodies, nv of the joints): body ``b``'s coordinate is
            ``selection[b] @ q_joints + offset[b]``.
        offset: Shape (n_bodies,), in [rad] / [m].
    """

    tree: KinematicTree
    reference: ReferenceRobot
    selection: np.ndarray
    offset: np.ndarray


@dataclass(frozen=True)
class DynamicsPrograms:
    """The compact program (``M``, ``C v``, ``G``) and the Newton–Euler program (``tau``) of
    one robot's bodies, derived together (a floating base: the same free-base symbols)."""

    compact: CompactDynamics
    tau: Program


def robot_bodies(robot: Robot) -> Bodies:
    """The robot's bodies and the map from its joints' coordinates (cheap: no sympy).

    Args:
        robot: The loaded robot.

    Raises:
        CompileError: If the reference tree and the Pinocchio model disagree on the joints.
    """
    tree = build_tree(robot.spec, robot.urdf, floating_base=robot.floating_base)
    if robot.floating_base:
        tree = floating_tree(tree)
    names = [name for name in robot.joint_names if not (robot.floating_base and name == robot.joint_names[0])]
    if sorted(tree.joint_names) != sorted(names):
        raise CompileError(robot.name, "the reference tree and the Pinocchio model disagree on the joints")
    selection = tree.selection[:, [tree.joint_names.index(name) for name in names]]
    count = len(tree.bodies)
    free = dataclasses.replace(tree, selection=np.eye(count), offset=np.zeros(count), joint_names=[f"b{i}" for i in range(count)])
    reference = ReferenceRobot(free, name=robot.name, urdf=robot.urdf, spec=robot.spec, gravity=robot.gravity_vector)
    return Bodies(tree, reference, selection, np.asarray(tree.offset, float))


def derived(robot: Robot, name: str, derive: Callable[[], T]) -> T:
    """``derive()``'s result for a robot, derived once per robot key and name: from this
    process's memory, else the cache folder's pickle, else derived and kept in both.

    Args:
        robot: The loaded robot (its cache key, :func:`robodyn.compiled.cache.robot_key`).
        name: What is derived (``"dynamics"``, ...): with the robot's key, the cache entry's name.
        derive: Derives the value; called only when neither memory nor the cache has it.
    """
    key = (robot_key(robot), name)
    if key in _DERIVED:
        return cast(T, _DERIVED[key])
    path = cache_dir() / f"prog-{digest(*key)}.pickle"
    try:
        with open(path, "rb") as handle:
            value = pickle.load(handle)
    except Exception:
        value = derive()
        _store(path, value)
    _DERIVED[key] = value
    return cast(T, value)


def _store(path: Path, value: object) -> None:
    """Pickle ``value`` to ``path`` under a temporary name renamed into place (never half a
    file); a read-only cache folder or an object that does not pickle is skipped."""
    try:
        data = pickle.dumps(value, protocol=pickle.HIGHEST_PROTOCOL)
        path.parent.mkdir(parents=True, exist_ok=True)
        handle, temporary = tempfile.mkstemp(prefix=".prog-", dir=path.parent)
    except (OSError, pickle.PicklingError, RecursionError, TypeError, AttributeError):
        return
    try:
        with os.fdopen(handle, "wb") as file:
            file.write(data)
        os.replace(temporary, path)
    except OSError:
        with contextlib.suppress(OSError):
            os.unlink(temporary)


def dynamics_programs(robot: Robot) -> DynamicsPrograms:
    """The robot's compact and Newton–Euler programs (derived once per robot key: seconds for a
    7-joint arm the first time, then microseconds in a process, milliseconds from the cache).

    Args:
        robot: The loaded robot.

    Raises:
        CompileError: For joints the reference does not map.
    """

    def derive() -> DynamicsPrograms:
        reference = robot_bodies(robot).reference
        base = BaseSymbols.make() if robot.floating_base else None
        compact = derive_compact(reference, snap=SNAP, free_base=base)
        return DynamicsPrograms(compact, derive_newton_euler(reference, snap=SNAP, free_base=base))

    return derived(robot, "dynamics", derive)
