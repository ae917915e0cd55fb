"""``controller="hybrid"``: hybrid force/motion control on a surface, as a named run.

:func:`run_hybrid` is what ``robodyn simulate --controller hybrid`` calls. The plant is the
robot with the surface as a frictionless :class:`~robodyn.constraints.PointContact` (its
multiplier ``λ`` is the **measured** normal force, :mod:`robodyn.sim.constrained`); the
controller is :class:`~robodyn.sim.force_control.HybridForceMotion` on its own copy of the
model, pressing with ``force`` along the surface's normal while its frame follows
``x_d(t) = c + a sin(2π f t) + b cos(2π f t)`` along the surface (``c``: ``target``,
default the frame's start; ``a`` and optionally ``b``: ``along``; ``f``: ``frequency``): a
line back and forth, or with ``a ⊥ b`` of equal length a circle about ``c`` (wiping).

The run starts with the frame **on** the surface: without ``q0`` the default configuration
is projected onto it (:func:`robodyn.sim.constrained.project`); a ``q0`` whose frame lies
more than :data:`ON_SURFACE` off it is refused. The summary's ``forces``
(:class:`ForceOutcome`) compares the commanded and measured normal force and gives the
motion's final error along the surface; ``contact`` (:class:`SurfaceRun`) writes the CSV's
``f[surface]`` (measured) and ``f_cmd[surface]`` (commanded) columns and the recording's
force arrow.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from robodyn.constraints import PointContact
from robodyn.dynamics import constrained
from robodyn.dynamics.loading import rebuild
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError, NonFiniteResultError
from robodyn.sim.constrained import project, simulate_constrained
from robodyn.sim.drawings import Polygon
from robodyn.sim.experiment import run_simulation
from robodyn.sim.force_control import HybridForceMotion, scalar, unit_normal, vector
from robodyn.sim.limits import limit_violations
from robodyn.sim.surface_run import ForceOutcome, SurfaceRun, refuse_options, summary_of, timed
from robodyn.sim.twin import compensate
from robodyn.trajectory import Trajectory

#: Largest distance in [m] a given ``q0`` (or ``target``) may leave the frame off the surface
#: (the start is then projected onto it: the summary says how far it moved).
ON_SURFACE = 1e-4
#: The contact's name in files and reports.
SURFACE = "surface"


@dataclass(frozen=True)
class SlidingReference:
    """``x_d(t) = center + a sin(2π frequency t) + b cos(2π frequency t)`` with its first two derivatives.

    Attributes:
        center: The middle of the motion in [m], world axes (3,).
        along: The amplitude vectors ``a`` and ``b`` in [m], shape (2, 3), in the surface.
        frequency: In [Hz].
    """

    center: np.ndarray
    along: np.ndarray
    frequency: float

    def __call__(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        rate = 2 * np.pi * self.frequency
        sine, cosine = self.along
        s, c = np.sin(rate * t), np.cos(rate * t)
        offset = sine * s + cosine * c
        return self.center + offset, rate * (sine * c - cosine * s), -(rate**2) * offset


def _surface(value: object) -> tuple[np.ndarray, np.ndarray]:
    """``(point, unit normal)`` of ``surface`` (a point and a normal, each 3 values)."""
    try:
        parts: list[Any] = list(value)  # type: ignore[call-overload]
    except TypeError:
        parts = []
    if len(parts) != 2:
        raise InputError("surface", "a point X,Y,Z in [m] and an outward normal NX,NY,NZ", repr(value)[:80])
    return vector(parts[0], "surface"), unit_normal(parts[1], "surface")


def _start(robot: Robot, contact: PointContact, q0: Sequence[float] | None) -> tuple[np.ndarray, float]:
    """The start configuration, its frame on the surface, and how far the projection moved it."""
    start = robot.default_configuration() if q0 is None else _configuration(robot, q0, "q0")
    normal, point = np.array(contact.normal), np.array(contact.plane_point)
    gap = float(normal @ (robot.frame_position(start, contact.frame) - point))
    if q0 is not None and abs(gap) > ON_SURFACE:
        raise InputError(
            "q0", f"a configuration with {contact.frame} on the surface (within {ON_SURFACE:g} m)", f"{gap:.3g} m off it"
        )
    try:
        placed, _ = project(robot, start, np.zeros(robot.nv), constrained.bound(robot, [contact]))
    except (InputError, NonFiniteResultError):  # Newton's steps toward a plane out of reach overflow
        raise InputError(
            "surface", f"a plane {contact.frame} can reach from the default configuration", f"{gap:.3g} m away"
        ) from None
    if q0 is None:
        _within_limits(robot, placed)
    return placed, float(np.abs(placed - start).max())


def _configuration(robot: Robot, value: object, name: str) -> np.ndarray:
    """``value`` as one configuration (nq,), or an :class:`InputError` naming ``name``."""
    try:
        q = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(name, f"one configuration of {robot.nq} finite values", repr(value)[:80]) from None
    if q.shape != (robot.nq,) or not np.isfinite(q).all():
        found = f"shape {q.shape}" if q.shape != (robot.nq,) else "non-finite values"
        raise InputError(name, f"one configuration of {robot.nq} finite values", found)
    return robot.validate(q=q)[0][0]


def _gains(kp: Any, kd: Any) -> dict[str, float]:
    """The motion's gains given, each one finite value >= 0 (naming ``kp`` or ``kd``)."""
    gains = {}
    for name, value in (("kp", kp), ("kd", kd)):
        if value is None:
            continue
        try:
            values = np.asarray(value, dtype=float)
        except (TypeError, ValueError):  # text, or ragged nested lists
            raise InputError(name, "one finite gain >= 0 for the hybrid controller", repr(value)[:80]) from None
        if values.size != 1:
            raise InputError(name, "one finite gain >= 0 for the hybrid controller", f"{values.size} values")
        gains[name] = scalar(float(values.reshape(())), name, "one finite gain >= 0")
    return gains


def _within_limits(robot: Robot, q: np.ndarray) -> None:
    """Refuse a solved start that breaks a joint's position limits (naming ``q0``)."""
    zeros = np.zeros((1, robot.nv))
    still = Trajectory(np.zeros(1), q[None], zeros, zeros, None, list(robot.joint_names), robot.name)
    broken = [violation for violation in limit_violations(robot, still) if violation.quantity == "position"]
    if broken:
        raise InputError(
            "q0", "given: the default configuration projected onto the surface breaks a joint limit", broken[0].text()
        )


def _reference(
    robot: Robot, frame: str, start: np.ndarray, surface: tuple[np.ndarray, np.ndarray], motion: tuple[Any, Any, float]
) -> SlidingReference:
    """The sliding reference, refused when it leaves the surface (``target``, ``along``)."""
    point, normal = surface
    target, along, frequency = motion
    center = robot.frame_position(start, frame) if target is None else vector(target, "target")
    if abs(normal @ (center - point)) > ON_SURFACE:
        raise InputError(
            "target", f"a point on the surface (within {ON_SURFACE:g} m)", f"{normal @ (center - point):.3g} m off it"
        )
    amplitude = np.zeros((2, 3)) if along is None else _amplitudes(along)
    if np.abs(amplitude @ normal).max() > 1e-9 * max(1.0, float(np.abs(amplitude).max())):
        raise InputError(
            "along",
            "amplitudes DX,DY,DZ[:EX,EY,EZ] in [m] along the surface (normal part 0)",
            f"normal part {np.abs(amplitude @ normal).max():.3g} m",
        )
    rate = scalar(frequency, "frequency", "a finite frequency >= 0 in [Hz]")
    return SlidingReference(center, amplitude, rate)


def _amplitudes(along: object) -> np.ndarray:
    """``along`` as the (2, 3) amplitudes of the sine and the cosine (3 values: no cosine)."""
    try:
        values = np.asarray(along, dtype=float)
    except (TypeError, ValueError):
        values = np.zeros(0)
    if values.shape == (3,):
        values = np.vstack([values, np.zeros(3)])
    if values.shape != (2, 3) or not np.isfinite(values).all():
        raise InputError("along", "3 amplitudes in [m] (or 2 x 3: the sine's and the cosine's)", repr(along)[:80])
    return values


def _fixed_base(robot: Robot) -> None:
    """Refuse a floating robot: its base has no actuator to press or slide with."""
    if robot.floating_base:
        raise InputError(
            "controller", "a fixed-base robot for the hybrid controller (a floating base has no actuator)", repr(robot.name)
        )


def run_hybrid(
    robot: Robot,
    *,
    force: float | None = None,
    surface: tuple[Sequence[float], Sequence[float]] | None = None,
    along: Sequence[float] | Sequence[Sequence[float]] | None = None,
    frequency: float = 0.5,
    target: Sequence[float] | None = None,
    frame: str | None = None,
    q0: Sequence[float] | None = None,
    duration: float = 3.0,
    dt: float = 1e-3,
    kp: float | Sequence[float] | None = None,
    kd: float | Sequence[float] | None = None,
    posture: Sequence[float] | None = None,
    limits: str = "warn",
    joint_friction: bool = True,
    **others: Any,
) -> tuple[Trajectory, Any]:
    """Hybrid force/motion control of a frame on a surface (module docstring).

    Args:
        robot: The plant (its frame slides on the surface without friction).
        force: The commanded normal force in [N] (≥ 0: pressing); required.
        surface: Required: A point of the plane in [m] and its normal toward the robot, each (3,), world axes.
        along: The motion's amplitude ``a`` in [m] (3,), or ``a`` and ``b`` (2, 3), in the
            surface (``None``: hold ``target``).
        frequency: Of the motion, in [Hz].
        target: The middle of the motion in [m] (3,), on the surface; default the frame's start.
        frame: The frame whose origin touches the surface (default the end effector).
        q0: The start (nq,), its frame on the surface; default: the default configuration
            projected onto it.
        duration, dt: Simulated time and step in [s] (RK4 and projection).
        kp, kd: The motion's gains in [1/s²] and [1/s] (default 400 and 40).
        posture: A configuration (nq,) held in the task's null space (default the start).
        limits: ``"warn"`` (report every broken limit) or ``"ignore"``.
        joint_friction: Apply the joints' viscous damping (the controller compensates it).
        **others: The other controllers' options, refused when set (``engine``, ``ground``, ...).

    Returns:
        The trajectory and its :class:`~robodyn.sim.report.SimulationSummary`, whose
        ``forces`` is a :class:`ForceOutcome` and ``contact`` a :class:`SurfaceRun`.

    Raises:
        InputError: Naming the parameter (``force``, ``surface``, ``along``, ``q0``, ...).
    """
    refuse_options(others, limits)
    for name, value in (("force", force), ("surface", surface)):
        if value is None:
            raise InputError(name, "given for the hybrid controller", "nothing")
    _fixed_base(robot)
    point, normal = _surface(surface)
    frame = robot.task_frame(frame, "hybrid force/motion control")
    contact = PointContact(frame, normal=tuple(normal), friction=0.0, plane_point=tuple(point), name=SURFACE)
    start, moved = _start(robot, contact, q0)
    reference = _reference(robot, frame, start, (point, normal), (target, along, frequency))
    gains: dict[str, Any] = _gains(kp, kd)
    model = rebuild(robot)
    held = start if posture is None else _configuration(robot, posture, "posture")
    law = HybridForceMotion(
        model,
        frame,
        normal,
        scalar(force, "force", "a finite normal force >= 0 in [N] (pressing)"),
        reference,
        posture=held,
        **gains,
    )
    compensate(law, joint_friction)
    plant = _plant(robot, law, joint_friction)
    run, loop_time = timed(lambda: simulate_constrained(robot, start, constraints=[contact], duration=duration, dt=dt, tau=plant))
    surface_run = SurfaceRun(
        run.trajectory, SURFACE, frame, normal, run.multipliers[:, 0], np.full(len(run.trajectory), law.force)
    )
    errors = np.array(
        [law.motion_error(t, q, v)[0] for t, q, v in zip(run.trajectory.t, run.trajectory.q, run.trajectory.v, strict=True)]
    )
    outcome = ForceOutcome.of(surface_run, errors, moved, _notes(robot, joint_friction))
    summary = summary_of(robot, run.trajectory, outcome, surface_run, limits=limits, loop_time=loop_time, dt=dt)
    return run.trajectory, replace(summary, panels=surface_run.panels(), drawings=(surface_patch(reference, normal),))


def _plant(robot: Robot, law: HybridForceMotion, joint_friction: bool) -> Callable:
    """The torques the plant feels: the law (which compensates the joints' viscous damping
    when the run applies it), minus that damping (the plant's) when ``joint_friction``."""
    if not joint_friction or not np.any(robot.joint_damping):
        return law
    return lambda t, q, v: law(t, q, v) - robot.joint_damping * v


def _notes(robot: Robot, joint_friction: bool) -> tuple[str, ...]:
    """What the run does not model, one line each."""
    if joint_friction and np.any(robot.joint_friction):
        return ("joint Coulomb friction of the file is not applied in hybrid runs (the constrained plant)",)
    return ()


def surface_patch(reference: SlidingReference, normal: np.ndarray) -> Polygon:
    """The surface drawn: a square in it about the motion's middle, 0.1 m beyond its amplitude.

    Args:
        reference: The motion.
        normal: The surface's unit normal (3,).
    """
    seed = np.eye(3)[int(np.argmin(np.abs(normal)))]
    u = np.cross(normal, seed) / np.linalg.norm(np.cross(normal, seed))
    w = np.cross(normal, u)
    half = float(np.abs(reference.along).sum(axis=0).max()) + 0.1
    corners = [reference.center + half * (a * u + b * w) for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    return Polygon("surface", np.array(corners), 0x808080)


def run_named(robot: Robot, **settings: Any) -> tuple[Trajectory, Any]:
    """:func:`run_hybrid` for ``controller="hybrid"``, else
    :func:`robodyn.sim.experiment.run_simulation` (which takes no ``force``, ``surface``,
    ``along`` or ``frequency``: refused naming them).

    Args:
        robot: The plant.
        **settings: As for either function.

    Raises:
        InputError: A hybrid option with another controller.
    """
    if settings.get("controller") == "hybrid":
        return run_hybrid(robot, **settings)
    for name in ("force", "surface", "along", "frequency"):
        if settings.get(name) is not None:
            raise InputError(name, "given only with the hybrid controller", repr(settings[name])[:80])
        settings.pop(name, None)
    return run_simulation(robot, **settings)


__all__ = ["ON_SURFACE", "SURFACE", "SlidingReference", "run_hybrid", "run_named", "surface_patch"]
