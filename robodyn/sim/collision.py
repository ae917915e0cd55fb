"""What a momentum observer's residual tells (:mod:`robodyn.sim.observer`): the wrench at a
frame (:func:`external_wrench`, ``F = (Jᵀ)⁺ r``) and the first collision
(:func:`detect_collision`: when the first ``|r_i|`` crosses its threshold, and the last
joint whose residual is significant — a force on a link moves only the joints before it,
so that joint's child link is the one that was hit).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError


def external_wrench(robot: Robot, q: np.ndarray, residual: np.ndarray, frame: str) -> np.ndarray:
    """The wrench at a frame's origin that explains external joint torques: ``(Jᵀ)⁺ r``.

    Exact when the torques come from a wrench at that frame and ``Jᵀ`` has full column
    rank (six joints or more before the frame, away from singularities); otherwise the
    least-squares wrench of least norm.

    Args:
        robot: The robot.
        q: Configuration(s), shape (nq,) or (N, nq).
        residual: External torques, shape (nv,) or (N, nv).
        frame: The frame whose wrench is wanted.

    Returns:
        Force in [N] then torque in [N m], world axes: shape (6,) or (N, 6).
    """
    jacobian = robot.frame_jacobian(q, robot.task_frame(frame, "an external wrench"))
    residual = np.asarray(residual, dtype=float)
    return np.einsum("...ij,...j->...i", np.linalg.pinv(np.swapaxes(jacobian, -1, -2), rcond=1e-10), residual)


@dataclass(frozen=True)
class Collision:
    """A detected contact.

    Attributes:
        time: First time a residual crossed its threshold, in [s].
        index: Index in ``v`` of the last joint whose residual was significant.
        dof: That degree of freedom's name (``robot.dofs``).
        peak: Largest ``|r_i|`` of each joint over the contact, shape (nv,).
    """

    time: float
    index: int
    dof: str
    peak: np.ndarray


def detect_collision(robot: Robot, t: np.ndarray, residual: np.ndarray, threshold: float | np.ndarray) -> Collision | None:
    """The first contact in an observer's residual, and which joint's link it hit.

    The contact starts when some ``|r_i|`` first exceeds its threshold and lasts while any
    does; the joint reported is the last one whose ``|r_i|`` exceeded its threshold during
    it (a wrench on a link produces torques at the joints before it only).

    Args:
        robot: The robot (for the joints' names).
        t: Times in [s], shape (N,).
        residual: The observer's estimate, shape (N, nv).
        threshold: In [N m] / [N], scalar or (nv,), positive.

    Returns:
        The contact, or ``None`` when no residual crosses its threshold.
    """
    residual = np.abs(np.asarray(residual, dtype=float))
    limits = np.broadcast_to(np.asarray(threshold, dtype=float), (robot.nv,))
    if not (np.isfinite(limits).all() and (limits > 0).all()):
        raise InputError("threshold", f"a positive scalar or {robot.nv} positive values in [N m] / [N]", repr(threshold))
    above = residual > limits
    hits = np.flatnonzero(above.any(axis=1))
    if hits.size == 0:
        return None
    start = int(hits[0])
    quiet = np.flatnonzero(~above[start:].any(axis=1))
    end = start + int(quiet[0]) if quiet.size else len(residual)
    peak = residual[start:end].max(axis=0)
    index = int(np.flatnonzero(peak > limits)[-1])
    return Collision(float(t[start]), index, robot.dofs[index].name, peak)
