"""What a simulation run on the ground may ask, checked when its plan is made.

The contact step (:mod:`robodyn.sim.contact`) is semi-implicit Euler at the velocity level
with the controller sampled once a step; it has no momentum observer. Enforced joint limits
are rows of its contact problem (:mod:`robodyn.sim.contact_limits`). A plan asking for
another integrator, a control period or an observer with a ground is refused, naming the
parameter, as is a start with a contact point deeper than :data:`START_PENETRATION` below
the ground, a link that is no contact point deeper than :data:`BURIED_DEPTH` (the contact
points are not the robot's lowest: talos's only collision box is its head camera) or a joint
further than that past an enforced limit.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pinocchio as pin

from robodyn.common.text import printable
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError
from robodyn.sim.contact import contact_kinematics
from robodyn.sim.contact_limits import LimitRows
from robodyn.sim.ground import ContactPoint, Contacts, Ground, collision_points, contact_points

#: Deepest a contact point may start below the ground, in [m] (deeper: refused; the
#: push-out of a deep penetration would launch the robot).
START_PENETRATION = 1e-3


def check_contact_run(
    robot: Robot,
    ground: Ground | None,
    contacts: str | Sequence[str | ContactPoint],
    *,
    q0: np.ndarray,
    integrator: str,
    every: int | None,
    limits: str,  # every mode: "enforce" puts the limits in the contact problem
    observer: object,
) -> Contacts | None:
    """The contact points of a run on ``ground`` (``None`` without one), or an
    :class:`InputError` naming what a contact run does not do.

    Args:
        robot: The simulated robot.
        ground: The plane the run stands on (:class:`~robodyn.sim.ground.Ground`); ``None``:
            no ground (then ``contacts`` must be the default ``"collision"``).
        contacts: The points that touch the ground (as for
            :func:`~robodyn.sim.ground.contact_points`).
        q0: Initial configuration, shape (nq,).
        integrator: The run's integrator (only ``"semi-implicit-euler"`` with a ground).
        every: Steps between two samples of a held controller; ``None`` or 1 with a ground.
        limits: The limits mode, ``"warn"``, ``"enforce"`` or ``"ignore"`` (``"enforce"``:
            ``q0`` must be within the joint limits).
        observer: The run's momentum observer; ``None`` with a ground.

    Raises:
        InputError: For what a contact run does not do (naming the parameter), a start with
            a contact point, or another link, below the ground, or past an enforced limit.
    """
    if ground is None:
        if not (isinstance(contacts, str) and contacts == "collision"):
            raise InputError("contacts", "given only with a ground", repr(contacts)[:80])
        return None
    if not isinstance(ground, Ground):
        raise InputError("ground", "a robodyn.sim.ground.Ground (a plane, its normal and friction)", repr(ground)[:80])
    refusals = [
        (integrator != "semi-implicit-euler", "integrator", "'semi-implicit-euler' with a ground (the contact step's scheme)", repr(integrator)),
        (every not in (None, 1), "control_period", "the step dt with a ground (the contact step samples the controller each step)", f"{every} steps"),
        (observer is not None, "observer", "none with a ground (the contact step runs no observer)", "an observer"),
    ]  # fmt: skip
    for refused, name, expected, received in refusals:
        if refused:
            raise InputError(name, expected, received)
    if limits == "enforce":
        _check_inside_limits(robot, q0)
    found = contact_points(robot, contacts)
    gaps = contact_kinematics(robot, q0, ground, found.points)[0]
    if gaps.min() < -START_PENETRATION:
        deepest = int(gaps.argmin())
        raise InputError(
            "q0",
            f"a configuration with every contact point above the ground (at most {START_PENETRATION} m below)",
            f"{found.names[deepest]!r} {-gaps[deepest]:.3g} m below",
        )
    buried = buried_links(robot, np.asarray(q0, dtype=float)[None], ground, found)
    if buried:
        shown = ", ".join(f"{printable(link)!r} {depth:.3g} m" for link, depth, _ in buried[:4]) + (
            ", …" if len(buried) > 4 else ""
        )
        raise InputError(
            "contacts",
            f"contact points that hold the robot above the ground at the start (no other link more than {BURIED_DEPTH} m below it)",
            f"{len(buried)} links under it: {shown}",
        )
    return found


def _check_inside_limits(robot: Robot, q0: np.ndarray) -> None:
    """Refuse a start further than :data:`START_PENETRATION` past a joint's position limit
    (enforced, the row's push-back would fling the joint out at ``β`` of it a step)."""
    rows = LimitRows(robot)
    gaps = rows.gaps(q0)
    if len(gaps) and gaps.min() < -START_PENETRATION:
        worst = int(gaps.argmin())
        raise InputError(
            "q0",
            f"a configuration within the joint limits (at most {START_PENETRATION} past one) when they are enforced",
            f"{rows.names[worst]!r} {-gaps[worst]:.3g} past",
        )


#: How many samples of a run :func:`buried_line` looks at (evenly spread, the last included).
BURIED_SAMPLES = 200
#: Depth below the ground [m] a link's origin or collision point may reach unreported
#: (a penetration the contact step tolerates).
BURIED_DEPTH = 1e-3


def buried_links(robot: Robot, q: np.ndarray, ground: Ground, contacts: Contacts) -> list[tuple[str, float, int]]:
    """The links that are not contact points and lie deeper than :data:`BURIED_DEPTH` under
    the ground at some row of ``q`` (k, nq): their origins (links with mass: not the massless
    frames between a planar root's slides) and collision spheres, boxes and capsules; each
    link with its depth in [m] and the first row, deepest first.

    Args:
        robot: The simulated robot.
        q: Configurations, shape (k, nq).
        ground: The ground plane.
        contacts: The run's contact points (their links are left out).
    """
    model, data, frames = robot.model, robot.handle.data, robot.handle.frames
    moving = {name for name in robot.spec.links if name in frames and model.frames[frames[name]].parentJoint != 0}
    links = sorted(moving - {point.link for point in contacts.points})
    shapes = [point for point in collision_points(robot).points if point.link in links]
    bodies = [link for link in links if getattr(robot.spec.links[link], "mass", 0.0) > 0]  # not a joint's massless frame
    depth: dict[str, tuple[float, int]] = {}
    for row, configuration in enumerate(q):
        pin.framesForwardKinematics(model, data, configuration)
        points = [(link, data.oMf[frames[link]].translation) for link in bodies]
        points += [
            (p.link, data.oMf[frames[p.link]].act(np.array(p.position)) - p.radius * np.array(ground.normal)) for p in shapes
        ]
        for link, where in points:
            below = -float(ground.gap(where))
            if below > BURIED_DEPTH:
                depth[link] = (max(depth.get(link, (0.0, row))[0], below), depth.get(link, (0.0, row))[1])
    return sorted(((link, value, row) for link, (value, row) in depth.items()), key=lambda item: -item[1])


def buried_line(robot: Robot, q: np.ndarray, t: np.ndarray, ground: Ground, contacts: Contacts) -> str | None:
    """One warning line naming the links that are not contact points and went under the
    ground in a run (``q`` (N, nq) at times ``t`` (N,) [s]): :func:`buried_links` at
    :data:`BURIED_SAMPLES` samples, each link with its deepest point in [m]; ``None`` when
    none went deeper than :data:`BURIED_DEPTH`.

    Args:
        robot: The simulated robot.
        q: Configurations of the run, shape (N, nq).
        t: Their times, shape (N,), in [s].
        ground: The ground plane.
        contacts: The run's contact points (their links are left out).
    """
    samples = np.unique(np.linspace(0, len(q) - 1, min(len(q), BURIED_SAMPLES)).round().astype(int))
    deepest = buried_links(robot, q[samples], ground, contacts)
    if not deepest:
        return None
    first = float(t[samples[min(row for _, _, row in deepest)]])
    shown = ", ".join(f"{printable(link)!r} {value:.3g} m" for link, value, _ in deepest[:4]) + (
        ", …" if len(deepest) > 4 else ""
    )
    return (
        f"warning: {len(deepest)} link{'s' if len(deepest) > 1 else ''} that are no contact points went under the ground "
        f"(from t = {first:.6g} s; deepest): {shown}: name them as contacts or hold the robot up"
    )


def start_above(
    robot: Robot, q0: np.ndarray, ground: Ground, contacts: str | Sequence[str | ContactPoint], clearance: float = 0.05
) -> tuple[np.ndarray, float]:
    """A floating robot's configuration moved along the ground's normal so that its lowest
    contact point is ``clearance`` [m] above the plane, and how far it moved [m].

    Args:
        robot: The robot (a floating base: ``q0[:3]`` is its position in [m]).
        q0: Configuration, shape (nq,).
        ground: The plane.
        contacts: The points that touch it (as for :func:`~robodyn.sim.ground.contact_points`).
        clearance: Height of the lowest contact point above the plane, in [m].
    """
    gaps = contact_kinematics(robot, q0, ground, contact_points(robot, contacts).points)[0]
    lift = clearance - float(gaps.min())
    moved = np.array(q0, dtype=float)
    moved[:3] += lift * np.array(ground.normal)
    return moved, lift


__all__ = [
    "BURIED_DEPTH",
    "BURIED_SAMPLES",
    "START_PENETRATION",
    "buried_line",
    "buried_links",
    "check_contact_run",
    "start_above",
]
