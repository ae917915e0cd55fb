"""Errors of what is around robodyn: a missing extra or tool, an output path, the viewer,
a Dask scheduler, LaTeX.
"""

from __future__ import annotations

from robodyn.common.text import printable, quoted
from robodyn.exceptions.base import RobodynError


class MissingExtraError(RobodynError, ImportError):
    """An optional dependency is not installed.

    Attributes:
        module: The module that could not be imported.
        extra: The robodyn extra that installs it.
        purpose: What it is needed for.
    """

    def __init__(self, module: str, extra: str, purpose: str):
        self.module = module
        self.extra = extra
        self.purpose = purpose
        super().__init__(
            f"{purpose} need {module!r}, which is not installed: the 'robodyn[{extra}]' extra "
            f"(pip install '.[{extra}]' in a clone of robodyn)."
        )


class OutputError(RobodynError, OSError):
    """An output file that robodyn refuses to write or cannot write; nothing was replaced.

    Attributes:
        path: The output path as given.
        reason: Why, e.g. ``"its folder does not exist"``.
    """

    def __init__(self, path: str, reason: str):
        self.path = path
        self.reason = reason
        super().__init__(f"cannot write {quoted(path)}: {reason}.")

    def __str__(self) -> str:  # OSError would format its own way
        return printable(self.args[0])


class MissingToolError(RobodynError, OSError):
    """An external program a feature needs is not installed.

    Attributes:
        tool: The program, e.g. ``"pdflatex"``.
        purpose: What it was needed for.
    """

    def __init__(self, tool: str, purpose: str, hint: str = ""):
        self.tool = tool
        self.purpose = purpose
        super().__init__(f"{purpose} needs {tool}, which is not installed{'; ' + hint if hint else ''}.")


class ViewerError(RobodynError):
    """Viewing failed or was refused: a recording, a still or video, the browser, the live viewer.

    Attributes:
        reason: What went wrong, with the offending values.
    """

    def __init__(self, reason: str):
        self.reason = reason
        super().__init__(reason)


class SchedulerError(RobodynError):
    """A Dask scheduler that cannot be used (Dask missing, address unreachable).

    Attributes:
        scheduler: The address or ``local:N`` given.
        reason: Why.
    """

    def __init__(self, scheduler: str, reason: str):
        self.scheduler = scheduler
        self.reason = reason
        super().__init__(f"scheduler={quoted(scheduler)}: {reason}.")


class TypesettingError(RobodynError):
    """The TeX engine refused a document robodyn wrote.

    Attributes:
        reason: The engine's first error line.
    """

    def __init__(self, reason: str):
        self.reason = reason
        super().__init__(f"pdflatex failed on the equations: {reason}")
