"""`robodyn view`: the live meshcat viewer."""

from __future__ import annotations

import argparse

from robodyn.cli.common import add_model_arguments, load_robot, vector


def add_parser(commands: argparse._SubParsersAction) -> None:
    """Add the command to the ``robodyn`` parser.

    Args:
        commands: The subparsers of the ``robodyn`` parser, from ``add_subparsers``.
    """
    parser = commands.add_parser("view", help="show a robot (and a trajectory) in a live meshcat viewer on 127.0.0.1")
    add_model_arguments(parser)
    parser.add_argument("--trajectory", help="trajectory file to play")
    parser.add_argument("--target", type=vector, metavar="X,Z|X,Y,Z", help="task target drawn as a red sphere, in [m]")
    parser.add_argument("--frame", help="frame whose path is drawn (default: the robot's end effector)")
    parser.add_argument("--seconds", type=float, help="stop after this many seconds (default: until Ctrl-C)")
    parser.set_defaults(run=run)


def run(arguments: argparse.Namespace) -> int:
    """Run ``robodyn view`` with the parsed ``arguments``; return the exit status.

    Args:
        arguments: The command line parsed by the parser :func:`add_parser` built.
    """
    from robodyn.trajectory import Trajectory
    from robodyn.viz.live import LiveViewer, wait

    robot = load_robot(arguments)
    trajectory = Trajectory.load(arguments.trajectory).for_robot(robot) if arguments.trajectory else None
    try:
        with LiveViewer() as viewer:
            viewer.show(robot, trajectory, target=arguments.target, frame=arguments.frame)
            print(f"meshcat viewer: {viewer.url}  (Ctrl-C to stop)", flush=True)
            wait(arguments.seconds)
    except KeyboardInterrupt:
        pass
    return 0
