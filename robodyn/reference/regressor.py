"""The reference's inertial-parameter regressor, computed without Pinocchio.

``tau`` is linear in the standard parameters π (per body: ``m, m·c, inertia about the body
origin``, the order of :mod:`robodyn.dynamics.regressor`), so a column of ``Y`` is the
reference's ``tau`` for a robot whose parameters are all zero but one. The reference
describes a body by its mass, centre of mass and inertia about the centre of mass, which
cannot hold a first moment without a mass; the columns are therefore taken as differences
of two robots with a unit mass: ``Y[:, m] = tau(m = 1)`` and
``Y[:, k] = tau(m = 1, π_k = 1) − tau(m = 1)``. (The parallel-axis form the reference uses is
exact for any non-zero mass, physical or not, so each robot is τ of that π.)

Bodies are the reference tree's bodies that carry a URDF link (a floating base's virtual
joints carry none but the last, which carries the root link), named by their link. Joints'
rotors (armature) are no rigid-body parameters: the regressor leaves them out (its ``tau``
is the robot's without the armature's ``a q̈``).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from robodyn.common.inputs import as_states
from robodyn.reference.numeric import ReferenceRobot
from robodyn.reference.tree import VIRTUAL_JOINTS, Body


def _inertia_about_origin(values: np.ndarray) -> np.ndarray:
    xx, xy, yy, xz, yz, zz = values
    return np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])


def _body_with(body: Body, parameters: np.ndarray) -> Body:
    """The body with standard parameters ``parameters`` (10 values, ``m`` non-zero)."""
    mass = float(parameters[0])
    com = parameters[1:4] / mass
    about_com = _inertia_about_origin(parameters[4:]) - mass * (com @ com * np.eye(3) - np.outer(com, com))
    return replace(body, mass=mass, com=com, inertia=about_com)


def reference_bodies(reference: ReferenceRobot) -> list[int]:
    """Indices of the tree's bodies that carry a link (the regressor's bodies, in order).

    Args:
        reference: The reference model of the robot.
    """
    bodies = reference.tree.bodies
    return [i for i, body in enumerate(bodies) if body.joint not in VIRTUAL_JOINTS[:5] and not body.rotor]


def reference_body_links(reference: ReferenceRobot) -> list[str]:
    """The link naming each regressor body.

    Args:
        reference: The reference model of the robot.
    """
    return [reference.tree.bodies[i].link for i in reference_bodies(reference)]


def reference_parameters(reference: ReferenceRobot) -> np.ndarray:
    """The reference's standard parameters π from the URDF, shape (10·n_bodies,).

    Args:
        reference: The reference model of the robot.
    """
    values = []
    for index in reference_bodies(reference):
        body = reference.tree.bodies[index]
        about_origin = body.inertia + body.mass * (body.com @ body.com * np.eye(3) - np.outer(body.com, body.com))
        values += [body.mass, *(body.mass * body.com), *about_origin[np.tril_indices(3)]]
    return np.array(values)


def reference_regressor(reference: ReferenceRobot, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
    """``Y(q, v, a)`` of the reference model, columns as :func:`reference_parameters`.

    Args:
        reference: The reference robot (:func:`robodyn.reference.load`).
        q, v, a: States, shape (n,) or (N, n) (``q`` (nq,) with a floating base), in the
            reference's joint order.

    Returns:
        Shape (n, 10·n_bodies) or (N, n, 10·n_bodies).
    """
    (q, v, a), batch = as_states({"q": (q, reference.nq), "v": (v, reference.nv), "a": (a, reference.nv)})
    q, v, a = np.atleast_2d(q), np.atleast_2d(v), np.atleast_2d(a)
    tree = reference.tree
    zero = [replace(body, mass=0.0, com=np.zeros(3), inertia=np.zeros((3, 3))) for body in tree.bodies]
    gravity = reference.gravity_vector

    def tau_with(index: int, parameters: np.ndarray) -> np.ndarray:
        bodies = list(zero)
        bodies[index] = _body_with(tree.bodies[index], parameters)
        robot = ReferenceRobot(
            replace(tree, bodies=bodies), name=reference.name, urdf=reference.urdf, spec=reference.spec, gravity=gravity
        )
        return robot.inverse_dynamics(q, v, a)

    columns = []
    unit = np.eye(10)
    for index in reference_bodies(reference):
        mass_only = tau_with(index, unit[0])
        columns.append(mass_only)
        columns += [tau_with(index, unit[0] + unit[k]) - mass_only for k in range(1, 10)]
    result = np.stack(columns, axis=-1)
    return result if batch else result[0]


__all__ = ["reference_bodies", "reference_body_links", "reference_parameters", "reference_regressor"]
