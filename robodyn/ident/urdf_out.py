"""Writing identified standard parameters back into the robot's URDF.

A body of the regressor is a moving joint's child link plus every link welded to it by
fixed joints (:mod:`robodyn.dynamics.regressor`); its identified parameters belong to the
whole rigid body. They are written on the child link (``<inertial>`` at the centre of
mass, inertia about it, axes of the link frame) and the ``<inertial>`` of the welded links
is removed, so that the new URDF's merged body has exactly the identified parameters
(checked by loading it again). Kinematics, visuals and collisions are untouched. For a
robot loaded with ``lock=`` the URDF written is the locked one (those joints are fixed).
"""

from __future__ import annotations

import copy
import xml.etree.ElementTree as ET

import numpy as np

from robodyn.dynamics.loading import rebuild
from robodyn.dynamics.regressor import body_links, inertial_parameters
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import IdentificationError
from robodyn.urdf.edit import inertial_element

#: Masses below this, in [kg], are written as a massless link (no centre of mass).
MASSLESS = 1e-12


def _welded(robot: Robot, link: str) -> list[str]:
    """Links welded to ``link`` by chains of fixed joints (``link`` excluded)."""
    found, stack = [], [link]
    while stack:
        for joint in robot.spec.child_joints(stack.pop()):
            if joint.type == "fixed":
                found.append(joint.child)
                stack.append(joint.child)
    return found


def _inertial(parameters: np.ndarray) -> ET.Element:
    mass, first, inertia = float(parameters[0]), parameters[1:4], parameters[4:10]
    xx, xy, yy, xz, yz, zz = inertia
    about_origin = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
    com = first / mass if mass > MASSLESS else np.zeros(3)
    about_com = about_origin - mass * (com @ com * np.eye(3) - np.outer(com, com))
    return inertial_element(max(mass, 0.0), com, about_com)


def identified_urdf(robot: Robot, standard: np.ndarray, columns: np.ndarray) -> str:
    """The robot's URDF with the identified standard parameters written in.

    Args:
        robot: The nominal robot.
        standard: Standard parameters over ``columns``; identified friction entries are
            written as the joints' ``<dynamics damping friction>`` (a mimic joint keeps
            its own, the source gets the rest: :func:`_write_friction`).
        columns: Their indices in the full standard vector (10 a body).

    Returns:
        URDF text, checked: loading it gives these parameters (to 1e-9 relative).

    Raises:
        IdentificationError: If the written URDF does not reproduce the parameters.
    """
    links = body_links(robot)
    full = inertial_parameters(robot)
    full[columns[columns < full.size]] = np.asarray(standard)[columns < full.size]
    root = copy.deepcopy(robot.spec.xml)
    nodes = {node.get("name"): node for node in root.findall("link")}
    changed = sorted({int(c) // 10 for c in columns if c < full.size})
    for body in changed:
        for name in [links[body], *_welded(robot, links[body])]:
            for old in nodes[name].findall("inertial"):
                nodes[name].remove(old)
        nodes[links[body]].insert(0, _inertial(full[10 * body : 10 * body + 10]))
    friction = np.asarray(standard)[columns >= full.size]
    if friction.size:
        _write_friction(robot, root, friction)
    text = ET.tostring(root, encoding="unicode")
    rebuilt = rebuild(robot, urdf=text, label=f"{robot.name} (identified)")
    written = inertial_parameters(rebuilt)
    if not np.allclose(written, full, rtol=1e-9, atol=1e-9 * np.abs(full).max()):
        worst = float(np.max(np.abs(written - full)))
        raise IdentificationError(
            robot.name, f"the written URDF does not reproduce the identified parameters (error {worst:.3g})"
        )
    if friction.size and not np.allclose(np.concatenate([rebuilt.joint_damping, rebuilt.joint_friction]), friction, atol=1e-9):
        raise IdentificationError(robot.name, "the written URDF's <dynamics> do not give the identified friction")
    return text


def _write_friction(robot: Robot, root: ET.Element, friction: np.ndarray) -> None:
    """Write identified damping and Coulomb friction (``friction``: all ``b`` then all
    ``f``, one a degree of freedom) as each joint's ``<dynamics>``. A degree of freedom's
    values include its mimic joints' (``k² b_m``, ``|k| f_m``), which stay as the file has
    them: its own joint gets the rest.

    Raises:
        IdentificationError: For friction on a floating base's coordinates, or a source
            joint's share that would be negative.
    """
    nv = robot.nv
    damping, coulomb = friction[:nv].copy(), friction[nv:].copy()
    index_of = {dof.name: dof.index for dof in robot.dofs if not dof.is_base}
    for joint in robot.spec.joints.values():
        if joint.mimic is not None and joint.type != "fixed" and joint.mimic.joint in index_of:
            index = index_of[joint.mimic.joint]
            damping[index] -= joint.mimic.multiplier**2 * joint.damping
            coulomb[index] -= abs(joint.mimic.multiplier) * joint.friction
    nodes = {node.get("name"): node for node in root.findall("joint")}
    for dof in robot.dofs:
        b, f = float(damping[dof.index]), float(coulomb[dof.index])
        if dof.is_base:
            if abs(b) > 1e-12 or abs(f) > 1e-12:
                raise IdentificationError(robot.name, f"friction on the floating base's {dof.name} has no place in a URDF")
            continue
        if b < -1e-12 or f < -1e-12:
            raise IdentificationError(
                robot.name, f"joint {dof.joint!r}: its mimic joints' friction exceeds the identified b={b:.3g}, f={f:.3g}"
            )
        for old in nodes[dof.joint].findall("dynamics"):
            nodes[dof.joint].remove(old)
        ET.SubElement(nodes[dof.joint], "dynamics", damping=repr(max(b, 0.0)), friction=repr(max(f, 0.0)))


__all__ = ["identified_urdf"]
