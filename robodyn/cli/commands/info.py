"""`robodyn info`: degrees of freedom, joints, limits and masses."""

from __future__ import annotations

import argparse

from robodyn.cli import report
from robodyn.cli.common import add_constraints_argument, add_model_arguments, load_robot
from robodyn.common.text import json_text


def add_parser(commands: argparse._SubParsersAction) -> None:
    """Add the command to the ``robodyn`` parser.

    Args:
        commands: The subparsers of the ``robodyn`` parser, from ``add_subparsers``.
    """
    parser = commands.add_parser("info", help="degrees of freedom, joints, limits and masses of a robot")
    add_model_arguments(parser)
    add_constraints_argument(parser)
    parser.add_argument("--json", action="store_true", help="print JSON")
    parser.set_defaults(run=run)


def run(arguments: argparse.Namespace) -> int:
    """Run ``robodyn info`` with the parsed ``arguments``; return the exit status.

    Args:
        arguments: The command line parsed by the parser :func:`add_parser` built.
    """
    robot = load_robot(arguments)
    if arguments.json:
        print(json_text(report.info_dict(robot)))
    else:
        print(report.info_text(robot))
    return 0
