"""Loads carried by a robot: attach a mass to a link and get a new robot.

The payload is written into the robot's URDF (a link welded to the carrying link), so the
new robot is an ordinary robot: Pinocchio and the reference both see it, ``robot.urdf``
shows it, and viewers draw it.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Sequence

import numpy as np

from robodyn.dynamics.loading import rebuild
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import FrameError, InputError
from robodyn.urdf.edit import inertial_element, weld_link


def attach_payload(
    robot: Robot,
    link: str,
    mass: float,
    *,
    com: Sequence[float] = (0.0, 0.0, 0.0),
    inertia: np.ndarray | None = None,
    name: str = "payload",
) -> Robot:
    """A copy of ``robot`` carrying a payload rigidly attached to ``link``.

    Args:
        robot: The robot.
        link: The URDF link that carries it (e.g. ``"end_effector"``).
        mass: Payload mass in [kg] (> 0).
        com: Payload centre of mass in the link's frame, in [m].
        inertia: 3×3 inertia about its centre of mass in [kg m²]; default a solid sphere
            of 3 cm radius.
        name: Name of the payload link (unique in the robot).

    Raises:
        FrameError: If the robot has no such link; ``StaticFrameError`` (a FrameError) if
            no joint moves it (the payload would change no torque).
        InputError: For a non-positive mass or a bad inertia.
    """
    if link not in robot.spec.links:
        raise FrameError(link, robot.name)
    robot.task_frame(link, "a payload")
    if not (np.isfinite(mass) and mass > 0):
        raise InputError("mass", "a positive number of kg", repr(mass))
    centre = np.asarray(com, dtype=float)
    inertia = np.eye(3) * (0.4 * mass * 0.03**2) if inertia is None else np.asarray(inertia, dtype=float)
    if centre.shape != (3,) or inertia.shape != (3, 3) or not (np.isfinite(centre).all() and np.isfinite(inertia).all()):
        raise InputError(
            "com and inertia", "3 finite values and a finite 3×3 matrix", f"shapes {centre.shape} and {inertia.shape}"
        )
    payload_link = ET.Element("link", name=name)
    payload_link.append(inertial_element(mass, centre, inertia))
    visual = ET.SubElement(payload_link, "visual")
    ET.SubElement(visual, "origin", xyz=" ".join(repr(float(x)) for x in centre), rpy="0 0 0")
    ET.SubElement(ET.SubElement(visual, "geometry"), "sphere", radius="0.03")
    text = weld_link(robot.spec, link, payload_link)
    return rebuild(robot, urdf=text, label=f"{robot.name}+{name}")
