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

import numpy as np

from robodyn.dynamics.robot import Robot

#: ``M``'s eigenvalues at or below this fraction of its largest are zero (as the simulator's check).
NULL_TOLERANCE = 1e-12

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


__all__ = ["inertialess_joints"]
