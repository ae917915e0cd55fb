"""Joint dynamics beyond the rigid bodies: viscous damping, Coulomb friction and armature.

One definition for all of robodyn (simulation, ``Robot.inverse_dynamics(...,
joint_friction=True)``, identification's friction columns), per degree of freedom:

- **viscous damping** ``b >= 0`` (URDF ``<dynamics damping>``, MJCF ``damping``): the joint
  torque ``−b q̇``, in [N m s/rad] or [N s/m];
- **Coulomb friction** ``f >= 0`` (URDF ``<dynamics friction>``, MJCF ``frictionloss``): the
  torque ``−f sign(q̇)`` while the joint slides, in [N m] or [N]; at rest it holds the joint
  as long as the other torques stay within ``±f`` (the simulation's stiction model,
  :mod:`robodyn.sim.joint_friction`); a formula of the state alone takes ``sign(0) = 0``;
- **armature** ``a >= 0`` (rotor inertia reflected to the joint: MJCF ``armature``,
  ``load(armature={joint: value})`` added to the file's): ``M(q) + diag(a)`` and
  ``tau + a q̈``, in [kg m²] or [kg]. It is Pinocchio's ``model.armature``, which CRBA,
  RNEA and ABA include, so every dynamics call of a :class:`~robodyn.dynamics.robot.Robot`
  does; so does the kinetic energy ``½ q̇ᵀ M q̇`` (as MuJoCo's).

The robot's Pinocchio model carries the values of its degrees of freedom in
``model.damping``, ``model.friction`` and ``model.armature`` (a floating base's six: 0).

Mimic joints (``q_m = k q_s + offset``) keep their own values and act on their source
through the mimic map: the source's degree of freedom gets ``b_s + k² b_m``,
``f_s + |k| f_m`` and ``a_s + k² a_m`` (the torques ``Sᵀ(−b ⊙ S q̇)``, ``Sᵀ(−f ⊙
sign(S q̇))`` and the inertia ``Sᵀ diag(a) S`` of the joints moving together). The model
with every joint free (:mod:`robodyn.dynamics.mimic`) carries each joint's own values.
A locked joint is a fixed joint: its values go with it.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import replace

import numpy as np
import pinocchio as pin

from robodyn.common.text import quoted
from robodyn.dynamics.mimic import MimicExpansion
from robodyn.dynamics.options import LoadOptions
from robodyn.exceptions import InputError
from robodyn.urdf.validation import URDFSpec

#: The per-joint quantities, as named on :class:`~robodyn.urdf.spec.JointSpec` and ``pin.Model``.
QUANTITIES = ("damping", "friction", "armature")
#: Joint names listed at most in a message.
_LISTED = 30


def apply_joint_dynamics(
    spec: URDFSpec, model: pin.Model, mimic: MimicExpansion | None, options: LoadOptions, label: str
) -> URDFSpec:
    """Put the joints' damping, friction and armature into the Pinocchio models.

    Args:
        spec: The validated description (its joints' ``damping``, ``friction``, ``armature``).
        model: The robot's model (mimic joints folded), changed in place.
        mimic: The model with every joint free and its map, or ``None``; changed in place.
        options: The load options (``armature``: added to the description's, by joint name;
            ``lock``: joints made fixed, whose armature is dropped with them).
        label: The robot's source, for messages.

    Returns:
        The description with the added armature in its joints.

    Raises:
        InputError: For ``armature`` naming no moving joint (the message lists them) or a
            value that is not a finite number >= 0.
    """
    spec = with_armature(spec, options.armature, locked=[name for name, _ in options.lock], label=label)
    effective = dof_values(spec, model)
    model.damping, model.friction, model.armature = effective
    if mimic is not None:
        full = mimic.model
        own = {name: np.zeros(full.nv) for name in QUANTITIES}
        for name, joint in spec.joints.items():
            if joint.type != "fixed" and full.existJointName(name):
                index = full.joints[full.getJointId(name)].idx_v
                for quantity in QUANTITIES:
                    own[quantity][index] = getattr(joint, quantity)
        full.damping, full.friction, full.armature = own["damping"], own["friction"], own["armature"]
    return spec


def with_armature(
    spec: URDFSpec, armature: Iterable[tuple[str, float]], *, locked: Iterable[str] = (), label: str = "robot"
) -> URDFSpec:
    """``spec`` with ``armature`` (``(joint name, value)`` pairs) added to its joints' armature.

    Args:
        spec: The validated URDF.
        armature: ``(joint name, value)`` pairs, values in [kg m²] / [kg].
        locked: Names of the locked joints.
        label: The file or robot name, for the error.

    Raises:
        InputError: For a name that is no moving joint (nor a locked one, whose armature
            goes with the lock) or a value that is not a finite number >= 0.
    """
    pairs = list(armature)
    if not pairs:
        return spec
    moving = [name for name, joint in spec.joints.items() if joint.type != "fixed"]
    frozen = set(locked)
    joints = dict(spec.joints)
    for name, value in pairs:
        if not (isinstance(value, int | float) and math.isfinite(value) and value >= 0):
            raise InputError(f"armature[{quoted(name)}]", "a finite number >= 0 in [kg m²] or [kg]", repr(value))
        if name in frozen and name not in moving:
            continue  # a locked joint: fixed, its armature goes with it
        if name not in moving:
            listed = ", ".join(quoted(joint) for joint in moving[:_LISTED]) + (", …" if len(moving) > _LISTED else "")
            raise InputError("armature", f"keyed by moving joints of robot {quoted(spec.name)} ({listed})", quoted(name))
        joints[name] = replace(joints[name], armature=joints[name].armature + float(value))
    return replace(spec, joints=joints)


def dof_values(spec: URDFSpec, model: pin.Model) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Damping, friction and armature per degree of freedom of ``model`` (mimic joints
    folded onto their sources, see the module docstring), each shape (nv,).

    Args:
        spec: The validated URDF (``<dynamics>`` and armature of its joints).
        model: Its Pinocchio model.
    """
    values = {quantity: np.zeros(model.nv) for quantity in QUANTITIES}
    for name, joint in spec.joints.items():
        if joint.type == "fixed":
            continue
        source, multiplier = (name, 1.0) if joint.mimic is None else (joint.mimic.joint, joint.mimic.multiplier)
        if not model.existJointName(source):
            continue
        index = model.joints[model.getJointId(source)].idx_v
        values["damping"][index] += multiplier**2 * joint.damping
        values["friction"][index] += abs(multiplier) * joint.friction
        values["armature"][index] += multiplier**2 * joint.armature
    return values["damping"], values["friction"], values["armature"]


def friction_torque(damping: np.ndarray, friction: np.ndarray, v: np.ndarray) -> np.ndarray:
    """The joints' friction torque ``−b q̇ − f sign(q̇)`` (``sign(0) = 0``), shape of ``v``
    ((nv,) or (N, nv)), in [N m] or [N].

    Args:
        damping: Viscous coefficients ``b``, shape (nv,), in [N m s/rad] / [N s/m].
        friction: Coulomb friction ``f``, shape (nv,), in [N m] / [N].
        v: Velocity, shape (nv,) or (N, nv), in [rad/s] / [m/s].
    """
    return -damping * v - friction * np.sign(v)


__all__ = ["QUANTITIES", "apply_joint_dynamics", "dof_values", "friction_torque", "with_armature"]
