"""What every command shares: number lists, the model arguments, loading, progress."""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np

import robodyn
from robodyn.exceptions import InputError


def vector(text: str) -> list[float]:
    """Parse ``"0.5,0.2"`` or ``"0.5 0.2"`` into floats."""
    tokens = text.replace(",", " ").split()
    try:
        return [float(token) for token in tokens]
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a list of numbers: {text!r}") from None


def add_model_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("model", help="URDF path, robot name (see 'robodyn list') or URDF text")
    base = parser.add_mutually_exclusive_group()
    base.add_argument(
        "--floating-base", dest="floating_base", action="store_true", default=None, help="give the root a free-flyer joint"
    )
    base.add_argument("--fixed-base", dest="floating_base", action="store_false", help="fix the root to the world")
    parser.add_argument(
        "--no-check-inertia", dest="check_inertia", action="store_false", help="accept physically impossible link inertias"
    )
    parser.add_argument(
        "--gravity", type=vector, metavar="GX,GY,GZ", help="gravity in the world frame, in [m/s²] (default 0,0,-9.81)"
    )


def load_robot(arguments: argparse.Namespace) -> robodyn.Robot:
    return robodyn.load(
        arguments.model,
        floating_base=arguments.floating_base,
        gravity=arguments.gravity,
        check_inertia=arguments.check_inertia,
    )


def state(robot: robodyn.Robot, values: list[float] | None, name: str, size: int, default: np.ndarray) -> np.ndarray:
    if values is None:
        return default
    if len(values) != size:
        raise InputError(f"--{name}", f"{size} values ({', '.join(robot.joint_names)})", f"{len(values)} values")
    return np.array(values)


def lock_values(text: str | None) -> dict[str, float] | None:
    """Parse ``--lock name=value,name2=value2`` (a bare name locks at 0)."""
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


class Progress:
    """A progress bar on stderr, shown once a derivation takes more than ``DELAY`` seconds."""

    DELAY = 0.5

    def __init__(self, label: str) -> None:
        self._label, self._start, self._shown = label, time.monotonic(), False

    def __call__(self, stage: str, done: int, total: int) -> None:
        if time.monotonic() - self._start < self.DELAY and not self._shown:
            return
        self._shown = True
        filled = int(20 * done / max(total, 1))
        sys.stderr.write(f"\r{self._label}: {stage:22s} [{'#' * filled}{'.' * (20 - filled)}] {done}/{total}")
        sys.stderr.flush()

    def close(self) -> None:
        if self._shown:
            sys.stderr.write("\n")
