"""The ``robodyn`` command: parses arguments, calls the library, prints the result.

Each command lives in :mod:`robodyn.cli.commands` (its arguments and a ``run`` handler).
Every robodyn error becomes one line on stderr and exit status 2 (``--debug``, before or
after the command's name, shows the traceback too). Output files are written only after
the work succeeded. Negative numbers follow options as written (``--q -0.5,0.1``), and
every numeric option is checked against its range
(:data:`robodyn.cli.common.RANGES`) before any work.
"""

from __future__ import annotations

import argparse
import os
import sys
import traceback
from collections.abc import Sequence

import robodyn
from robodyn.cli.commands import (
    check,
    equations,
    excite,
    identify,
    info,
    linearize,
    lint,
    listing,
    observe,
    optimize,
    record,
    simulate,
    torques,
    view,
    whatif,
)
from robodyn.cli.common import attach_negative_values, check_ranges
from robodyn.cli.flags import error_text
from robodyn.exceptions import RobodynError, one_line_warnings

#: The commands, in the order ``robodyn --help`` lists them.
COMMANDS = (
    listing, info, equations, check, lint, simulate, observe, record, view, torques, whatif, excite, identify, linearize,
    optimize,
)  # fmt: skip


class _CommandParser(argparse.ArgumentParser):
    """A command's parser that takes its positionals among its options in any order
    (``identify MODEL --floating-base DATA``: argparse alone fills an optional positional only
    from the run of positionals before the first option and refuses ``DATA`` after it)."""

    _intermixing = False

    def parse_known_args(  # type: ignore[override]
        self, args: Sequence[str] | None = None, namespace: argparse.Namespace | None = None
    ) -> tuple[argparse.Namespace, list[str]]:
        if self._intermixing:  # parse_known_intermixed_args calls back here
            return super().parse_known_args(args, namespace)
        self._intermixing = True
        try:
            return self.parse_known_intermixed_args(args, namespace)
        finally:
            self._intermixing = False


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``robodyn`` command."""
    parser = argparse.ArgumentParser(prog="robodyn", description="Rigid-body robot dynamics from any URDF, verified.")
    parser.add_argument("--version", action="version", version=f"robodyn {robodyn.__version__}")
    parser.add_argument("--debug", action="store_true", help="show tracebacks of errors")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND", parser_class=_CommandParser)

    for command in COMMANDS:
        command.add_parser(commands)
    for subparser in commands.choices.values():  # --debug after the command's name, too
        subparser.add_argument("--debug", action="store_true", default=argparse.SUPPRESS, help="show tracebacks of errors")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the ``robodyn`` command.

    Args:
        argv: Arguments without the program name; ``None`` reads ``sys.argv``.

    Returns:
        Exit status: 0 on success, 1 when a check fails, 2 on an error.
    """
    parser = build_parser()
    argv = attach_negative_values(parser, sys.argv[1:] if argv is None else list(argv))
    try:
        arguments = parser.parse_args(argv)
    except SystemExit as exit_:
        return int(exit_.code or 0)
    try:
        check_ranges(arguments)
        with one_line_warnings():
            return arguments.run(arguments)
    except RobodynError as error:
        if arguments.debug:
            traceback.print_exc()
        print(f"robodyn: error: {error_text(error)}", file=sys.stderr)
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
