"""The roots of robodyn's errors and warnings, and how the CLI shows a warning."""

from __future__ import annotations

import contextlib
import sys
import warnings
from collections.abc import Iterator

from robodyn.common.text import printable


@contextlib.contextmanager
def one_line_warnings() -> Iterator[None]:
    """Show each :class:`RobodynWarning` as one escaped stderr line.

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


class RobodynError(Exception):
    """Base class of every error robodyn raises on purpose.

    Its message is always one printable line: whatever a subclass puts into it (names
    from a URDF included) passes through :func:`printable`.
    """

    def __str__(self) -> str:
        return printable(super().__str__())


class RobodynWarning(UserWarning):
    """A legal but suspicious input that robodyn accepts (``strict=True`` refuses it).

    Example: a positive semi-definite inertia that breaks the triangle inequality, which
    Pinocchio, Drake, pybullet and urdfdom all load.
    """
