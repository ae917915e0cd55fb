"""Joints whose motion moves no inertia: the null space of the mass matrix.

A joint whose whole subtree has no mass makes ``M(q)`` singular for every ``q``
(:func:`robodyn.dynamics.kernels.massless_joints`). Bodies with mass but no rotational
inertia (point masses) can do it too, as a combination of joints: two revolute axes
through one point, carrying only point masses on the line their combined rotation turns
about, move nothing together (example-robot-data's iCub: its head is a point mass behind
``neck_roll`` and ``neck_yaw``). This module names the joints of such a combination at a
configuration; it is a fact of the model, which Pinocchio's CRBA shares.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from robodyn.exceptions import SingularMassMatrixError

if TYPE_CHECKING:  # the robot calls singular_error on its failing path: no import cycle
    from robodyn.dynamics.robot import Robot

#: ``M``'s eigenvalues at or below this fraction of its largest are zero (as the simulator's check).
NULL_TOLERANCE = 1e-12

#: Accelerations above this, in [rad/s²] / [m/s²], have ``M(q)``'s rank looked at: a solve
#: on a singular ``M`` divides a torque by a round-off pivot, some 1e15 times too large.
SUSPECT_ACCELERATION = 1e12

#: Entries of ``M⁻¹`` above this, in [1/(kg m²)] / [1/kg], have ``M(q)``'s rank looked at.
SUSPECT_INVERSE = 1e12

#: A degree of freedom whose weight in the null space exceeds this takes part in it.
WEIGHT = 0.1


def inertialess_joints(robot: Robot, q: np.ndarray) -> list[str]:
    """The joints whose motions together move no inertia at ``q`` (``M(q)``'s null space), in
    the robot's joint order; ``[]`` when ``M(q)`` is regular.

    Args:
        robot: The robot.
        q: One configuration, shape (nq,), in [rad] / [m].
    """
    eigenvalues, vectors = np.linalg.eigh(robot.mass_matrix(q))
    null = eigenvalues <= NULL_TOLERANCE * max(abs(eigenvalues[-1]), np.finfo(float).tiny)
    if not null.any():
        return []
    weights = np.linalg.norm(vectors[:, null], axis=1)
    names: list[str] = []
    for index in np.flatnonzero(weights > WEIGHT):
        joint = robot.dofs[int(index)].joint
        if joint not in names:
            names.append(joint)
    return names


def singular_error(robot: Robot, q: np.ndarray, rows: np.ndarray | None = None) -> SingularMassMatrixError:
    """The error of a forward dynamics that failed at ``q``: it names the joints that together
    move no inertia at the first state of ``q`` (in ``rows``) where there are some, and that
    state's row in a batch; without any, the plain singular-mass-matrix error. For failing
    paths only (one eigendecomposition of ``M`` a state looked at).

    Args:
        robot: The robot.
        q: One configuration, shape (nq,), or a batch, shape (N, nq), in [rad] / [m].
        rows: The rows of a batch to look at (default: all), in order.
    """
    q = np.asarray(q, dtype=float)
    if q.ndim == 1:
        joints = inertialess_joints(robot, q)
        return SingularMassMatrixError(robot.name, joints, inertialess=bool(joints))
    for row in range(len(q)) if rows is None else rows:
        joints = inertialess_joints(robot, q[int(row)])
        if joints:
            return SingularMassMatrixError(robot.name, joints, inertialess=True, row=int(row))
    return SingularMassMatrixError(robot.name, [])


def refuse_singular(robot: Robot, q: np.ndarray, values: np.ndarray, limit: float = SUSPECT_ACCELERATION) -> None:
    """Raise :func:`singular_error` if ``values`` computed at ``q`` (accelerations, or ``M⁻¹``)
    came from a singular ``M(q)``. When none exceeds ``limit`` in magnitude this costs a dot
    product (one state) or an extremum (a batch); ``M``'s rank is looked at only at the
    states whose values do.

    Args:
        robot: The robot.
        q: One configuration, shape (nq,), or a batch, shape (N, nq), in [rad] / [m].
        values: The state's result, e.g. accelerations of shape (nv,) in [rad/s²] / [m/s²],
            or a batch's, with a leading axis of length N.
        limit: The magnitude above which a value is suspect (default :data:`SUSPECT_ACCELERATION`).
    """
    rows = None
    if np.ndim(q) == 1:
        flat = values.ravel()
        if not flat.dot(flat) > limit**2:
            return
    elif values.size and (values.max() > limit or values.min() < -limit):  # no BLAS on a batch: its threads
        rows = np.flatnonzero(np.abs(values).reshape(len(values), -1).max(axis=1) > limit)  # wait on Pinocchio's
    else:
        return
    error = singular_error(robot, q, rows)
    if error.joints:
        raise error


__all__ = ["SUSPECT_ACCELERATION", "SUSPECT_INVERSE", "inertialess_joints", "refuse_singular", "singular_error"]
