"""What every command shares: number lists, the model arguments, loading, progress,
numeric ranges and strict JSON."""

from __future__ import annotations

import argparse
import math
import re
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

import robodyn
from robodyn.common.text import counted
from robodyn.exceptions import InputError


def vector(text: str) -> list[float]:
    """Parse ``"0.5,0.2"`` or ``"0.5 0.2"`` into floats.

    Args:
        text: The option's value, numbers separated by commas or whitespace.
    """
    tokens = text.replace(",", " ").split()
    try:
        return [float(token) for token in tokens]
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a list of numbers: {text!r}") from None


#: What the model argument takes (every command that reads a robot).
MODEL_HELP = "a URDF, .xacro or MJCF file path, a robot name (see 'robodyn list'), or URDF/xacro/MJCF text"


def add_model_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the robot-file arguments every command shares (the model and how to read it) to ``parser``.

    Args:
        parser: The command's parser.
    """
    parser.add_argument("model", help=MODEL_HELP)
    base = parser.add_mutually_exclusive_group()
    base.add_argument(
        "--floating-base", dest="floating_base", action="store_true", default=None, help="give the root a free-flyer joint"
    )
    base.add_argument("--fixed-base", dest="floating_base", action="store_false", help="fix the root to the world")
    parser.add_argument(
        "--no-check-inertia", dest="check_inertia", action="store_false", help="accept physically impossible link inertias"
    )
    parser.add_argument(
        "--gravity",
        type=vector,
        metavar="GX,GY,GZ",
        help="gravity in the world frame, in [m/s²] (default: the file's, else 0,0,-9.81)",
    )
    parser.add_argument(
        "--strict", action="store_true", help="refuse what robodyn otherwise loads with a warning (e.g. the triangle inequality)"
    )
    parser.add_argument(
        "--max-dof",
        type=int,
        dest="max_dof",
        help="largest number of degrees of freedom to build (Pinocchio's memory grows as nv²; default 300)",
    )
    add_file_arguments(parser)


def add_file_arguments(parser: argparse.ArgumentParser) -> None:
    """``--xacro-arg NAME:=VALUE`` and ``--package NAME=DIR`` (each repeatable), ``--xacro-env``.

    Args:
        parser: The command's parser.
    """
    parser.add_argument(
        "--xacro-arg",
        dest="xacro_arg",
        action="append",
        metavar="NAME:=VALUE",
        help="a xacro argument of a .xacro model (repeatable)",
    )
    parser.add_argument(
        "--xacro-env",
        dest="xacro_env",
        action="store_true",
        help="let a xacro model read environment variables ($(env NAME), $(optenv NAME)); refused otherwise",
    )
    parser.add_argument(
        "--package",
        dest="package",
        action="append",
        metavar="NAME=DIR",
        help="where ROS package NAME is, for package:// paths and $(find NAME) (repeatable; "
        "then $ROS_PACKAGE_PATH, then the zoo's folders)",
    )


def xacro_arguments(values: Sequence[str] | None) -> dict[str, str]:
    """Parse ``--xacro-arg NAME:=VALUE`` options into ``{NAME: VALUE}``.

    Args:
        values: The repeated option's values (``None`` when not given).

    Raises:
        InputError: For a value without ``:=`` or with an empty name.
    """
    arguments = {}
    for item in values or []:
        name, separator, value = item.partition(":=")
        if not separator or not name.strip():
            raise InputError("--xacro-arg", "NAME:=VALUE", repr(item))
        arguments[name.strip()] = value
    return arguments


def package_arguments(values: Sequence[str] | None) -> dict[str, str]:
    """Parse ``--package NAME=DIR`` options into ``{NAME: DIR}``.

    Args:
        values: The repeated option's values (``None`` when not given).

    Raises:
        InputError: For a value without ``=``, with an empty name or folder.
    """
    packages = {}
    for item in values or []:
        name, separator, folder = item.partition("=")
        if not separator or not name.strip() or not folder.strip() or "/" in name:
            raise InputError("--package", "NAME=DIR (a package name and its folder)", repr(item))
        packages[name.strip()] = folder.strip()
    return packages


def add_constraints_argument(parser: argparse.ArgumentParser) -> None:
    """``--constraints FILE``: loop closures, welds and contacts added to the robot (docs/constraints.md).

    Args:
        parser: The command's parser.
    """
    parser.add_argument(
        "--constraints",
        metavar="FILE",
        help="a YAML file of anchor, weld and contact lists added to the robot's constraints, e.g. the loop "
        "of a linkage written as a URDF (docs/constraints.md)",
    )


def constraints_file(arguments: argparse.Namespace) -> tuple | None:
    """The constraints of ``--constraints FILE`` (``None`` when not given, or for a command without it).

    Args:
        arguments: The parsed arguments.
    """
    path = getattr(arguments, "constraints", None)
    if path is None:
        return None
    from robodyn.constraints.files import read_constraints

    return read_constraints(Path(path))


def load_robot(arguments: argparse.Namespace) -> robodyn.Robot:
    """The robot of a command's model arguments (and its ``--lock`` and ``--constraints``, where it has them).

    Args:
        arguments: The parsed arguments of a command that called :func:`add_model_arguments`.
    """
    return robodyn.load(
        arguments.model,
        floating_base=arguments.floating_base,
        gravity=arguments.gravity,
        check_inertia=arguments.check_inertia,
        strict=arguments.strict,
        max_dof=arguments.max_dof,
        lock=lock_values(getattr(arguments, "lock", None)),
        xacro_args=xacro_arguments(getattr(arguments, "xacro_arg", None)) or None,
        packages=package_arguments(getattr(arguments, "package", None)) or None,
        xacro_env=bool(getattr(arguments, "xacro_env", False)),
        constraints=constraints_file(arguments),
    )


def state(robot: robodyn.Robot, values: list[float] | None, name: str, size: int, default: np.ndarray) -> np.ndarray:
    """The values of flag ``--name`` as an array of ``size`` (``default`` when not given).

    Args:
        robot: The loaded robot (its joint names go into the error).
        values: The flag's numbers (``None`` when not given).
        name: The flag's name without ``--``, e.g. ``"q"``.
        size: How many values the flag takes (e.g. ``robot.nq`` or ``robot.nv``).
        default: The array returned when the flag is not given.

    Raises:
        InputError: Naming the flag and the joints, when the count is not ``size``.
    """
    if values is None:
        return default
    if len(values) != size:
        raise InputError(f"--{name}", f"{counted(size, 'value')} ({', '.join(robot.joint_names)})", counted(len(values), "value"))
    return np.array(values)


def lock_values(text: str | None) -> dict[str, float] | None:
    """Parse ``--lock name=value,name2=value2`` (a bare name locks at 0).

    Args:
        text: The option's value (``None`` or empty when not given).
    """
    if not text:
        return None
    locked = {}
    for item in text.split(","):
        name, _, value = item.partition("=")
        try:
            locked[name.strip()] = float(value) if value else 0.0
        except ValueError:
            raise InputError("--lock", "name=value pairs with numbers", repr(item)) from None
    return locked


def warn(lines: Sequence[str]) -> None:
    """Each line as ``robodyn: warning: <line>`` on stderr.

    Args:
        lines: The warnings, one a line.
    """
    for line in lines:
        print(f"robodyn: warning: {line}", file=sys.stderr)


class Progress:
    """A progress bar on stderr, shown once a derivation takes more than ``DELAY`` seconds,
    and only when stderr is a terminal: redraws with ``\\r`` would clutter a captured log
    (CI, a file), so there nothing is written and an error stays alone on stderr."""

    DELAY = 0.5

    def __init__(self, label: str) -> None:
        self._label, self._start, self._shown = label, time.monotonic(), False
        self._terminal = _is_terminal(sys.stderr)

    def __call__(self, stage: str, done: int, total: int) -> None:
        if not self._terminal or (time.monotonic() - self._start < self.DELAY and not self._shown):
            return
        self._shown = True
        filled = int(20 * done / max(total, 1))
        sys.stderr.write(f"\r{self._label}: {stage:22s} [{'#' * filled}{'.' * (20 - filled)}] {done}/{total}")
        sys.stderr.flush()

    def close(self) -> None:
        if self._shown:
            sys.stderr.write("\n")


def _is_terminal(stream: object) -> bool:
    isatty = getattr(stream, "isatty", None)
    try:
        return bool(isatty()) if callable(isatty) else False
    except (OSError, ValueError):  # a closed stream
        return False


# --------------------------------------------------------------------------------------
# Numbers as people write them: negative values after an option, ranges, valid JSON
# --------------------------------------------------------------------------------------
_NUMBER_LIST = re.compile(r"^[-+]?(\d|\.\d|inf|nan)", re.IGNORECASE)


def attach_negative_values(parser: argparse.ArgumentParser, argv: Sequence[str]) -> list[str]:
    """``["--q", "-0.5,0.1"]`` → ``["--q=-0.5,0.1"]`` for every option that takes a value.

    argparse reads a token starting with ``-`` as an option unless it is a single plain
    number; a list like ``-0.5,0.1`` (or ``-9.81,0,0``) must be attached to its option
    with ``=``, which this does for every option of any command that takes one value.

    Args:
        parser: The ``robodyn`` parser (its subcommands' options are seen too).
        argv: The command line without the program name.
    """
    takes_value = _value_options(parser)
    result: list[str] = []
    index = 0
    while index < len(argv):
        token = argv[index]
        following = argv[index + 1] if index + 1 < len(argv) else None
        if token in takes_value and following is not None and following.startswith("-") and _NUMBER_LIST.match(following):
            result.append(f"{token}={following}")
            index += 2
            continue
        result.append(token)
        index += 1
    return result


def _value_options(parser: argparse.ArgumentParser) -> set[str]:
    options: set[str] = set()
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for subparser in action.choices.values():
                options |= _value_options(subparser)
        elif action.option_strings and action.nargs is None and isinstance(action, argparse._StoreAction):
            options.update(name for name in action.option_strings if name.startswith("--"))
    return options


@dataclass(frozen=True)
class Range:
    """The values a numeric option accepts: ``low`` to ``high``, each end open or closed."""

    low: float
    high: float
    unit: str = ""
    low_open: bool = False
    high_open: bool = False
    integer: bool = False

    def __contains__(self, value: float) -> bool:
        if not math.isfinite(value):
            return False
        above = value > self.low if self.low_open else value >= self.low
        below = value < self.high if self.high_open else value <= self.high
        return above and below

    def text(self) -> str:
        """E.g. ``"in (0, 240] fps"`` or ``"an integer in [1, 100000]"``."""
        unit = f" {self.unit}" if self.unit else ""
        low, high = (f"{int(x)}" if self.integer else f"{x:g}" for x in (self.low, self.high))
        interval = f"{'(' if self.low_open else '['}{low}, {high}{')' if self.high_open else ']'}"
        return f"{'an integer' if self.integer else 'a number'} in {interval}{unit}"


#: The accepted range of every numeric option of every command, by its ``dest``
#: (``equations --precision`` is checked by the equations command itself: 1 to 17).
RANGES: dict[str, Range] = {
    "dt": Range(1e-6, 1.0, "s"),
    "duration": Range(0.0, 3600.0, "s", low_open=True),
    "samples": Range(1, 100_000, integer=True),
    "seed": Range(0, 2**63 - 1, integer=True),
    "tolerance": Range(0.0, 1.0, low_open=True, high_open=True),
    "fps": Range(0.0, 240.0, "fps", low_open=True),
    "seconds": Range(0.0, 86_400.0, "s", low_open=True),
    "max_dof": Range(1, 100_000, integer=True),
}
#: Per-entry ranges of list options.
LIST_RANGES: dict[str, Range] = {
    "payloads": Range(0.0, 1e4, "kg"),
    "force": Range(-1e6, 1e6, "N"),
    "gravity": Range(-1e3, 1e3, "m/s²"),
    "target": Range(-1e3, 1e3),
}


def check_ranges(arguments: argparse.Namespace) -> None:
    """Refuse any numeric option outside its range (:data:`RANGES`), one line.

    Also ``--dt`` ≤ ``--duration`` where a command has both.

    Args:
        arguments: The parsed arguments.

    Raises:
        InputError: Naming the option, its range and the value given.
    """
    for dest, accepted in RANGES.items():
        value = getattr(arguments, dest, None)
        if value is not None and not isinstance(value, bool) and value not in accepted:
            raise InputError(f"--{dest.replace('_', '-')}", accepted.text(), f"{value:g}")
    for dest, accepted in LIST_RANGES.items():
        values = getattr(arguments, dest, None)
        if values is not None and not all(value in accepted for value in values):
            bad = next(value for value in values if value not in accepted)
            raise InputError(f"--{dest}", f"values each {accepted.text()}", f"{bad:g}")
    dt, duration = getattr(arguments, "dt", None), getattr(arguments, "duration", None)
    if dt is not None and duration is not None and dt > duration:
        raise InputError("--dt", f"at most --duration ({duration:g} s)", f"{dt:g} s")
