"""``controller="stand"`` of :func:`robodyn.sim.experiment.run_simulation`: a floating robot on
the ground held by the whole-body QP (:class:`robodyn.sim.whole_body.Stand`).

The robot starts with its lowest contact point on the ground (gap 0, not the 5 cm drop of
the other controllers: the QP assumes feet that do not move), its feet (the run's contact
points within 1 mm of the ground there; the others, a hand or a knee, are no feet) become sticking :class:`~robodyn.constraints.PointContact` s of the ground's normal
and friction, and the controller holds the base attitude and the centre of mass at its
start shifted by ``target`` (DX, DY, DZ in [m]; refused outside the support polygon). The
summary gains the centre of mass's final error, the largest difference between the QP's
and the simulated contact forces, and the final centre of mass's support margin.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from robodyn.common.text import counted, quoted
from robodyn.constraints import PointContact
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import ControllerFailedError, InputError
from robodyn.sim.contact import contact_kinematics
from robodyn.sim.contact_checks import start_above
from robodyn.sim.drawings import MovingPoint, PlotPanel, Polygon
from robodyn.sim.ground import ContactPoint, Ground, contact_points
from robodyn.sim.whole_body import Stand, support_margin
from robodyn.trajectory import Trajectory
from robodyn.trajectory.columns import commanded_header, contact_header
from robodyn.trajectory.io import write_csv_with_columns

#: A contact point is a foot when it lies within this gap [m] of the ground at the start.
FOOT_GAP = 1e-3


class RecordedStand:
    """A :class:`Stand` that keeps the QP's contact forces of every call, (3 k,) each in [N]
    for the run's ``k`` contact points (zero at a point that is no foot), and the call's
    time in [s]."""

    def __init__(self, law: Stand, feet: Sequence[int] | None = None, count: int | None = None) -> None:
        self.law = law
        self.feet = list(range(len(law.contacts))) if feet is None else list(feet)
        self.count = len(self.feet) if count is None else count
        self.forces: list[np.ndarray] = []
        self.times: list[float] = []

    def __call__(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        try:
            tau = self.law(t, q, v)
        except InputError as error:  # no QP solution mid-run: say when, not the state's parameter name
            fastest = int(np.argmax(np.abs(v)))
            reason = f"the whole-body QP: {error.received}, {error.expected}"
            raise ControllerFailedError(
                float(t), len(self.times), self.law.model.dofs[fastest].joint, float(v[fastest]), reason
            ) from None
        forces = np.zeros((self.count, 3))
        forces[self.feet] = self.law.last_forces.reshape(-1, 3)
        self.forces.append(forces.reshape(-1))
        self.times.append(float(t))
        return tau

    @property
    def compensate_damping(self) -> bool:
        """The recorded law's ``compensate_damping`` (what the run sets from ``joint_friction``)."""
        return self.law.compensate_damping

    @compensate_damping.setter
    def compensate_damping(self, value: bool) -> None:
        self.law.compensate_damping = value

    def held(self, times: np.ndarray) -> np.ndarray:
        """The QP's forces in force at ``times`` (its last call at or before each), (N, k, 3) [N].

        Args:
            times: In [s], shape (N,).
        """
        forces = np.array(self.forces).reshape(len(self.forces), -1, 3)
        return forces[np.clip(np.searchsorted(self.times, times, side="right") - 1, 0, len(forces) - 1)]


@dataclass(frozen=True)
class CommandedContacts:
    """A stand run's contacts (:class:`~robodyn.sim.contact_run.ContactSimulation`, every
    attribute of it) with the QP's forces, which its CSV writes beside the simulated ones.

    Attributes:
        run: The contact simulation.
        commanded: The QP's force of each contact at each sample, (N, k, 3), world axes, in [N].
    """

    run: Any
    commanded: np.ndarray

    def __getattr__(self, name: str) -> Any:
        if name == "run":  # not set yet (copying): no recursion
            raise AttributeError(name)
        return getattr(self.run, name)

    def save(self, path: str | Path, extras: dict[str, np.ndarray] | None = None) -> Path:
        """The run's CSV (``ContactSimulation.save``) with ``f_cmd[<contact>].x/.y/.z`` [N]
        after its ``f[<contact>]`` columns.

        Args:
            path: The ``.csv`` file.
            extras: As for ``ContactSimulation.save``.

        Raises:
            InputError: For a file name that does not end in ``.csv``.
        """
        path = Path(path)
        if path.suffix != ".csv":
            raise InputError("out", "a .csv file for a run on the ground (its contact forces are columns)", repr(str(path)))
        names, count = list(self.run.contacts), len(self.run.contacts)
        flags = contact_header(names)
        header = flags[: 3 * count] + commanded_header(names) + flags[3 * count :]
        forces, commanded = (array.reshape(len(array), 3 * count) for array in (self.run.forces, self.commanded))
        columns = [forces, commanded, self.run.active.astype(float)]
        return write_csv_with_columns(path, self.run.trajectory, extras or {}, header, columns)


def _feet(robot: Robot, q: np.ndarray, ground: Ground, points: Sequence[ContactPoint]) -> tuple[PointContact, ...]:
    """Each contact point's lowest point (a sphere's centre minus ``radius · n``) as a
    sticking point contact on ``ground``, in its link's frame at ``q``."""
    pin.framesForwardKinematics(robot.model, robot.data, q)
    feet = []
    for point in points:
        placement = robot.data.oMf[robot.frame_id(point.link)]
        lowest = placement.act(np.array(point.position)) - point.radius * np.array(ground.normal)
        local = placement.actInv(lowest)
        feet.append(
            PointContact(
                point.link, tuple(local.tolist()), ground.normal, ground.friction, tuple(ground.point.tolist()), point.name
            )
        )
    return tuple(feet)


def stand_law(
    robot: Robot,
    model: Robot,
    start: np.ndarray,
    target: list[float] | None,
    ground: Ground | None,
    contacts: str | Sequence[str | ContactPoint],
) -> tuple[RecordedStand, np.ndarray, str]:
    """The stand controller (on ``model``, the controller's copy of ``robot``) and its start.

    Args:
        robot: The plant (a floating base).
        model: The controller's own copy of it.
        start: The configuration (nq,) whose base is moved along the ground's normal until
            its lowest contact point touches the ground.
        target: The centre of mass's shift DX, DY, DZ in [m] (``None``: hold it).
        ground: The plane the robot stands on.
        contacts: The run's contact points (``"collision"`` or frame names).

    Returns:
        The controller, the start configuration (nq,) and the summary's line saying how
        far the base moved to put the feet on the ground.

    Raises:
        InputError: Naming ``ground`` (none), ``controller`` (a fixed base), ``friction`` (0),
            ``contacts`` (fewer than three feet off one line, or feet whose polygon does not
            hold the start's centre of mass), or ``target`` (not 3 values, or outside the
            support polygon).
    """
    if not robot.floating_base:
        raise InputError(
            "controller",
            "another controller than 'stand' for a fixed-base robot (stand holds a floating one on its feet)",
            repr(robot.name),
        )
    if ground is None:
        raise InputError("ground", "given for the stand controller (the robot stands on it)", "no ground")
    if ground.friction <= 0:
        raise InputError("friction", "a coefficient > 0 for the stand controller (its feet stick)", repr(ground.friction))
    shift = np.zeros(3) if target is None else np.asarray(target, dtype=float)
    if shift.shape != (3,) or not np.isfinite(shift).all():
        raise InputError(
            "target", "DX,DY,DZ in [m] (the centre of mass's shift) for the stand controller", counted(shift.size, "value")
        )
    start, lift = start_above(robot, start, ground, contacts, clearance=0.0)
    points = contact_points(robot, contacts).points
    touching = _touching(robot, start, ground, points)
    feet = _feet(robot, start, ground, [points[index] for index in touching])
    com = robot.center_of_mass(start) + shift
    margin = support_margin(robot, start, feet, com)
    if not np.isfinite(margin):
        raise InputError("contacts", "feet spanning a support polygon (three points or more off one line)", f"{len(feet)} points")
    if not margin > 0 and target is None:  # the feet do not hold the start: they are not the robot's feet
        links = sorted({foot.frame for foot in feet})
        raise InputError(
            "contacts",
            "feet whose support polygon holds the centre of mass at the start (name them)",
            f"{-margin:.3g} m outside the polygon of {len(feet)} points on {', '.join(map(quoted, links[:4]))}",
        )
    if not margin > 0:
        raise InputError(
            "target", "a centre of mass shift that stays over the support polygon of the feet", f"{-margin:.3g} m outside it"
        )
    rotation = pin.Quaternion(start[6], start[3], start[4], start[5]).toRotationMatrix()
    line = (
        f"start: the base moved {lift:.6g} m along the ground's normal (its lowest contact point on it: stand's feet do not move)"
    )
    if len(feet) < len(points):
        line += f"; feet: the {len(feet)} of {len(points)} contact points within {FOOT_GAP:g} m of the ground at the start"
    return RecordedStand(Stand(model, feet, com, rotation, start), touching, len(points)), start, line


def _touching(robot: Robot, q: np.ndarray, ground: Ground, points: Sequence[ContactPoint]) -> list[int]:
    """The indices of the contact points within :data:`FOOT_GAP` of ``ground`` at ``q``: the
    feet (a hand or a knee above the ground is no foot the QP may push on)."""
    gaps = contact_kinematics(robot, q, ground, tuple(points))[0]
    return [index for index, gap in enumerate(gaps) if gap <= FOOT_GAP]


def stand_outcome(robot: Robot, law: RecordedStand, contact: Any) -> dict[str, Any]:
    """The summary's stand fields: ``com_error`` (final centre of mass to its target, in [m]),
    ``force_difference`` (largest ``|f_QP − f_simulated|`` of a contact over the run, in [N]),
    ``support_margin`` (of the final centre of mass, in [m]), and the figure's ``panels`` and
    the recording's ``drawings`` (:func:`stand_panels`, :func:`stand_drawings`).

    Args:
        robot: The plant.
        law: The run's controller.
        contact: The run's :class:`~robodyn.sim.contact_run.ContactSimulation`.
    """
    final = contact.trajectory.q[-1]
    feet = law.law.contacts
    commanded = np.array(law.forces).reshape(len(law.forces), -1, 3)
    count, held = min(len(commanded), len(contact.forces)), law.held(contact.trajectory.t)
    return {
        "com_error": float(np.linalg.norm(robot.center_of_mass(final) - law.law.com)),
        "force_difference": float(np.abs(commanded[:count] - contact.forces[:count]).max()),
        "support_margin": support_margin(robot, final, feet, robot.center_of_mass(final)),
        "contact": CommandedContacts(contact, held),
        "panels": (*stand_panels(robot, contact.trajectory, feet, law.law.com), force_panel(contact, held)),
        "drawings": stand_drawings(robot, contact.trajectory, feet, law.law.com),
    }


def feet_outline(robot: Robot, q: np.ndarray, feet: Sequence[PointContact]) -> np.ndarray:
    """The feet's points at ``q`` on the support polygon's boundary (its corners), in order
    counter-clockwise seen from above, world frame, shape (k, 3), in [m].

    Args:
        robot: The robot.
        q: Its configuration (nq,).
        feet: The contacts.
    """
    pin.framesForwardKinematics(robot.model, robot.data, q)
    world = np.array([robot.data.oMf[robot.frame_id(foot.frame)].act(np.asarray(foot.point, float)) for foot in feet])
    boundary = world[[abs(support_margin(robot, q, feet, point)) <= 1e-9 for point in world]]
    up = -robot.gravity_vector / np.linalg.norm(robot.gravity_vector)
    arms = boundary - boundary.mean(axis=0)
    angles = np.arctan2(np.cross(arms[0], arms) @ up, arms @ arms[0])
    return boundary[np.argsort(angles)]


def stand_drawings(
    robot: Robot, trajectory: Trajectory, feet: Sequence[PointContact], com: np.ndarray
) -> tuple[Polygon | MovingPoint, ...]:
    """The recording's support polygon (the feet at the start), the centre of mass over the
    motion, its shadow along gravity on the feet's plane, and its target.

    Args:
        robot: The plant.
        trajectory: The motion.
        feet: The contacts.
        com: The centre of mass's target in [m] (3,).
    """
    outline = feet_outline(robot, trajectory.q[0], feet)
    step = max(1, len(trajectory) // 2000)
    t, centre = trajectory.t[::step], np.atleast_2d(robot.center_of_mass(trajectory.q[::step]))
    up = -robot.gravity_vector / np.linalg.norm(robot.gravity_vector)
    shadow = centre - np.outer((centre - outline[0]) @ up, up)
    return (
        Polygon("support_polygon", outline),
        MovingPoint("com", t, centre, 0.015, 0x20A040),
        MovingPoint("com_shadow", t, shadow, 0.008, 0x20A040),
        MovingPoint("com_target", t[:1], np.asarray(com, float)[None], 0.01, 0xE02020),
    )


def stand_panels(robot: Robot, trajectory: Trajectory, feet: Sequence[PointContact], com: np.ndarray) -> tuple[PlotPanel, ...]:
    """The figure's panels: the centre of mass minus its target (x, y, z) and the support
    margin over time (at most 100 samples), both in [m].

    Args:
        robot: The plant.
        trajectory: The motion.
        feet: The contacts.
        com: The centre of mass's target in [m] (3,).
    """
    centre = np.atleast_2d(robot.center_of_mass(trajectory.q)) - np.asarray(com, float)
    step = max(1, len(trajectory) // 100)
    t = trajectory.t[::step]
    margin = np.array([support_margin(robot, q, feet, robot.center_of_mass(q)) for q in trajectory.q[::step]])
    errors = tuple((f"com {axis} − target", trajectory.t, centre[:, k], "solid") for k, axis in enumerate("xyz"))
    return PlotPanel("centre of mass − target [m]", errors), PlotPanel(
        "support margin [m]", (("support margin", t, margin, "solid"),)
    )


def force_panel(contact: Any, commanded: np.ndarray) -> PlotPanel:
    """The figure's force panel: the feet's total normal force, the QP's (commanded) and the
    simulated (measured), in [N].

    Args:
        contact: The run's :class:`~robodyn.sim.contact_run.ContactSimulation`.
        commanded: The QP's forces at each sample, (N, k, 3) [N].
    """
    normal, t = np.asarray(contact.ground.normal, dtype=float), contact.trajectory.t
    curves = (
        ("commanded force", t, (commanded @ normal).sum(axis=1), "dashed"),
        ("measured force", t, contact.normal_forces.sum(axis=1), "solid"),
    )
    return PlotPanel("total normal force [N]", curves)


__all__ = [
    "CommandedContacts",
    "RecordedStand",
    "feet_outline",
    "force_panel",
    "stand_drawings",
    "stand_law",
    "stand_outcome",
    "stand_panels",
]
