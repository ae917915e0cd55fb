"""`robodyn identify`: base parameters of a model, or its parameters identified from data."""

from __future__ import annotations

import argparse

from robodyn.cli.common import add_model_arguments, load_robot
from robodyn.exceptions import InputError


def add_parser(commands: argparse._SubParsersAction) -> None:
    """Add the command to the ``robodyn`` parser.

    Args:
        commands: The subparsers of the ``robodyn`` parser, from ``add_subparsers``.
    """
    parser = commands.add_parser("identify", help="identify base inertial parameters from a trajectory with tau columns")
    add_model_arguments(parser)
    parser.add_argument("data", nargs="?", help="trajectory file (.csv or .npz) with q, v, a and tau columns")
    parser.add_argument("--method", choices=["ls", "wls", "physical"], default="ls", help="estimator (default ls)")
    parser.add_argument("--friction", action="store_true", help="also identify viscous and Coulomb friction per joint")
    parser.add_argument("--out", help="write the result as JSON to this file")
    parser.add_argument(
        "--urdf-out",
        help="with --method physical: write the identified URDF to this file (every body's <inertial> is refitted "
        "unless --bodies names the unknown ones; mass may move between links the data cannot tell apart)",
    )
    parser.add_argument(
        "--bodies",
        type=_links,
        action="extend",
        metavar="LINK[,LINK...]",
        help="identify only these bodies (link names; e.g. the link that carries an unknown payload); "
        "the others keep the URDF's values",
    )
    parser.add_argument("--base-parameters", action="store_true", help="print the base parameters of the model and stop")
    parser.add_argument("--format", choices=["text", "latex", "json"], default="text", help="with --base-parameters")
    parser.add_argument("--lock", help="freeze joints: name=value,... (e.g. panda_finger_joint1=0)")
    parser.set_defaults(run=run)


def _links(text: str) -> list[str]:
    return [name.strip() for name in text.split(",") if name.strip()]


def _refuse_what_is_not_used(arguments: argparse.Namespace) -> None:
    """``--base-parameters`` prints the model's base parameters and identifies nothing: what
    an identification takes is refused with it, and ``--format`` without it."""
    if arguments.base_parameters:
        unused = [
            name
            for name, given in (
                ("DATA", arguments.data is not None),
                ("--method", arguments.method != "ls"),
                ("--out", arguments.out is not None),
                ("--urdf-out", arguments.urdf_out is not None),
            )
            if given
        ]
        if unused:
            raise InputError("--base-parameters", "given without DATA, --method, --out and --urdf-out", ", ".join(unused))
    elif arguments.format != "text":
        raise InputError(
            "--format", "given with --base-parameters (an identification prints text, --out writes JSON)", arguments.format
        )


def run(arguments: argparse.Namespace) -> int:
    """Run ``robodyn identify`` with the parsed ``arguments``; return the exit status.

    Args:
        arguments: The command line parsed by the parser :func:`add_parser` built.
    """
    from robodyn.ident import base_parameters
    from robodyn.ident.render import render_base_parameters
    from robodyn.ident.run import identify_run
    from robodyn.trajectory import Trajectory

    if arguments.data is None and not arguments.base_parameters:
        raise InputError("DATA", "a trajectory file (or --base-parameters)", "nothing")
    _refuse_what_is_not_used(arguments)
    robot = load_robot(arguments)
    if arguments.base_parameters:
        base = base_parameters(robot, friction=arguments.friction, bodies=arguments.bodies)
        print(render_base_parameters(base, arguments.format), end="")
        return 0
    run = identify_run(
        robot,
        Trajectory.load(arguments.data).for_robot(robot),
        method=arguments.method,
        friction=arguments.friction,
        bodies=arguments.bodies,
        out=arguments.out,
        urdf_out=arguments.urdf_out,
    )
    print(run.text())
    return 0
