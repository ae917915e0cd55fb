"""The lecture's "what if" questions, answered with numbers.

What changes if the links are plastic, aluminium or steel? If the robot carries a load at
its end effector? If an external force acts on it? :func:`sweep` drives one motion (a
rest-to-rest quintic between two configurations) through the inverse dynamics of each
variant of the arm and reports the peak and RMS torque of every joint, marking peaks above
the joint's effort limit.

The payload and the force act on one frame (default the robot's end effector,
:attr:`robodyn.Robot.end_effector`), which must be a frame some joint moves: a load on a
frame fixed to the world changes no torque, and is refused rather than reported as such.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robodyn.common.text import printable
from robodyn.dynamics.loading import load
from robodyn.dynamics.payload import attach_payload
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError
from robodyn.sim.control import quintic_reference
from robodyn.urdf.models import RPArmParameters, rp_arm_urdf

DEFAULT_MATERIALS = ("abs", "aluminium", "steel")
DEFAULT_PAYLOADS = (0.0, 0.5, 2.0)


@dataclass(frozen=True)
class Variant:
    """One row of the what-if table.

    Attributes:
        material: Link material (or ``"as loaded"`` for robots that are not generated).
        payload: Payload mass at the end effector in [kg].
        force: External force at the end effector in [N], world axes, shape (3,).
        robot_mass: Total mass of the arm with its payload in [kg].
        peak: Peak absolute torque per joint in [N m] / [N], shape (nv,).
        rms: RMS torque per joint over the motion, shape (nv,).
        effort: Effort limit per joint (inf where none), shape (nv,).
    """

    material: str
    payload: float
    force: np.ndarray
    robot_mass: float
    peak: np.ndarray
    rms: np.ndarray
    effort: np.ndarray

    @property
    def over_limit(self) -> np.ndarray:
        """Which joints' peak torque exceeds their effort limit, shape (nv,)."""
        return self.peak > self.effort


def motion_torques(
    robot: Robot,
    q_start: np.ndarray,
    q_end: np.ndarray,
    duration: float,
    *,
    samples: int = 401,
    frame: str | None = None,
    force: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Torques along a rest-to-rest quintic motion: times (N,) and torques (N, nv).

    An external ``force`` (in [N], world axes) acting on ``frame`` is subtracted through
    ``J(q)ᵀ f``: the motors need that much less torque when it helps, more when it resists.

    Args:
        robot: The robot.
        q_start: Start configuration, shape (nq,), in [rad] / [m].
        q_end: End configuration, shape (nq,), in [rad] / [m].
        duration: Duration of the motion in [s].
        samples: Number of evenly spaced times, both ends included.
        frame: The frame the force acts on (needed with a non-zero ``force``).
        force: External force on ``frame``'s origin, shape (3,), in [N], world axes (``None``: none).
    """
    reference = quintic_reference(q_start, q_end, duration)
    times = np.linspace(0.0, duration, samples)
    q, v, a = (np.array(column) for column in zip(*(reference(t) for t in times), strict=True))
    torques = robot.inverse_dynamics(q, v, a)
    if force is not None and np.any(force):
        if frame is None:
            raise InputError("frame", "a frame the force acts on", "None")
        torques = torques - np.array([robot.wrench_torques(qi, frame, force) for qi in q])
    return times, torques


@dataclass(frozen=True)
class WhatIfTable:
    """The what-if table of one robot's motion: a row a material × payload × force.

    Attributes:
        robot: The robot's name.
        duration: Motion time in [s].
        joint_names: Its joints (one column pair each).
        torque_units: Unit of each joint's torques (``robot.dofs``: N m or N).
        rows: The variants, in sweep order.
        plot: A bar chart written of the table, if any.
    """

    robot: str
    duration: float
    joint_names: tuple[str, ...]
    torque_units: tuple[str, ...]
    rows: tuple[Variant, ...]
    plot: str | None = None

    def to_dict(self) -> dict:
        """JSON-ready (the ``robodyn whatif --json`` output)."""
        data = table_dict(list(self.rows), list(self.joint_names), list(self.torque_units))
        return data if self.plot is None else data | {"plot": self.plot}

    def text(self) -> str:
        """A title line and the table (a peak above the effort limit ends in ``!``)."""
        title = f"{printable(self.robot)}: one rest-to-rest motion of {self.duration:g} s; torques of each joint"
        table = table_text(list(self.rows), list(self.joint_names), list(self.torque_units))
        return f"{title}\n\n{table}" + (f"\n\nplot: {self.plot}" if self.plot is not None else "")


def sweep(model: str = "rp_arm", **options) -> list[Variant]:
    """The rows of :func:`what_if` (same arguments)."""
    return list(what_if(model, **options).rows)


def what_if(
    model: str = "rp_arm",
    *,
    materials: tuple[str, ...] | None = None,
    payloads: tuple[float, ...] = DEFAULT_PAYLOADS,
    forces: tuple[tuple[float, float, float], ...] = ((0.0, 0.0, 0.0),),
    q_start: np.ndarray | None = None,
    q_end: np.ndarray | None = None,
    duration: float = 1.5,
    frame: str | None = None,
) -> WhatIfTable:
    """Peak and RMS joint torques of one motion, for each material × payload × force.

    Args:
        model: ``"rp_arm"`` (materials apply) or any robot :func:`robodyn.load` takes
            (then ``materials`` must be ``None``).
        materials: Link materials for the RP arm; default plastic, aluminium, steel.
        payloads: Payload masses at the end effector, in [kg].
        forces: External forces at the end effector, in [N], world axes.
        q_start, q_end: The motion; default: the RP arm from hanging 45° down and retracted
            to 45° up and extended; other robots from
            :meth:`~robodyn.Robot.default_configuration` (neutral, clipped into the
            limits) by 0.5 rad (or m) on every joint, towards the side with room.
        duration: Motion time in [s], > 0.
        frame: The frame carrying the payload and the force; default the end effector.

    Raises:
        InputError: Negative payloads, non-finite forces, a duration ≤ 0.
        FrameError: An unknown frame, one no joint moves, or no default end effector.
    """
    payloads = _check_sweep(payloads, forces, duration)
    generated = model == "rp_arm"
    variants = model_variants(model, materials)
    base_robot = variants[0][1]
    if any(payloads) or any(np.any(f) for f in forces):
        frame = base_robot.task_frame(frame, "a payload or force")
    if q_start is None:
        q_start = np.array([-np.pi / 4, 0.0]) if generated else base_robot.default_configuration()
    if q_end is None:
        q_end = np.array([np.pi / 4, 0.25]) if generated else _half_radian_away(base_robot, q_start)
    effort = _effort_limits(base_robot)
    rows = []
    for material, robot in variants:
        for payload in payloads:
            loaded = attach_payload(robot, frame, payload) if payload > 0 and frame is not None else robot
            for force in forces:
                force_vector = np.asarray(force, dtype=float)
                _, torques = motion_torques(loaded, q_start, q_end, duration, frame=frame, force=force_vector)
                peak, rms = np.abs(torques).max(axis=0), np.sqrt((torques**2).mean(axis=0))
                rows.append(Variant(material, float(payload), force_vector, loaded.total_mass, peak, rms, effort))
    return table_of(base_robot, duration, rows)


def table_of(robot: Robot, duration: float, rows: list[Variant]) -> WhatIfTable:
    """The table of ``rows`` swept on ``robot`` (names and units from ``robot.dofs``).

    Args:
        robot: The robot swept.
        duration: Duration of the motion in [s].
        rows: The sweep's variants.
    """
    units = tuple(dof.effort_unit for dof in robot.dofs)
    return WhatIfTable(robot.name, duration, tuple(robot.joint_names), units, tuple(rows))


def _check_sweep(payloads: tuple[float, ...], forces: tuple[tuple[float, float, float], ...], duration: float) -> tuple:
    """The payloads as floats; refuse negative payloads, bad forces or a duration ≤ 0."""
    payloads = tuple(float(p) for p in payloads)
    if not all(np.isfinite(p) and p >= 0 for p in payloads):
        raise InputError("payloads", "masses ≥ 0 in [kg]", ", ".join(f"{p:g}" for p in payloads))
    if not all(np.isfinite(np.asarray(f, float)).all() and np.shape(f) == (3,) for f in forces):
        raise InputError("forces", "3 finite values FX, FY, FZ in [N] each", repr(forces))
    if not (np.isfinite(duration) and duration > 0):
        raise InputError("duration", "finite and > 0 s", f"{duration:g}")
    return payloads


def model_variants(model: str, materials: tuple[str, ...] | None) -> list[tuple[str, Robot]]:
    """The robots a sweep compares: the RP arm in each material, or ``model`` as loaded.

    Args:
        model: A robot file or name (``"rp_arm"``: the generated RP arm).
        materials: Material names for the RP arm's links (``None``: the defaults); refused for another robot.

    Raises:
        InputError: Materials for another robot than ``rp_arm``, or a floating base.
    """
    if model == "rp_arm":
        variants = [(name, load(rp_arm_urdf(RPArmParameters.from_material(name)))) for name in (materials or DEFAULT_MATERIALS)]
    else:
        if materials:
            raise InputError("materials", "given only for the generated rp_arm", f"{len(materials)} materials for {model!r}")
        variants = [("as loaded", load(model))]
    if variants[0][1].floating_base:
        raise InputError(
            "model",
            "a fixed-base robot (a floating base's motion needs contacts; the sweep would report the "
            "wrench of a hook holding the base)",
            f"floating-base {variants[0][1].name!r}",
        )
    return variants


def _half_radian_away(robot: Robot, q_start: np.ndarray) -> np.ndarray:
    """``q_start`` moved by 0.5 on every joint, downwards where upwards leaves the limits."""
    lower, upper = robot.physical_limits()
    start = robot.nq - lower.size
    q_end = np.array(q_start, dtype=float)
    joints = q_end[start:]
    up = joints + 0.5
    q_end[start:] = np.clip(np.where(up <= upper, up, joints - 0.5), lower, upper)
    return q_end


def _effort_limits(robot: Robot) -> np.ndarray:
    """Effort limit per velocity coordinate, inf where none (zero in a URDF means none)."""
    effort = np.array([dof.effort_limit for dof in robot.dofs], dtype=float)
    return np.where(effort > 0, effort, np.inf)


def table_text(rows: list[Variant], joint_names: list[str], units: list[str]) -> str:
    """The sweep as a readable table; a peak above the joint's effort limit ends in ``!``.

    Args:
        rows: The sweep's variants.
        joint_names: The robot's joint names.
        units: The torque unit of each joint (``"N m"`` or ``"N"``).
    """
    header = f"{'material':10s} {'payload':>8s} {'force [N]':>16s} {'mass':>8s}"
    for name, unit in zip((printable(n) for n in joint_names), units, strict=True):
        header += f" {'peak ' + name + ' [' + unit + ']':>22s} {'rms ' + name:>14s}"
    lines = [header]
    for row in rows:
        force = ",".join(f"{f:g}" for f in row.force)
        line = f"{row.material:10s} {row.payload:>6.2f}kg {force:>16s} {row.robot_mass:>6.2f}kg"
        for peak, rms, over in zip(row.peak, row.rms, row.over_limit, strict=True):
            line += f" {peak:>21.3f}{'!' if over else ' '} {rms:>14.3f}"
        lines.append(line)
    over = [
        f"{printable(name)} ({rows[0].effort[index]:g} {units[index]})"
        for index, name in enumerate(joint_names)
        if any(row.over_limit[index] for row in rows)
    ]
    if over:
        lines += ["", f"! peak above the effort limit of {', '.join(over)}"]
    return "\n".join(lines)


def table_dict(rows: list[Variant], joint_names: list[str], units: list[str]) -> dict:
    """The sweep, JSON-ready.

    Args:
        rows: The sweep's variants.
        joint_names: The robot's joint names.
        units: The torque unit of each joint (``"N m"`` or ``"N"``).
    """
    return {
        "joint_names": joint_names,
        "torque_units": units,
        "effort_limits": [float(e) if np.isfinite(e) else None for e in (rows[0].effort if rows else [])],
        "rows": [
            {
                "material": r.material,
                "payload_kg": r.payload,
                "force_N": r.force.tolist(),
                "robot_mass_kg": r.robot_mass,
                "peak_torque": r.peak.tolist(),
                "rms_torque": r.rms.tolist(),
                "over_effort_limit": r.over_limit.tolist(),
            }
            for r in rows
        ],
    }
