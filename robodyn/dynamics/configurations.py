"""Configurations of a robot: its joint limits, and the neutral, default (the start) and random ``q``.

Functions of a :class:`~robodyn.dynamics.handle.ModelHandle` and the robot's degrees of
freedom (:attr:`robodyn.Robot.dofs`, which own the limits); :class:`robodyn.Robot` has them
as methods and properties.

Limits a URDF leaves open: an infinite limit, or a *placeholder* of magnitude at least
:data:`PLACEHOLDER_LIMIT` (1e3 m or rad: URDFs write ±999 999 where the format demands a
number), or an empty range (``lower == upper`` on a moving joint), counts as no limit
wherever robodyn needs a physical range (sampling, the default configuration,
simulation's limit checks).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pinocchio as pin

from robodyn.common.inputs import as_states
from robodyn.dynamics.dofs import Dof
from robodyn.dynamics.handle import ModelHandle
from robodyn.exceptions import InputError

#: Position limits at least this large in magnitude (1e3 m or rad) are placeholders for
#: "unlimited" (URDFs write ±999 999 where the format demands a number).
PLACEHOLDER_LIMIT = 1e3


def lower_limits(dofs: Sequence[Dof]) -> np.ndarray:
    """Lower position limits per degree of freedom, shape (nv,), in [rad] or [m].

    The six base coordinates of a floating base are unlimited (-inf).

    Args:
        dofs: The degrees of freedom (:attr:`robodyn.Robot.dofs`).
    """
    return np.array([dof.lower for dof in dofs])


def upper_limits(dofs: Sequence[Dof]) -> np.ndarray:
    """Upper position limits per degree of freedom, shape (nv,), in [rad] or [m].

    Args:
        dofs: The degrees of freedom (:attr:`robodyn.Robot.dofs`).
    """
    return np.array([dof.upper for dof in dofs])


def neutral_configuration(handle: ModelHandle) -> np.ndarray:
    """Pinocchio's neutral configuration (zero joint positions, the base at the origin,
    unrotated), shape (nq,).

    It may lie outside the joint limits (panda's joint 4 lives in [-3.07, -0.07] rad) and
    ignores where the file puts a floating base; :func:`default_configuration` (the
    robot's start) does neither.
    """
    return pin.neutral(handle.model)


def default_configuration(handle: ModelHandle, dofs: Sequence[Dof], base_pose: Sequence[float] | None = None) -> np.ndarray:
    """The robot's start: the file's base pose, the joints at zero clipped into their
    position limits, shape (nq,).

    The initial state of simulations and motions when none is given: every joint at
    zero, or at its nearest limit when zero is outside them (placeholder limits, see
    :func:`random_configuration`, are ignored); a floating base where the file puts it
    (MJCF: the free body's ``<body pos quat>``, so that with the joints' ``ref`` as
    robodyn's zero this is MuJoCo's ``qpos0`` where it lies within the limits), else at
    the origin, unrotated.

    Args:
        handle: The robot's model handle.
        dofs: Its degrees of freedom (:attr:`robodyn.Robot.dofs`).
        base_pose: The floating base's start, position in [m] then quaternion x, y, z, w
            (:attr:`robodyn.urdf.sources.URDFSource.base_pose`); ignored for a fixed base.
    """
    q = neutral_configuration(handle)
    if handle.floating_base and base_pose is not None:
        q[:7] = base_pose
    lower, upper = physical_limits(dofs)
    start = handle.nq - lower.size
    q[start:] = np.clip(q[start:], lower, upper)
    return q


def physical_limits(dofs: Sequence[Dof]) -> tuple[np.ndarray, np.ndarray]:
    """Position limits of the joints (floating base excluded), placeholders as ±inf.

    A limit of magnitude at least :data:`PLACEHOLDER_LIMIT` (1e3 m or rad, e.g.
    ridgeback's ±999 999 m) stands for "unlimited" and becomes ±inf, and so does an
    empty range ``lower == upper`` of a joint that is not fixed (example-robot-data's
    double pendulums write ``lower="0" upper="0"`` on joints that swing freely).

    Args:
        dofs: The degrees of freedom (:attr:`robodyn.Robot.dofs`).

    Returns:
        ``(lower, upper)``, each of shape (nv,), or (nv − 6,) with a floating base.
    """
    joints = [dof for dof in dofs if not dof.is_base]
    lower, upper = lower_limits(joints), upper_limits(joints)
    empty = lower == upper
    lower = np.where((np.abs(lower) >= PLACEHOLDER_LIMIT) | empty, -np.inf, lower)
    upper = np.where((np.abs(upper) >= PLACEHOLDER_LIMIT) | empty, np.inf, upper)
    return lower, upper


def floating_configuration(handle: ModelHandle, position, rpy, joints=None) -> np.ndarray:
    """A floating-base configuration from the base pose and the joint positions.

    Args:
        handle: The robot's model handle.
        position: Base origin in the world frame, in [m], shape (3,).
        rpy: Base orientation as roll, pitch, yaw in [rad] (rotations about the fixed
            x, y, z axes, as in URDF), shape (3,).
        joints: Joint positions, shape (nv - 6,); default zeros.

    Returns:
        ``q`` of shape (nq,): position, quaternion (x, y, z, w), joints.

    Raises:
        InputError: For a fixed-base robot or wrong sizes.
    """
    if not handle.floating_base:
        raise InputError("robot", "a floating-base robot (load it with floating_base=True)", f"fixed-base {handle.name!r}")
    position, rpy = as_states({"position": (position, 3), "rpy": (rpy, 3)})[0]
    joints = np.zeros(handle.nv - 6) if joints is None else as_states({"joints": (joints, handle.nv - 6)})[0][0]
    quaternion = pin.Quaternion(pin.rpy.rpyToMatrix(*rpy)).coeffs()
    return np.concatenate([position, quaternion, joints])


def random_configuration(
    handle: ModelHandle, dofs: Sequence[Dof], rng: np.random.Generator, count: int | None = None
) -> np.ndarray:
    """Configurations drawn uniformly within the joint limits, in a physical range.

    The rule: a joint with both limits draws between them. A limit that is missing,
    infinite or a placeholder (magnitude ≥ 1e3 m or rad, :data:`PLACEHOLDER_LIMIT`;
    an empty range ``lower == upper``) counts as absent: a joint with no limit draws from [-π, π] (in [rad] or [m]), a
    joint with one limit from the 2π-wide interval on its side of it. A floating base
    draws its position from [-1, 1] m and a uniform random orientation.

    Args:
        handle: The robot's model handle.
        dofs: Its degrees of freedom (:attr:`robodyn.Robot.dofs`).
        rng: Random generator (for reproducible draws).
        count: Number of configurations (≥ 0); ``None`` for a single one.

    Returns:
        Shape (nq,) or (count, nq).

    Raises:
        InputError: If ``count`` is not a non-negative integer.
    """
    if count is not None and (isinstance(count, bool) or not isinstance(count, (int, np.integer)) or count < 0):
        raise InputError("count", "a non-negative integer or None", repr(count))
    rows = 1 if count is None else int(count)
    lower, upper = physical_limits(dofs)
    lower, upper = (
        np.where(np.isfinite(lower), lower, np.where(np.isfinite(upper), upper - 2 * np.pi, -np.pi)),
        np.where(np.isfinite(upper), upper, np.where(np.isfinite(lower), lower + 2 * np.pi, np.pi)),
    )
    joints = rng.uniform(lower, upper, size=(rows, lower.size))
    if handle.floating_base:
        quaternion = rng.normal(size=(rows, 4))
        quaternion /= np.linalg.norm(quaternion, axis=1, keepdims=True)
        joints = np.hstack([rng.uniform(-1, 1, size=(rows, 3)), quaternion, joints])
    return joints[0] if count is None else joints


__all__ = [
    "PLACEHOLDER_LIMIT",
    "default_configuration",
    "floating_configuration",
    "lower_limits",
    "neutral_configuration",
    "physical_limits",
    "random_configuration",
    "upper_limits",
]
