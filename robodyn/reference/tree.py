"""The kinematic tree the reference works on, read from the URDF with yourdfpy.

The URDF first passes robodyn's strict validator (:mod:`robodyn.urdf.validation`); yourdfpy then
reads it and this module turns it into a list of rigid :class:`Body` objects, one for each
moving joint:

- links welded to a body by fixed joints are merged into it (masses added, centres of
  mass averaged, inertias moved with the parallel-axis theorem), and the fixed joints
  between two moving joints are folded into the constant transform ``origin``;
- the bodies are in topological order (a parent before its children), so forward
  kinematics is one pass;
- joint axes are normalised (as the validator requires of both implementations);
- a ``<mimic>`` joint stays a body of its own; :attr:`KinematicTree.selection` maps the
  independent coordinates ``q`` onto the coordinate of every body
  (``theta = selection @ q + offset``);
- a joint's **armature** ``a`` (``JointSpec.armature``: rotor inertia reflected to the
  joint) is a body of its own, after all the others: a massless rotor of inertia
  ``diag(0, 0, a)`` spinning about a fixed ``z`` axis at the joint's rate (its selection
  row is the joint's). Its kinetic energy is ``½ a θ̇²`` whatever the other joints do, it
  has no weight and no Coriolis term, so every method that sums over bodies (Lagrangian,
  Newton–Euler, composite bodies) gets ``M + Sᵀ diag(a) S`` and ``tau + Sᵀ(a θ̈)``, mimic
  joints' rotors included, without knowing of armature. (For a prismatic joint the
  rotor's "angle" is the joint's position in [m], ``a`` in [kg]: the same ``½ a ẋ²``.)

Nothing here imports Pinocchio.
"""

from __future__ import annotations

import io
import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, replace

import numpy as np
import yourdfpy

from robodyn.common.text import quoted
from robodyn.exceptions import InputError
from robodyn.urdf.validation import URDFSpec

#: The six virtual joints of a floating base: translations then rotations about the base
#: frame's x, y, z axes (the root link is carried by the last).
VIRTUAL_JOINTS = ("root_tx", "root_ty", "root_tz", "root_rx", "root_ry", "root_rz")


@dataclass(frozen=True)
class Body:
    """A rigid body carried by one moving joint.

    Attributes:
        joint: Name of the joint that moves it.
        link: Name of the joint's child link (the body's frame).
        parent: Index of the parent body, or -1 when the parent is the fixed root.
        origin: 4×4 transform from the parent body's frame to the joint frame (constant).
        axis: Unit joint axis in the joint frame.
        revolute: True for revolute/continuous joints, false for prismatic ones.
        mass: Total mass in [kg] of the links welded together.
        com: Centre of mass in the body frame, in [m].
        inertia: 3×3 inertia about the centre of mass, body-frame axes, in [kg m²].
        rotor: Whether it is the rotor of a joint's armature (see the module docstring).
    """

    joint: str
    link: str
    parent: int
    origin: np.ndarray
    axis: np.ndarray
    revolute: bool
    mass: float
    com: np.ndarray
    inertia: np.ndarray
    rotor: bool = False


@dataclass(frozen=True)
class KinematicTree:
    """The robot as moving bodies, in topological order.

    Attributes:
        name: Robot name.
        bodies: One body per moving joint (mimic joints included).
        joint_names: The independent joints, in the order of ``q`` (bodies' order, mimic
            joints left out).
        selection: Shape (n_bodies, n_joints): ``theta = selection @ q + offset``.
        offset: Shape (n_bodies,).
        ancestors: Boolean (n_bodies, n_bodies): ``ancestors[b, i]`` when body ``i`` is
            body ``b`` or one of its ancestors.
        floating_base: Whether the first six bodies are the virtual joints of a free root.
    """

    name: str
    bodies: list[Body]
    joint_names: list[str]
    selection: np.ndarray
    offset: np.ndarray
    ancestors: np.ndarray
    floating_base: bool = False


def _link_mass_properties(link: yourdfpy.Link) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass, centre of mass and inertia about the centre of mass, in the link frame.

    A link without ``<inertial>`` has none; a massless link keeps the rotational inertia
    its URDF gives (as Pinocchio does).
    """
    inertial = link.inertial
    if inertial is None:
        return 0.0, np.zeros(3), np.zeros((3, 3))
    origin = inertial.origin if inertial.origin is not None else np.eye(4)
    rotation = origin[:3, :3]
    inertia = np.zeros((3, 3)) if inertial.inertia is None else np.asarray(inertial.inertia, float)
    return float(inertial.mass or 0.0), origin[:3, 3].copy(), rotation @ inertia @ rotation.T


def _combine(parts: list[tuple[float, np.ndarray, np.ndarray]]) -> tuple[float, np.ndarray, np.ndarray]:
    """Merge rigidly attached masses (each: mass, centre, inertia about its centre)."""
    mass = float(sum(part[0] for part in parts))
    com = np.sum([part[0] * part[1] for part in parts], axis=0) / mass if mass > 0 else np.zeros(3)
    inertia = np.zeros((3, 3))
    for part_mass, part_com, part_inertia in parts:
        d = part_com - com
        inertia += part_inertia + part_mass * (d @ d * np.eye(3) - np.outer(d, d))
    return mass, com, inertia


def build_tree(spec: URDFSpec, text: str, *, floating_base: bool = False) -> KinematicTree:
    """Build the reference's kinematic tree from a validated URDF.

    Args:
        spec: The validated URDF (from :func:`robodyn.urdf.validation.parse_urdf`).
        text: The same URDF text, read again here by yourdfpy.
        floating_base: Give the root link six degrees of freedom: three prismatic then
            three revolute "virtual" joints along the x, y, z axes of the base's own frame
            (see :mod:`robodyn.reference.numeric` for how they map to Pinocchio's state).
    """
    urdf = yourdfpy.URDF.load(io.BytesIO(text.encode("utf-8")), build_scene_graph=False, load_meshes=False)
    bodies = _virtual_bodies(spec.root) if floating_base else []
    bodies = _moving_bodies(urdf, spec.root, bodies)
    independent, selection, offset = _mimic_map(spec, bodies)
    bodies, selection, offset = _with_rotors(spec, bodies, selection, offset)
    ancestors = np.zeros((len(bodies), len(bodies)), dtype=bool)
    for index, body in enumerate(bodies):
        ancestors[index, index] = True
        if body.parent >= 0:
            ancestors[index] |= ancestors[body.parent]
    return KinematicTree(spec.name, bodies, independent, selection, offset, ancestors, floating_base)


def _massless(joint: str, link: str, parent: int, origin: np.ndarray, axis: np.ndarray, revolute: bool) -> Body:
    """A body whose mass properties are filled in once its welded links are known."""
    return Body(joint, link, parent, origin, axis, revolute, 0.0, np.zeros(3), np.zeros((3, 3)))


def _virtual_bodies(root: str) -> list[Body]:
    """The six massless bodies of a floating base's virtual joints (the last carries ``root``)."""
    revolute = (False,) * 3 + (True,) * 3
    return [
        _massless(name, root if index == 5 else name, index - 1, np.eye(4), np.eye(3)[index % 3], revolute[index])
        for index, name in enumerate(VIRTUAL_JOINTS)
    ]


def _moving_bodies(urdf: yourdfpy.URDF, root: str, bodies: list[Body]) -> list[Body]:
    """``bodies`` followed by one body per moving joint of ``urdf``, depth-first from
    ``root`` (a parent before its children), each with the links welded to it merged in."""
    links = {link.name: link for link in urdf.robot.links}
    children: dict[str, list[yourdfpy.Joint]] = {}
    for joint in urdf.robot.joints:
        children.setdefault(joint.parent, []).append(joint)
    bodies = list(bodies)
    # Each entry: (link, transform from the current body's frame to this link's frame,
    # index of the current body).
    stack = [(root, np.eye(4), len(bodies) - 1)]
    welded: dict[int, list[tuple[float, np.ndarray, np.ndarray]]] = {}
    while stack:
        link_name, to_link, body_index = stack.pop()
        mass, com, inertia = _link_mass_properties(links[link_name])
        rotation = to_link[:3, :3]
        welded.setdefault(body_index, []).append((mass, rotation @ com + to_link[:3, 3], rotation @ inertia @ rotation.T))
        for joint in reversed(children.get(link_name, [])):
            origin = joint.origin if joint.origin is not None else np.eye(4)
            if joint.type == "fixed":
                stack.append((joint.child, to_link @ origin, body_index))
                continue
            axis = np.asarray(joint.axis if joint.axis is not None else (1.0, 0.0, 0.0), float)
            bodies.append(
                _massless(
                    joint.name, joint.child, body_index, to_link @ origin, axis / np.linalg.norm(axis), joint.type != "prismatic"
                )
            )
            stack.append((joint.child, np.eye(4), len(bodies) - 1))
    return [
        Body(b.joint, b.link, b.parent, b.origin, b.axis, b.revolute, *_combine(welded.get(index, [])))
        for index, b in enumerate(bodies)
    ]


def _mimic_map(spec: URDFSpec, bodies: list[Body]) -> tuple[list[str], np.ndarray, np.ndarray]:
    """The independent joints (the order of ``q``) and the map ``theta = selection @ q + offset``
    from them to every body's coordinate (a mimic joint follows its source)."""

    def mimic_of(body: Body):
        return None if body.joint in VIRTUAL_JOINTS else spec.joints[body.joint].mimic

    independent = [body.joint for body in bodies if mimic_of(body) is None]
    column_of = {name: column for column, name in enumerate(independent)}
    selection = np.zeros((len(bodies), len(independent)))
    offset = np.zeros(len(bodies))
    for index, body in enumerate(bodies):
        mimic = mimic_of(body)
        if mimic is None:
            selection[index, column_of[body.joint]] = 1.0
        else:
            selection[index, column_of[mimic.joint]] = mimic.multiplier
            offset[index] = mimic.offset
    return independent, selection, offset


def _with_rotors(
    spec: URDFSpec, bodies: list[Body], selection: np.ndarray, offset: np.ndarray
) -> tuple[list[Body], np.ndarray, np.ndarray]:
    """``bodies`` and the map to them with one rotor body appended for every joint with
    armature (see the module docstring), its selection row the joint's body's."""
    rotors, rows = [], []
    for index, body in enumerate(bodies):
        joint = spec.joints.get(body.joint) if body.joint not in VIRTUAL_JOINTS else None
        if joint is None or joint.armature == 0:
            continue
        link = f"armature of {body.joint}"
        while link in spec.links:  # never a link of the robot's (kinematics look bodies up by link)
            link += "'"
        inertia = np.diag([0.0, 0.0, float(joint.armature)])
        rotors.append(
            Body(body.joint, link, -1, np.eye(4), np.array([0.0, 0.0, 1.0]), True, 0.0, np.zeros(3), inertia, rotor=True)
        )
        rows.append(selection[index])
    if not rotors:
        return bodies, selection, offset
    return [*bodies, *rotors], np.vstack([selection, *rows]), np.concatenate([offset, np.zeros(len(rotors))])


def spec_with_armature(spec: URDFSpec, armature: Mapping[str, float], *, locked: Iterable[str] = ()) -> URDFSpec:
    """``spec`` with ``armature`` (``{joint name: value}``) added to its joints' armature
    (a locked joint's is dropped with it).

    Args:
        spec: The validated URDF.
        armature: Armature by joint name, in [kg m²] / [kg].
        locked: Names of the locked joints.

    Raises:
        InputError: For a name that is no moving joint of ``spec``, or a value that is not a
            finite number >= 0.
    """
    joints = dict(spec.joints)
    moving = [name for name, joint in joints.items() if joint.type != "fixed"]
    for name, value in armature.items():
        if not (isinstance(value, int | float) and math.isfinite(value) and value >= 0):
            raise InputError(f"armature[{quoted(name)}]", "a finite number >= 0", repr(value))
        if name in locked and name not in moving:
            continue
        if name not in moving:
            listed = ", ".join(quoted(joint) for joint in moving)
            raise InputError("armature", f"keyed by moving joints of {quoted(spec.name)} ({listed})", quoted(name))
        joints[name] = replace(joints[name], armature=joints[name].armature + float(value))
    return replace(spec, joints=joints)
