"""The ``robodyn`` command: parses arguments, calls the library, prints the result.

Each command lives in :mod:`robodyn.cli.commands` (its arguments and a ``run`` handler).
Every robodyn error becomes one line on stderr and exit status 2 (``--debug`` shows the
traceback instead). Output files are written only after the work succeeded.
"""

from __future__ import annotations

import argparse
import os
import sys
import traceback
from collections.abc import Sequence

import robodyn
from robodyn.cli.commands import check, equations, excite, identify, info, lint, listing, record, simulate, torques, view, whatif
from robodyn.common.text import one_line_warnings, printable
from robodyn.exceptions import RobodynError

#: The commands, in the order ``robodyn --help`` lists them.
COMMANDS = (listing, info, equations, check, lint, simulate, record, view, torques, whatif, excite, identify)


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``robodyn`` command."""
    parser = argparse.ArgumentParser(prog="robodyn", description="Rigid-body robot dynamics from any URDF, verified.")
    parser.add_argument("--version", action="version", version=f"robodyn {robodyn.__version__}")
    parser.add_argument("--debug", action="store_true", help="show tracebacks of errors")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    for command in COMMANDS:
        command.add_parser(commands)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the ``robodyn`` command.

    Args:
        argv: Arguments without the program name; ``None`` reads ``sys.argv``.

    Returns:
        Exit status: 0 on success, 1 when a check fails, 2 on an error.
    """
    parser = build_parser()
    try:
        arguments = parser.parse_args(argv)
    except SystemExit as exit_:
        return int(exit_.code or 0)
    try:
        with one_line_warnings():
            return arguments.run(arguments)
    except RobodynError as error:
        if arguments.debug:
            traceback.print_exc()
        print(f"robodyn: error: {printable(error)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("robodyn: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # output piped into a reader that stopped (e.g. head)
        devnull = os.open(os.devnull, os.O_WRONLY)  # Python flushes stdout at exit: let it
        os.dup2(devnull, 1)  # write into the void, not raise again
        os.close(devnull)
        return 0


if __name__ == "__main__":
    sys.exit(main())
