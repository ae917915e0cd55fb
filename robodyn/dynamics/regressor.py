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
- Optional **friction** columns come after all bodies: one viscous coefficient a degree
  of freedom (``fv``, torque ``fv·v`` in [N m s/rad] or [N s/m]), then one Coulomb
  coefficient a degree of freedom (``fc``, torque ``fc·sign(v)`` in [N m] or [N]), in the
  order of ``robot.dofs`` (named by them: ``fv[joint1]``, a floating base's ``fv[base.x]``).
  They are the joints' damping ``b`` and Coulomb friction ``f`` of
  :mod:`robodyn.dynamics.joint_dynamics` (``<dynamics damping friction>``): the robot's own
  friction parameters are its :attr:`~robodyn.Robot.joint_damping` and
  :attr:`~robodyn.Robot.joint_friction` (zero where the file gives none).
- The joints' **armature** is no parameter of the regressor: it is a known torque
  ``a ⊙ q̈`` (:attr:`~robodyn.Robot.joint_armature`), so that
  ``Y π + armature ⊙ q̈ = robot.inverse_dynamics`` (``joint_friction=True`` with the
  friction columns; ``sign(0) = 0`` in both).

The columns for a body are exactly those of Pinocchio's ``computeJointTorqueRegressor``
(``Y = Sᵀ Y_full`` through the mimic map for robots with mimic joints, where Pinocchio's
regressor is evaluated on the expanded model; locked joints are fixed joints, so their
links are welded). ``Y π = robot.inverse_dynamics`` to rounding for a robot without armature.

:func:`regressor` and :func:`inertial_parameters` are functions of the robot's
:class:`~robodyn.dynamics.handle.ModelHandle` (a :class:`robodyn.Robot` is taken too, for
its handle); the names (:func:`body_links`, :func:`parameter_names`) need the robot's
URDF and degrees of freedom.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np
import pinocchio as pin

from robodyn.dynamics.dofs import Dof
from robodyn.dynamics.handle import ModelHandle
from robodyn.urdf.validation import URDFSpec

#: Names of a body's 10 standard parameters, in order.
PARAMETER_KINDS = ("m", "mx", "my", "mz", "Ixx", "Ixy", "Iyy", "Ixz", "Iyz", "Izz")
#: Names of a joint's friction parameters, in order (all viscous columns, then all Coulomb).
FRICTION_KINDS = ("fv", "fc")


class DescribedModel(Protocol):
    """A model handle with the description it was built from (a :class:`robodyn.Robot`)."""

    @property
    def handle(self) -> ModelHandle: ...
    @property
    def spec(self) -> URDFSpec: ...
    @property
    def dofs(self) -> tuple[Dof, ...]: ...


def _handle(model: ModelHandle | DescribedModel) -> ModelHandle:
    """The handle itself, or a robot's handle."""
    return model if isinstance(model, ModelHandle) else model.handle


def body_links(robot: DescribedModel) -> list[str]:
    """The URDF link that names each body (the moving joint's child link), in order.

    Args:
        robot: The robot (its handle and URDF).
    """
    handle, spec = robot.handle, robot.spec
    model = handle.model if handle.mimic is None else handle.mimic.model
    links = []
    for joint_id in range(1, model.njoints):
        name = model.names[joint_id]
        links.append(spec.joints[name].child if name in spec.joints else spec.root)
    return links


def parameter_names(robot: DescribedModel, *, friction: bool = False) -> list[str]:
    """Names of the standard parameters, ``"kind[link]"`` (e.g. ``"Izz[link1]"``), in the
    order of :func:`regressor`'s columns (friction: ``"fv[dof]"``, ``"fc[dof]"`` with the
    degrees of freedom's names, :attr:`robodyn.Robot.dofs`: a floating base's six are
    ``base.x`` … ``base.rz``).

    Args:
        robot: The robot (its handle, URDF and degrees of freedom).
    """
    names = [f"{kind}[{link}]" for link in body_links(robot) for kind in PARAMETER_KINDS]
    if friction:
        names += [f"{kind}[{dof.name}]" for kind in FRICTION_KINDS for dof in robot.dofs]
    return names


def _bodies(handle: ModelHandle) -> pin.Model:
    """The model whose joints are the bodies (the expanded one for mimic joints)."""
    return handle.model if handle.mimic is None else handle.mimic.model


def inertial_parameters(model: ModelHandle | DescribedModel, *, friction: bool = False) -> np.ndarray:
    """The standard parameters π of the robot's model (its URDF), so that ``Y π = tau``.

    Args:
        model: The robot's model handle (or the robot).
        friction: Append the friction parameters: the joints' damping ``b`` then Coulomb
            friction ``f`` (the model's ``model.damping``, ``model.friction``).

    Returns:
        Shape (10·n_bodies,) (``+ 2·nv`` with friction), units as in the module docstring.
    """
    handle = _handle(model)
    bodies = _bodies(handle)
    values = np.concatenate([bodies.inertias[i].toDynamicParameters() for i in range(1, bodies.njoints)])
    if not friction:
        return values
    return np.concatenate([values, np.asarray(handle.model.damping, float), np.asarray(handle.model.friction, float)])


def regressor(
    model: ModelHandle | DescribedModel, q: np.ndarray, v: np.ndarray, a: np.ndarray, *, friction: bool = False
) -> np.ndarray:
    """The regressor ``Y(q, v, a)`` with ``tau = Y π`` (π from :func:`inertial_parameters`).

    Args:
        model: The robot's model handle (or the robot).
        q: Configuration, shape (nq,) or (N, nq).
        v: Velocity, shape (nv,) or (N, nv).
        a: Acceleration, shape (nv,) or (N, nv).
        friction: Append the viscous and Coulomb friction columns (``v`` and ``sign(v)``).

    Returns:
        Shape (nv, 10·n_bodies) or (N, nv, 10·n_bodies) (``+ 2·nv`` columns with friction).

    Raises:
        InputError: For states of the wrong shape or with non-finite values.
    """
    handle = _handle(model)
    nv = handle.nv
    (q, v, a), batch = handle.validate(q=q, v=v, a=a)
    rows = [_one(handle, *state) for state in zip(np.atleast_2d(q), np.atleast_2d(v), np.atleast_2d(a), strict=True)]
    result = np.stack(rows) if rows else np.zeros((0, nv, 10 * (_bodies(handle).njoints - 1)))
    if friction:
        v2 = np.atleast_2d(v)
        eye = np.eye(nv)
        columns = np.concatenate([eye[None] * v2[:, None, :], eye[None] * np.sign(v2)[:, None, :]], axis=2)
        result = np.concatenate([result, columns], axis=2)
    return result if batch else result[0]


def _one(handle: ModelHandle, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
    # (the Python binding returns a 1-D array when nv = 1: reshape)
    mimic = handle.mimic
    if mimic is None:
        return np.array(pin.computeJointTorqueRegressor(handle.model, handle.data, q, v, a)).reshape(handle.nv, -1)
    full = pin.computeJointTorqueRegressor(mimic.model, mimic.data, mimic.q(q), mimic.selection @ v, mimic.selection @ a)
    return mimic.selection.T @ np.reshape(full, (mimic.model.nv, -1))


__all__ = [
    "FRICTION_KINDS",
    "PARAMETER_KINDS",
    "DescribedModel",
    "body_links",
    "inertial_parameters",
    "parameter_names",
    "regressor",
]
