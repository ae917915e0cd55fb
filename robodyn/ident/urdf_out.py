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
        standard: Standard parameters over ``columns`` (friction entries are ignored: URDF
            has no place the dynamics read them from).
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
    text = ET.tostring(root, encoding="unicode")
    written = inertial_parameters(rebuild(robot, urdf=text, label=f"{robot.name} (identified)"))
    if not np.allclose(written, full, rtol=1e-9, atol=1e-9 * np.abs(full).max()):
        worst = float(np.max(np.abs(written - full)))
        raise IdentificationError(
            robot.name, f"the written URDF does not reproduce the identified parameters (error {worst:.3g})"
        )
    return text


__all__ = ["identified_urdf"]
