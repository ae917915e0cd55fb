"""Text that is safe on a terminal: the one escaping function for names from a URDF.

A URDF is untrusted input: its link and joint names, its robot name and its numbers'
text can hold newlines, carriage returns, ANSI escape sequences (``ESC [ 31 m``), C1
control characters (``\\x9b`` is a one-byte CSI on many terminals) and Unicode bidi
overrides (U+202E reverses what follows). Printed raw, they forge lines ("robodyn: ok:
...") or hide text. Every message that can contain such a name goes through
:func:`printable` (names in messages through :func:`quoted`): each such character becomes
a visible ``\\xNN`` / ``\\uNNNN`` escape, so one message is one visible line.

The implementation lives in :mod:`robodyn.exceptions` (the lowest layer, so that every
exception message is escaped by the same function); this module is its public home.
"""

from __future__ import annotations

import contextlib
import sys
import warnings
from collections.abc import Iterator

from robodyn.exceptions import RobodynWarning, printable, quoted


def is_printable(text: str) -> bool:
    """Whether ``text`` is already safe (:func:`printable` would not change it)."""
    return printable(text) == text


def printable_lines(text: object) -> str:
    """Multi-line text (a table, a report) with :func:`printable` applied to each line:
    its own line breaks are kept, any other control character is escaped."""
    return "\n".join(printable(line) for line in str(text).split("\n"))


@contextlib.contextmanager
def one_line_warnings() -> Iterator[None]:
    """Show each :class:`~robodyn.exceptions.RobodynWarning` as one escaped stderr line.

    ``robodyn: warning: <message>`` instead of Python's two-line ``file:line: category``
    format, each problem once (robodyn and the reference may both find it); other warnings
    keep Python's format. The previous hook is restored on exit.
    """
    with warnings.catch_warnings():
        previous = warnings.showwarning
        shown: set[str] = set()

        def show(message, category, filename, lineno, file=None, line=None):
            if issubclass(category, RobodynWarning):
                text = printable(message)
                problem = text.split(": ", 1)[-1]  # the same problem found by two loaders: once
                if problem not in shown:
                    shown.add(problem)
                    print(f"robodyn: warning: {text}", file=file or sys.stderr)
            else:
                previous(message, category, filename, lineno, file, line)

        warnings.showwarning = show
        yield


__all__ = ["is_printable", "one_line_warnings", "printable", "printable_lines", "quoted"]
