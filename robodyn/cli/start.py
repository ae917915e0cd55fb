"""Where a motion starts: ``--q0`` values or an MJCF file's ``--keyframe``, one or the other."""

from __future__ import annotations

import argparse

import numpy as np

import robodyn
from robodyn.cli.common import vector
from robodyn.exceptions import InputError


def add_start_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``--q0`` and ``--keyframe`` to ``parser``.

    Args:
        parser: The command's parser.
    """
    parser.add_argument("--q0", type=vector, help="start (default: joints at 0 in their limits, an MJCF free body at its pose)")
    parser.add_argument("--keyframe", metavar="NAME", help="start at the MJCF file's <keyframe> NAME (its qpos); not with --q0")


def start_configuration(robot: robodyn.Robot, arguments: argparse.Namespace) -> list[float] | np.ndarray | None:
    """The start ``--q0`` or ``--keyframe`` gives (the library resolves the keyframe's name),
    or ``None`` for the robot's default start.

    Args:
        robot: The loaded robot.
        arguments: The parsed arguments of a command that called :func:`add_start_arguments`.

    Raises:
        InputError: If both are given, or the file has no keyframe of that name (its keyframes listed).
    """
    if arguments.keyframe is None:
        return arguments.q0
    if arguments.q0 is not None:
        raise InputError("--keyframe", "left out with --q0 (each sets the start)", "both")
    return robot.default_configuration(keyframe=arguments.keyframe)
