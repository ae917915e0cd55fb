"""`robodyn lint`: every problem of a URDF (a xacro as its expansion, an MJCF file as robodyn reads it)."""

from __future__ import annotations

import argparse
import json

from robodyn.cli.common import MODEL_HELP, add_file_arguments, package_arguments, xacro_arguments
from robodyn.common.text import counted, printable


def add_parser(commands: argparse._SubParsersAction) -> None:
    """Add the command to the ``robodyn`` parser.

    Args:
        commands: The subparsers of the ``robodyn`` parser, from ``add_subparsers``.
    """
    parser = commands.add_parser("lint", help="every problem of a URDF at once (exit 1 if any error)")
    parser.add_argument("model", help=MODEL_HELP)
    parser.add_argument(
        "--floating-base", dest="floating_base", action="store_true", default=None, help="check as a floating-base robot"
    )
    parser.add_argument("--json", action="store_true", help="print JSON")
    add_file_arguments(parser)
    parser.set_defaults(run=run)


def run(arguments: argparse.Namespace) -> int:
    """Run ``robodyn lint`` with the parsed ``arguments``; return the exit status.

    Args:
        arguments: The command line parsed by the parser :func:`add_parser` built.
    """
    from robodyn.urdf.sources import lint_source

    problems = lint_source(
        arguments.model,
        floating_base=arguments.floating_base,
        xacro_args=xacro_arguments(arguments.xacro_arg) or None,
        packages=package_arguments(arguments.package) or None,
        xacro_env=arguments.xacro_env,
    )
    errors = sum(problem.severity == "error" for problem in problems)
    if arguments.json:
        print(
            json.dumps(
                {
                    "errors": errors,
                    "warnings": len(problems) - errors,
                    "problems": [{"severity": p.severity, "element": p.element, "rule": p.rule} for p in problems],
                },
                indent=2,
            )
        )
    else:
        for problem in problems:
            print(f"{problem.severity}: {problem}")
        print(
            f"{'<URDF text>' if arguments.model.lstrip().startswith('<') else printable(arguments.model)}: "
            f"{counted(errors, 'error')}, {counted(len(problems) - errors, 'warning')}"
        )
    return 1 if errors else 0
