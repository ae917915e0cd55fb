"""The inertial-parameter regressor: ``tau = Y(q, v, a) π``, linear in the links' inertias.

Conventions, stated once (they are Pinocchio's, ``pin.Inertia.toDynamicParameters``):

- The **bodies** are the rigid bodies that move: one per moving joint (mimic joints
  included, a floating base's root link first), in Pinocchio's joint order. A body is the
  joint's child link together with every link welded to it by fixed joints, merged as in
  Pinocchio's ``model.inertias`` (masses added, first moments and inertias moved to the
  body frame). Links welded to the fixed world carry no parameter.
- Each body has 10 **standard parameters**, expressed in the body frame (the joint's child
  link frame, whose origin is on the joint):
  ``m, m·cx, m·cy, m·cz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz`` — the mass in [kg], the first
  moment ``m·c`` in [kg m] (``c`` the centre of mass), and the inertia **about the body
  frame's origin** (not about the centre of mass) in [kg m²], lower triangle row by row.
- Optional **friction** columns come after all bodies: one viscous coefficient a joint
  (``fv``, torque ``fv·v`` in [N m s/rad] or [N s/m]), then one Coulomb coefficient a
  joint (``fc``, torque ``fc·sign(v)`` in [N m] or [N]), in the order of ``joint_names``.
  The robot's own dynamics have no friction, so its friction parameters are zero.

The columns for a body are exactly those of Pinocchio's ``computeJointTorqueRegressor``
(``Y = Sᵀ Y_full`` through the mimic map for robots with mimic joints, where Pinocchio's
regressor is evaluated on the expanded model; locked joints are fixed joints, so their
links are welded). ``Y π = robot.inverse_dynamics`` to rounding.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

if TYPE_CHECKING:  # Robot calls into this module (Robot.regressor): no import at run time
    from robodyn.dynamics.robot import Robot

#: Names of a body's 10 standard parameters, in order.
PARAMETER_KINDS = ("m", "mx", "my", "mz", "Ixx", "Ixy", "Iyy", "Ixz", "Iyz", "Izz")
#: Names of a joint's friction parameters, in order (all viscous columns, then all Coulomb).
FRICTION_KINDS = ("fv", "fc")


def body_links(robot: Robot) -> list[str]:
    """The URDF link that names each body (the moving joint's child link), in order."""
    model = robot.model if robot.mimic is None else robot.mimic.model
    links = []
    for joint_id in range(1, model.njoints):
        name = model.names[joint_id]
        links.append(robot.spec.joints[name].child if name in robot.spec.joints else robot.spec.root)
    return links


def parameter_names(robot: Robot, *, friction: bool = False) -> list[str]:
    """Names of the standard parameters, ``"kind[link]"`` (e.g. ``"Izz[link1]"``), in the
    order of :func:`regressor`'s columns (friction: ``"fv[joint]"``, ``"fc[joint]"``)."""
    names = [f"{kind}[{link}]" for link in body_links(robot) for kind in PARAMETER_KINDS]
    if friction:
        names += [f"{kind}[{joint}]" for kind in FRICTION_KINDS for joint in _friction_joints(robot)]
    return names


def _friction_joints(robot: Robot) -> list[str]:
    """One name per velocity coordinate (a floating base's six get ``root_joint.k``)."""
    names = []
    for joint in robot.joints:
        names += [f"{joint.name}.{k}" for k in range(6)] if joint.type == "floating" else [joint.name]
    return names


def inertial_parameters(robot: Robot, *, friction: bool = False) -> np.ndarray:
    """The standard parameters π of the robot's model (its URDF), so that ``Y π = tau``.

    Args:
        robot: The robot.
        friction: Append the friction parameters (zeros: the model has no friction).

    Returns:
        Shape (10·n_bodies,) (``+ 2·nv`` with friction), units as in the module docstring.
    """
    model = robot.model if robot.mimic is None else robot.mimic.model
    values = np.concatenate([model.inertias[i].toDynamicParameters() for i in range(1, model.njoints)])
    return np.concatenate([values, np.zeros(2 * robot.nv)]) if friction else values


def regressor(robot: Robot, q: np.ndarray, v: np.ndarray, a: np.ndarray, *, friction: bool = False) -> np.ndarray:
    """The regressor ``Y(q, v, a)`` with ``tau = Y π`` (π from :func:`inertial_parameters`).

    Args:
        robot: The robot.
        q: Configuration, shape (nq,) or (N, nq).
        v: Velocity, shape (nv,) or (N, nv).
        a: Acceleration, shape (nv,) or (N, nv).
        friction: Append the viscous and Coulomb friction columns (``v`` and ``sign(v)``).

    Returns:
        Shape (nv, 10·n_bodies) or (N, nv, 10·n_bodies) (``+ 2·nv`` columns with friction).

    Raises:
        InputError: For states of the wrong shape or with non-finite values.
    """
    (q, v, a), batch = robot.validate(q=q, v=v, a=a)
    rows = [_one(robot, *state) for state in zip(np.atleast_2d(q), np.atleast_2d(v), np.atleast_2d(a), strict=True)]
    result = np.stack(rows) if rows else np.zeros((0, robot.nv, 10 * len(body_links(robot))))
    if friction:
        v2 = np.atleast_2d(v)
        eye = np.eye(robot.nv)
        columns = np.concatenate([eye[None] * v2[:, None, :], eye[None] * np.sign(v2)[:, None, :]], axis=2)
        result = np.concatenate([result, columns], axis=2)
    return result if batch else result[0]


def _one(robot: Robot, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
    # (the Python binding returns a 1-D array when nv = 1: reshape)
    if robot.mimic is None:
        return np.array(pin.computeJointTorqueRegressor(robot.model, robot.data, q, v, a)).reshape(robot.nv, -1)
    mimic = robot.mimic
    full = pin.computeJointTorqueRegressor(mimic.model, mimic.data, mimic.q(q), mimic.selection @ v, mimic.selection @ a)
    return mimic.selection.T @ np.reshape(full, (mimic.model.nv, -1))


__all__ = ["FRICTION_KINDS", "PARAMETER_KINDS", "body_links", "inertial_parameters", "parameter_names", "regressor"]
