"""MuJoCo's state and robodyn's: ``qpos``, ``qvel`` ↔ ``q``, ``v`` by one rule.

- **Joint order**: MuJoCo's is the file's (its joints in document order, a free joint
  first); robodyn's is :attr:`robodyn.Robot.joint_names`. Joints are matched by name: for
  a robot read from an MJCF file the file's order is known; for any other robot the
  MuJoCo order is given as ``joint_names`` (MuJoCo's joint names in its order), or the
  call is refused.
- **ref**: a hinge or slide joint's ``ref`` is a constant offset, MuJoCo's
  ``qpos = q + ref`` (:attr:`robodyn.urdf.sources.URDFSource.joint_offsets`): robodyn's
  ``q = 0`` is the body in its modelled pose.
- **Free joint**: MuJoCo's ``qpos`` is position, quaternion **w x y z**; robodyn's ``q``
  is position, quaternion **x y z w**. MuJoCo's ``qvel`` is the linear velocity in the
  **world** frame and the angular velocity in the body frame; robodyn's (Pinocchio's)
  ``v`` has both in the base frame: ``v_linear = Rᵀ qvel_linear``.

A 1-D state gives one result, a 2-D array (one state a row) a stacked result.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

import numpy as np

from robodyn.common.inputs import as_state
from robodyn.common.text import quoted
from robodyn.dynamics.dofs import Dof
from robodyn.dynamics.options import LoadOptions
from robodyn.exceptions import InputError
from robodyn.urdf.sources import URDFSource
from robodyn.urdf.validation import URDFSpec


class Robot(Protocol):
    """What of a :class:`robodyn.Robot` the conversion reads (the robot module calls this one)."""

    nq: int
    nv: int
    floating_base: bool
    dofs: tuple[Dof, ...]
    configuration_names: list[str]
    source: URDFSource
    spec: URDFSpec
    options: LoadOptions


def mujoco_joint_order(robot: Robot, joint_names: Sequence[str] | None = None) -> list[str]:
    """MuJoCo's order of the robot's moving joints (the free joint not included).

    Args:
        robot: The robot.
        joint_names: MuJoCo's joint names in its order (default: the file's order, for a
            robot read from MJCF).

    Raises:
        InputError: If the order is not known or does not name each joint of the robot once.
    """
    moving = [dof.joint for dof in robot.dofs if not dof.is_base]
    if joint_names is None:
        if robot.source.file_format != "mjcf":
            raise InputError("joint_names", "MuJoCo's joint names in its order (the robot was not read from MJCF)", "None")
        if robot.options.lock:
            locked = ", ".join(quoted(name) for name, _ in robot.options.lock)
            raise InputError("joint_names", f"given for a robot with locked joints (MuJoCo's model moves {locked})", "None")
        written = [node.get("name") for node in robot.spec.xml.findall("joint") if node.get("type") != "fixed"]
        joint_names = [name for name in written if name in moving]
    names = [str(name) for name in joint_names]
    if sorted(names) != sorted(moving):
        missing = sorted(set(moving) - set(names)) or sorted(set(names) - set(moving)) or ["a repeated name"]
        raise InputError(
            "joint_names", f"each of the robot's {len(moving)} joints once", f"a list missing or adding {quoted(missing[0])}"
        )
    return names


def _layout(robot: Robot, joint_names: Sequence[str] | None) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """Indices into robodyn's q and v of MuJoCo's joint entries, their ``ref`` offsets, and
    the free joint's size in qpos (0 or 7)."""
    order = mujoco_joint_order(robot, joint_names)
    offsets = dict(robot.source.joint_offsets)
    q_index = np.array([robot.configuration_names.index(name) for name in order], dtype=int)
    v_index = np.array([next(dof.index for dof in robot.dofs if dof.name == name) for name in order], dtype=int)
    return q_index, v_index, np.array([offsets.get(name, 0.0) for name in order]), 7 if robot.floating_base else 0


def to_mujoco(
    robot: Robot, q: np.ndarray, v: np.ndarray | None = None, *, joint_names: Sequence[str] | None = None
) -> tuple[np.ndarray, np.ndarray | None]:
    """MuJoCo's ``qpos`` and ``qvel`` of robodyn's ``q`` and ``v`` (see the module).

    Args:
        robot: The robot.
        q: Configuration, (nq,) or (N, nq).
        v: Velocity, (nv,) or (N, nv), or ``None``.
        joint_names: MuJoCo's joint names in its order (needed unless read from MJCF).

    Returns:
        ``qpos`` (nq,) or (N, nq), ``qvel`` (nv,) or (N, nv) (``None`` without ``v``).
    """
    q_index, v_index, offsets, free = _layout(robot, joint_names)
    q = as_state(q, "q", robot.nq)
    rows = np.atleast_2d(q)
    qpos = np.empty_like(rows)
    if free:
        qpos[:, :3], qpos[:, 3], qpos[:, 4:7] = rows[:, :3], rows[:, 6], rows[:, 3:6]
    qpos[:, free:] = rows[:, q_index] + offsets
    qvel = None
    if v is not None:
        velocity = np.atleast_2d(as_state(v, "v", robot.nv))
        if len(velocity) != len(rows):
            raise InputError("v", f"{len(rows)} rows as q", f"{len(velocity)} rows")
        qvel = np.empty_like(velocity)
        if free:
            qvel[:, :3] = np.einsum("nij,nj->ni", _rotations(rows[:, 3:7]), velocity[:, :3])
            qvel[:, 3:6] = velocity[:, 3:6]
        qvel[:, 6 if free else 0 :] = velocity[:, v_index]
    return (qpos[0], None if qvel is None else qvel[0]) if q.ndim == 1 else (qpos, qvel)


def from_mujoco(
    robot: Robot, qpos: np.ndarray, qvel: np.ndarray | None = None, *, joint_names: Sequence[str] | None = None
) -> tuple[np.ndarray, np.ndarray | None]:
    """robodyn's ``q`` and ``v`` of MuJoCo's ``qpos`` and ``qvel`` (see the module).

    Args:
        robot: The robot.
        qpos: MuJoCo's positions, (nq,) or (N, nq).
        qvel: MuJoCo's velocities, (nv,) or (N, nv), or ``None``.
        joint_names: MuJoCo's joint names in its order (needed unless read from MJCF).

    Returns:
        ``q`` (nq,) or (N, nq), ``v`` (nv,) or (N, nv) (``None`` without ``qvel``).
    """
    q_index, v_index, offsets, free = _layout(robot, joint_names)
    qpos = as_state(qpos, "qpos", robot.nq)
    rows = np.atleast_2d(qpos)
    q = np.empty_like(rows)
    if free:
        q[:, :3], q[:, 3:6], q[:, 6] = rows[:, :3], rows[:, 4:7], rows[:, 3]
    q[:, q_index] = rows[:, free:] - offsets
    v = None
    if qvel is not None:
        velocity = np.atleast_2d(as_state(qvel, "qvel", robot.nv))
        if len(velocity) != len(rows):
            raise InputError("qvel", f"{len(rows)} rows as qpos", f"{len(velocity)} rows")
        v = np.empty_like(velocity)
        if free:
            v[:, :3] = np.einsum("nji,nj->ni", _rotations(q[:, 3:7]), velocity[:, :3])
            v[:, 3:6] = velocity[:, 3:6]
        v[:, v_index] = velocity[:, 6 if free else 0 :]
    return (q[0], None if v is None else v[0]) if qpos.ndim == 1 else (q, v)


def _rotations(xyzw: np.ndarray) -> np.ndarray:
    """Rotation matrices (N, 3, 3) of quaternions x, y, z, w (N, 4), normalised."""
    x, y, z, w = (xyzw / np.linalg.norm(xyzw, axis=1, keepdims=True)).T
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], axis=-1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], axis=-1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=-1),
        ],
        axis=1,
    )
