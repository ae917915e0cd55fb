"""`robodyn check`: Pinocchio against the independent reference."""

from __future__ import annotations

import argparse

from robodyn.cli.common import (
    RANGES,
    Progress,
    add_constraints_argument,
    add_model_arguments,
    load_robot,
    package_arguments,
    xacro_arguments,
)
from robodyn.common.text import json_text


def add_parser(commands: argparse._SubParsersAction) -> None:
    """Add the command to the ``robodyn`` parser.

    Args:
        commands: The subparsers of the ``robodyn`` parser, from ``add_subparsers``.
    """
    parser = commands.add_parser("check", help="compare Pinocchio with the independent Lagrangian reference")
    add_model_arguments(parser)
    add_constraints_argument(parser)
    parser.add_argument(
        "--samples",
        type=int,
        default=100,
        help=f"random states within the joint limits, {RANGES['samples'].text()} (default 100)",
    )
    parser.add_argument("--seed", type=int, default=0, help=f"seed of the random states, {RANGES['seed'].text()} (default 0)")
    parser.add_argument(
        "--tolerance",
        type=float,
        default=1e-9,
        help=f"largest relative error accepted, {RANGES['tolerance'].text()} (default 1e-9)",
    )
    parser.add_argument(
        "--reference",
        metavar="URDF",
        help="build the reference from this URDF instead of the model's own (e.g. the true model of a suspect file); "
        "--xacro-arg, --package and --xacro-env read it too",
    )
    parser.add_argument("--json", action="store_true", help="print JSON")
    parser.set_defaults(run=run)


def run(arguments: argparse.Namespace) -> int:
    """Run ``robodyn check`` with the parsed ``arguments``; return the exit status.

    Args:
        arguments: The command line parsed by the parser :func:`add_parser` built.
    """
    from robodyn.common.text import printable, printable_lines
    from robodyn.verify.check import check_robot

    robot = load_robot(arguments)
    progress = Progress(f"checking {printable(robot.name)[:60]}")  # on a terminal only, after 0.5 s
    try:
        report = check_robot(
            robot,
            samples=arguments.samples,
            seed=arguments.seed,
            tolerance=arguments.tolerance,
            check_inertia=arguments.check_inertia,
            reference_source=_reference(arguments),
            progress=progress,
        )
    finally:
        progress.close()
    print(json_text(report.to_dict()) if arguments.json else printable_lines(report.text()))
    return 0 if report.passed else 1


def _reference(arguments: argparse.Namespace) -> str | None:
    """The ``--reference`` file, read with the model's ``--xacro-arg``, ``--package`` and
    ``--xacro-env`` (its text then), never without the packages the user named."""
    if arguments.reference is None or not (arguments.xacro_arg or arguments.package or arguments.xacro_env):
        return arguments.reference
    from robodyn.urdf.sources import resolve_source

    return resolve_source(
        arguments.reference,
        xacro_args=xacro_arguments(arguments.xacro_arg),
        packages=package_arguments(arguments.package),
        xacro_env=arguments.xacro_env,
    ).text
