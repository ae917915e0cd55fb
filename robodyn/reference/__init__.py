"""The independent Lagrangian reference: robot dynamics from a URDF without Pinocchio.

A second implementation of the equations of motion, written from the lecture's method
(kinetic and potential energy of every link, ``tau = d/dt ∂L/∂q̇ − ∂L/∂q``) and used to
verify Pinocchio's numbers. It reads the URDF itself (robodyn's strict validator, then
yourdfpy), computes its own kinematics, and shares nothing with Pinocchio: nothing in this
package imports it, and a test runs it in a process where Pinocchio cannot be imported.

- :func:`load` gives a :class:`~robodyn.reference.numeric.ReferenceRobot` (numpy, any size,
  stacks of states) with the same method names as :class:`robodyn.Robot`.
- :mod:`robodyn.reference.rp_closed_form` is the RP arm's closed form, written by hand.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence

import numpy as np

from robodyn.common.constants import STANDARD_GRAVITY
from robodyn.common.inputs import as_state
from robodyn.reference.numeric import ReferenceRobot
from robodyn.reference.tree import KinematicTree, build_tree, spec_with_armature
from robodyn.urdf.sources import locked_source, resolve_source, with_file_dynamics
from robodyn.urdf.validation import parse_urdf


def load(
    source: str | os.PathLike,
    *,
    gravity: Sequence[float] | None = None,
    check_inertia: bool = True,
    lock: dict[str, float] | None = None,
    floating_base: bool = False,
    xacro_args: Mapping[str, str] | None = None,
    packages: Mapping[str, str] | None = None,
    armature: Mapping[str, float] | None = None,
) -> ReferenceRobot:
    """Load the reference model of a robot.

    Args:
        source: As for :func:`robodyn.load`: a URDF path, URDF text, a zoo name or a
            generated robot's name.
        gravity: Gravity in the world frame, in [m/s²]; default the file's (MJCF
            ``<option gravity>``, as :func:`robodyn.load`), else ``(0, 0, -9.81)``.
        check_inertia, lock: As for :func:`robodyn.load`.
        floating_base: Give the root six degrees of freedom (Pinocchio's free-flyer
            convention for ``q`` and ``v``); unlike :func:`robodyn.load` the default is
            a fixed base whatever the source.
        xacro_args, packages: As for :func:`robodyn.load` (a xacro or MJCF source is read
            by robodyn's own readers, never by Pinocchio).
        armature: Rotor inertia added at joints, ``{joint name: value in [kg m²] or
            [kg]}``, on top of the description's (as for :func:`robodyn.load`).

    Raises:
        UnknownRobotError, URDFError: As :func:`robodyn.load`.
    """
    resolved = resolve_source(source, xacro_args=xacro_args, packages=packages)
    if lock:
        resolved = locked_source(resolved, lock, floating_base=floating_base, check_inertia=check_inertia)
    spec = parse_urdf(
        resolved.text, resolved.label, floating_base=floating_base, check_inertia=check_inertia, **resolved.mesh_context
    )
    spec = with_file_dynamics(spec, resolved.label)
    spec = spec_with_armature(spec, armature or {}, locked=lock or {})
    tree = build_tree(spec, resolved.text, floating_base=floating_base)
    name = spec.name if resolved.name == "robot" else resolved.name
    default = STANDARD_GRAVITY if resolved.gravity is None else resolved.gravity
    gravity_vector = np.array(default) if gravity is None else as_state(gravity, "gravity", 3)
    return ReferenceRobot(tree, name=name, urdf=resolved.text, spec=spec, gravity=gravity_vector)


__all__ = ["KinematicTree", "ReferenceRobot", "build_tree", "load"]
