"""Physical consistency of a URDF's mass properties (part of the validation).

The checks add problems to the validator's reader (``reader.error`` / ``reader.warn``).
This module does not import Pinocchio.
"""

from __future__ import annotations

import numpy as np

from robodyn.urdf.spec import Inertial, JointSpec

#: Relative tolerance on the triangle inequality of principal moments of inertia.
TRIANGLE_TOLERANCE = 1e-6
#: Smallest length that matters for a body's inertia, in [m]: a principal moment is
#: compared with ``mass × BODY_SCALE²`` (see :func:`check_inertias`).
BODY_SCALE = 1e-3


def _fmt(values: np.ndarray) -> str:
    return "(" + ", ".join(f"{value:.4g}" for value in values) + ")"


def moving_links(root: str, children: dict[str, list[JointSpec]], floating_base: bool) -> set[str]:
    """Links that move: below a moving joint, or every link on a floating base (linear time).

    Args:
        root: The root link.
        children: Child joints of each link (:func:`robodyn.urdf.spec.child_index`).
        floating_base: Whether the root is free (then every link moves).
    """
    moving = set()
    frontier = [(root, floating_base)]
    while frontier:
        link, moves = frontier.pop()
        if moves:
            moving.add(link)
        frontier += [(j.child, moves or j.type != "fixed") for j in children.get(link, ())]
    return moving


def check_inertias(reader, links: dict[str, Inertial | None], moving: set[str], check_inertia: bool, strict: bool) -> None:
    """Physical consistency of each link's inertia.

    On a link that moves, an inertia that is not positive semi-definite is an error (a
    warning with ``check_inertia=False``); one that is positive semi-definite but breaks
    the triangle inequality is a loud warning (peers load it), an error when ``strict``.
    The tolerance is relative to the body's scale: ``1e-9`` of the larger of its largest
    principal moment and ``mass × (1 mm)²``, so rounding noise of ±1e-35 kg m² on a
    point-like body is not a negative moment.

    Args:
        reader: The validator's reader, collecting problems (``reader.error`` / ``reader.warn``).
        links: Each link's inertial (``None``: none).
        moving: The links that move (:func:`moving_links`).
        check_inertia: An impossible inertia on a moving link is an error (else a warning).
        strict: A broken triangle inequality is an error (else a warning).
    """
    for name, inertial in links.items():
        if inertial is None:
            continue
        where = f'link "{name}"'
        if inertial.mass == 0:
            if np.abs(inertial.inertia).max() > 0:
                reader.warn(where, "has rotational inertia but no mass (no rigid body does); both dynamics keep the inertia")
            continue
        is_moving = name in moving
        moments = np.linalg.eigvalsh(inertial.inertia)
        tolerance = 1e-9 * max(abs(moments).max(), inertial.mass * BODY_SCALE**2)
        if moments[0] < -tolerance:
            report = reader.error if check_inertia and is_moving else reader.warn
            report(where, f"inertia must be positive semi-definite (principal moments {_fmt(moments)} kg m²)")
        elif moments[2] > (moments[0] + moments[1]) * (1 + TRIANGLE_TOLERANCE) + tolerance:
            rule = f"principal moments of inertia {_fmt(moments)} kg m² break the triangle inequality (no rigid body has them)"
            if strict and is_moving:
                reader.error(where, rule)
            else:
                reader.warn(where, rule, loud=is_moving and check_inertia)
        elif moments[2] < 1e-10 * inertial.mass:
            reader.warn(where, f"tiny inertia (largest principal moment {moments[2]:.3g} kg m²) for mass {inertial.mass:.3g} kg")
        elif is_moving and moments[0] <= tolerance:
            reader.warn(where, f"singular inertia (principal moments {_fmt(moments)} kg m²): the mass matrix may be singular")


def check_moving_masses(reader, spec_links: dict, joints: dict[str, JointSpec], children: dict) -> None:
    """Warn about moving joints that carry a massless leaf body (linear time: each link is
    visited once, by the moving joint whose rigid body holds it).

    Args:
        reader: The validator's reader, collecting problems (``reader.error`` / ``reader.warn``).
        spec_links: Each link's inertial (``None``: none).
        joints: The joints by name.
        children: Child joints of each link (:func:`robodyn.urdf.spec.child_index`).
    """
    for joint in joints.values():
        if joint.type == "fixed":
            continue
        # The rigid body a moving joint carries: its child plus links welded to it.
        mass, carries_joint, frontier = 0.0, False, [joint.child]
        while frontier:
            link = frontier.pop()
            inertial = spec_links.get(link)
            mass += inertial.mass if inertial is not None else 0.0
            for child in children.get(link, ()):
                if child.type == "fixed":
                    frontier.append(child.child)
                else:
                    carries_joint = True
        if mass == 0 and not carries_joint:
            reader.warn(f'joint "{joint.name}"', "moves a massless leaf body: its mass matrix is singular")
