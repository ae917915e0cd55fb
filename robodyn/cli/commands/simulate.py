"""`robodyn simulate`: a simulation run, its files and summary."""

from __future__ import annotations

import argparse
from dataclasses import replace
from typing import TYPE_CHECKING

from robodyn.cli.common import RANGES, add_constraints_argument, add_model_arguments, load_robot, vector, warn
from robodyn.cli.flags import command_line_text
from robodyn.cli.start import add_start_arguments, start_configuration
from robodyn.common.text import json_text, printable
from robodyn.exceptions import InputError

if TYPE_CHECKING:
    from robodyn.dynamics.robot import Robot


def add_parser(commands: argparse._SubParsersAction) -> None:
    """Add the command to the ``robodyn`` parser.

    Args:
        commands: The subparsers of the ``robodyn`` parser, from ``add_subparsers``.
    """
    parser = commands.add_parser("simulate", help="simulate a robot, optionally under a controller; write trajectory and plot")
    add_model_arguments(parser)
    add_constraints_argument(parser)
    parser.add_argument(
        "--controller",
        choices=["passive", "pd", "computed-torque", "task-space", "osc", "impedance", "lqr", "stand", "hybrid"],
        default="passive",
    )
    parser.add_argument(
        "--target",
        type=vector,
        help="task-space: frame position X,Z or X,Y,Z in [m]; osc / impedance: X,Y,Z[,ROLL,PITCH,YAW] in [m] and [rad]; "
        "pd / computed-torque: joint target (pd's default: the start's); lqr: the equilibrium (joint values) to balance at; "
        "stand: the centre of mass's shift DX,DY,DZ in [m] (default none: hold it); hybrid: the motion's middle X,Y,Z",
    )
    parser.add_argument(
        "--frame",
        help="controlled frame for task-space, osc, impedance, hybrid (default: the end effector 'robodyn info' shows; it "
        "must move); with any controller, the path --record and --plot draw",
    )
    _add_controller_options(parser)
    add_start_arguments(parser)
    parser.add_argument("--duration", type=float, default=3.0, help=f"simulated time, {RANGES['duration'].text()} (default 3)")
    parser.add_argument("--dt", type=float, default=1e-3, help=f"step, {RANGES['dt'].text()}, at most --duration (default 0.001)")
    parser.add_argument(
        "--integrator",
        choices=["rk4", "semi-implicit-euler"],
        default=None,
        help="default rk4; with --ground semi-implicit-euler (the contact step's scheme, the only one there)",
    )
    _add_ground_arguments(parser)
    parser.add_argument(
        "--limits",
        choices=["warn", "enforce", "ignore"],
        default="warn",
        help="joint limits: warn (report every violation, default), enforce (saturate torques at the effort "
        "limits, stop joints at the position limits), ignore",
    )
    parser.add_argument(
        "--compiled",
        action="store_true",
        help="integrate in C (robodyn.compile; a C compiler needed; fixed or floating base, the joints' damping "
        "included, Coulomb friction refused); PD, computed torque, lqr run in C too, and task-space, osc and impedance "
        "on a fixed base (the same as --engine compiled)",
    )
    _add_engine_arguments(parser)
    no_friction = "leave out the joints' damping and friction (<dynamics>): the rigid-body motion"
    parser.add_argument("--no-joint-friction", dest="joint_friction", action="store_false", help=no_friction)
    parser.add_argument("--out", help="trajectory file (.csv or .npz)")
    parser.add_argument(
        "--reference",
        help="computed-torque: track this trajectory file (e.g. robodyn optimize's) instead of the quintic; no --target",
    )
    parser.add_argument("--plot", help="PNG figure: positions, torques, task error, energy")
    parser.add_argument("--record", help="HTML animation (meshcat, self-contained, plays on open)")
    parser.add_argument(
        "--png", help="with --record: a poster of the motion, its final frame with the path drawn (needs Chromium)"
    )
    parser.add_argument("--json", action="store_true", help="print the summary as JSON")
    parser.set_defaults(run=run)


def _reference(arguments: argparse.Namespace) -> dict:
    """``reference=`` the trajectory of ``--reference`` (nothing when not given)."""
    if not getattr(arguments, "reference", None):
        return {}
    from robodyn.trajectory import Trajectory

    return {"reference": Trajectory.load(arguments.reference)}


def run(arguments: argparse.Namespace) -> int:
    """Run ``robodyn simulate`` with the parsed ``arguments``; return the exit status.

    Args:
        arguments: The command line parsed by the parser :func:`add_parser` built.
    """
    from robodyn.sim.report import seconds_since_process_start
    from robodyn.viz.experiment import run_experiment

    robot = load_robot(arguments)
    startup = seconds_since_process_start()  # interpreter, imports, loading the robot
    summary = run_experiment(
        robot,
        controller=arguments.controller,
        target=arguments.target,
        frame=arguments.frame,
        q0=start_configuration(robot, arguments),
        duration=arguments.duration,
        dt=arguments.dt,
        integrator=arguments.integrator,
        limits=arguments.limits,
        engine=_engine(arguments),
        control_period=arguments.control_period,
        posture=arguments.posture,
        stiffness=arguments.stiffness,
        damping=arguments.damping,
        force_at=arguments.force_at,
        observer_gain=arguments.observer_gain,
        actuated=None if arguments.actuated is None else [name.strip() for name in arguments.actuated.split(",")],
        joint_friction=arguments.joint_friction,
        kp=arguments.kp,
        kd=arguments.kd,
        out=arguments.out,
        plot=arguments.plot,
        record=arguments.record,
        png=arguments.png,
        **_reference(arguments),
        **_ground(arguments, robot),
        **_hybrid(arguments),
    )
    # the library's summary names its parameters (engine='compiled'); the command line, its flags
    summary = replace(summary.with_startup(startup), engine_reason=command_line_text(summary.engine_reason))
    warn(summary.warnings())
    if summary.task is not None and not summary.task.reached and summary.task.deflection is None:
        warn([
            f"{printable(summary.robot)}: the target was not reached: final error {summary.task.final_error:.3g} m "
            "(a longer --duration, another --q0 or --target?)"
        ])  # fmt: skip
    if summary.com_error is not None and summary.com_error >= 1e-3:
        warn([
            f"{printable(summary.robot)}: the centre of mass missed its target by {summary.com_error:.3g} m "
            "(a push still acting, a longer --duration, or legs stretched straight: a --q0 with bent legs?)"
        ])  # fmt: skip
    print(json_text(summary.to_dict()) if arguments.json else summary.text())
    return 0


def _engine(arguments: argparse.Namespace) -> str:
    """``--engine`` (``--compiled`` is ``--engine compiled``; both at odds: one stderr line)."""
    if arguments.compiled and arguments.engine not in (None, "compiled"):
        raise InputError("--compiled", "not combined with another --engine", f"--engine {arguments.engine}")
    return "compiled" if arguments.compiled else (arguments.engine or "auto")


def _add_controller_options(parser: argparse.ArgumentParser) -> None:
    """The options of particular controllers, pushes and the observer."""
    parser.add_argument("--posture", type=vector, help="osc, hybrid: a configuration drawn toward in the task's null space")
    parser.add_argument("--stiffness", type=vector, help="impedance: K, 3 values in [N/m] (or 6, then [N m/rad])")
    parser.add_argument("--damping", type=vector, help="impedance: D, in [N s/m] (then [N m s/rad])")
    parser.add_argument(
        "--force-at",
        dest="force_at",
        action="append",
        default=[],
        metavar="T:FX,FY,FZ[@FRAME]",
        help="a push of FX,FY,FZ [N] from time T [s] on, at FRAME (default: the controlled frame); repeatable",
    )
    parser.add_argument(
        "--observer-gain",
        dest="observer_gain",
        type=float,
        help="run a momentum observer of this gain [1/s]; --out then has tau_ext[<joint>] columns",
    )
    parser.add_argument(
        "--kp",
        type=vector,
        help="pd: stiffness, one value or one a joint, in [N m/rad] / [N/m] (default: 100 x each joint's inertia, a "
        "critically damped 10 rad/s; a floating robot on --ground adds each joint's load at the target over 0.05 rad); "
        "computed-torque, hybrid (the motion along the surface): in [1/s^2] (default 400)",
    )
    parser.add_argument(
        "--kd",
        type=vector,
        help="pd: damping in [N m s/rad] / [N s/m] (default: 20 x each joint's inertia, or critical for a given --kp); "
        "computed-torque, hybrid: in [1/s] (default 40)",
    )
    parser.add_argument(
        "--actuated",
        help="pd, computed-torque, lqr: the actuated joints, comma-separated (default: the file's actuated joints, else "
        "all); the others get no torque",
    )
    _add_hybrid_arguments(parser)


def _add_ground_arguments(parser: argparse.ArgumentParser) -> None:
    """``--ground``, ``--friction`` and ``--contact`` (docs/contact.md)."""
    parser.add_argument(
        "--ground",
        type=float,
        nargs="?",
        const=...,  # given without a value: the file's plane
        metavar="HEIGHT",
        help="stand the robot on a flat ground at this height in [m] (without a value: the MJCF file's plane, "
        "else height 0; the summary says which): point contacts with Coulomb friction; the summary gives peak "
        "normal force, slip and penetration",
    )
    parser.add_argument(
        "--friction", type=float, help="with --ground: the friction coefficient mu (default: the file's plane's, else 1)"
    )
    parser.add_argument(
        "--contact",
        metavar="FRAME[,...]",
        help="with --ground: the frames that touch it, comma-separated (default: the URDF's collision spheres and boxes)",
    )


def _ground(arguments: argparse.Namespace, robot: Robot) -> dict:
    """``ground=`` and ``contacts=`` of ``--ground``, ``--friction`` and ``--contact``."""
    if arguments.ground is None:
        for flag, value in (("--contact", arguments.contact), ("--friction", arguments.friction)):
            if value is not None:
                raise InputError(flag, "given only with --ground", repr(value))
        return {}
    from robodyn.sim.ground import asked_ground

    height = None if arguments.ground is ... else arguments.ground
    ground = asked_ground(robot, height=height, friction=arguments.friction)
    contacts = "collision" if arguments.contact is None else [name.strip() for name in arguments.contact.split(",")]
    return {"ground": ground, "contacts": contacts}


def _add_hybrid_arguments(parser: argparse.ArgumentParser) -> None:
    """``--force``, ``--surface``, ``--along``, ``--frequency`` of ``--controller hybrid``."""
    parser.add_argument("--force", dest="normal_force", type=float, help="hybrid: the normal force pressing the surface, in [N]")
    parser.add_argument(
        "--surface",
        metavar="X,Y,Z:NX,NY,NZ",
        help="hybrid: the surface, a point of it in [m] and its normal toward the robot (world axes); the frame "
        "(--frame, default the end effector) slides on it without friction and starts on it",
    )
    parser.add_argument(
        "--along",
        metavar="DX,DY,DZ[:EX,EY,EZ]",
        help="hybrid: the motion along the surface, X(t) = middle + D sin(2 pi f t) + E cos(2 pi f t), in [m] (a circle: "
        "D, E of one length at right angles; default: hold the middle)",
    )
    parser.add_argument("--frequency", type=float, help="hybrid: f of --along, in [Hz] (default 0.5)")


def _hybrid(arguments: argparse.Namespace) -> dict:
    """``force=``, ``surface=``, ``along=``, ``frequency=`` of the flags given."""
    given = {} if arguments.frequency is None else {"frequency": arguments.frequency}
    if arguments.normal_force is not None:
        given["force"] = arguments.normal_force
    if arguments.along is not None:
        parts = _vectors("--along", arguments.along, "DX,DY,DZ[:EX,EY,EZ] in [m]")
        given["along"] = parts[0] if len(parts) == 1 else parts
    if arguments.surface is not None:
        parts = _vectors("--surface", arguments.surface, "X,Y,Z:NX,NY,NZ (a point in [m], a colon, the normal)")
        if len(parts) != 2:
            raise InputError("--surface", "X,Y,Z:NX,NY,NZ (a point in [m], a colon, the normal)", repr(arguments.surface))
        given["surface"] = tuple(parts)
    return given


def _vectors(flag: str, text: str, expected: str) -> list[list[float]]:
    """``text``'s colon-separated lists of numbers (one stderr line, naming ``flag``, if not)."""
    try:
        return [vector(part) for part in text.split(":")]
    except argparse.ArgumentTypeError:
        raise InputError(flag, expected, repr(text)) from None


def _add_engine_arguments(parser: argparse.ArgumentParser) -> None:
    """``--engine`` and ``--control-period``."""
    parser.add_argument(
        "--engine",
        choices=["auto", "pinocchio", "compiled"],
        default=None,
        help="where the loop runs: auto (default: compiled when the whole loop runs in C, a C compiler exists and the "
        "robot was compiled before (--engine compiled compiles it), "
        "else pinocchio; the summary says which and why), pinocchio (Python over Pinocchio), compiled (C)",
    )
    parser.add_argument(
        "--control-period",
        dest="control_period",
        type=float,
        help="sample the controller every this many seconds (a whole number of --dt) and hold its torque "
        "(zero-order hold); default: evaluated at every integrator stage",
    )
