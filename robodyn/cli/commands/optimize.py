"""`robodyn optimize`: a minimum-effort or minimum-time rest-to-rest motion, written as a trajectory."""

from __future__ import annotations

import argparse
import sys

from robodyn.cli.common import Progress, add_model_arguments, load_robot, vector


def add_parser(commands: argparse._SubParsersAction) -> None:
    """Add the command to the ``robodyn`` parser.

    Args:
        commands: The subparsers of the ``robodyn`` parser, from ``add_subparsers``.
    """
    parser = commands.add_parser(
        "optimize", help="a rest-to-rest motion within the joint limits (multiple shooting, IPOPT), as a trajectory file"
    )
    add_model_arguments(parser)
    parser.add_argument("--start", type=vector, required=True, help="start configuration, comma-separated, in [rad] / [m]")
    parser.add_argument("--goal", type=vector, required=True, help="goal configuration, comma-separated, in [rad] / [m]")
    parser.add_argument("--duration", type=float, required=True, help="duration in [s] (with --cost time: its upper bound)")
    parser.add_argument("--intervals", type=int, default=50, help="shooting intervals (samples: intervals + 1; default 50)")
    parser.add_argument("--cost", choices=["effort", "time"], default="effort", help="minimise effort (default) or time")
    parser.add_argument(
        "--actuated",
        help="the joints the motors drive, comma-separated (default: the file's actuated joints, else all); the others "
        "get no torque",
    )
    parser.add_argument(
        "--no-joint-friction",
        dest="joint_friction",
        action="store_false",
        help="plan the rigid-body motion (default: with the joints' damping, as simulate applies it)",
    )
    parser.add_argument("--out", required=True, help="trajectory file to write (.csv or .npz)")
    parser.set_defaults(run=run)


def run(arguments: argparse.Namespace) -> int:
    """Run ``robodyn optimize`` with the parsed ``arguments``; return the exit status.

    Args:
        arguments: The command line parsed by the parser :func:`add_parser` built.
    """
    from robodyn.common.text import printable
    from robodyn.optimize import point_to_point

    robot = load_robot(arguments)
    progress = Progress(f"optimizing {printable(robot.name)[:60]}")
    try:
        motion = point_to_point(
            robot, arguments.start, arguments.goal, arguments.duration, intervals=arguments.intervals, cost=arguments.cost,
            actuated=None if arguments.actuated is None else [name.strip() for name in arguments.actuated.split(",")],
            joint_friction=arguments.joint_friction, progress=progress,
        )  # fmt: skip
    finally:
        progress.close()
    motion.trajectory.save(arguments.out)
    print(motion.text())
    print(f"wrote {printable(arguments.out)} ({len(motion.trajectory)} samples)", file=sys.stderr)
    return 0
