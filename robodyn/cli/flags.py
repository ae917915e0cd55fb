"""The one table from library parameter names to command-line flags.

The library's errors name the parameter a caller passed (``target``, ``max_dof=``); the
command line shows the flag its user typed (``--target``, ``--max-dof``). :func:`error_text`
rewrites an error's message with this table before the CLI prints it.
"""

from __future__ import annotations

import re

from robodyn.common.text import printable
from robodyn.exceptions import InputError, RobodynError

#: Library parameter name -> the flag that sets it.
FLAGS: dict[str, str] = {
    "ground": "--ground",
    "constraints": "--constraints",
    "controller": "--controller",
    "height": "--ground",
    "friction": "--friction",
    "contacts": "--contact",
    "integrator": "--integrator",
    "target": "--target",
    "frame": "--frame",
    "q0": "--q0",
    "keyframe": "--keyframe",
    "out": "--out",
    "scheduler": "--scheduler",
    "form": "--form",
    "format": "--format",
    "fps": "--fps",
    "bodies": "--bodies",
    "max_dof": "--max-dof",
    "at": "--at",
    "urdf_out": "--urdf-out",
    "method": "--method",
    "data": "DATA",
    "source": "MODEL",
    "posture": "--posture",
    "stiffness": "--stiffness",
    "damping": "--damping",
    "force_at": "--force-at",
    "external": "--force-at",
    "observer_gain": "--observer-gain",
    "observer": "--observer-gain",
    "limits": "--limits",
    "gain": "--gain",
    "threshold": "--threshold",
    "torque": "--torque",
    "plot": "--plot",
    "actuated": "--actuated",
    "q_eq": "--target",
    "xacro_args": "--xacro-arg",
    "packages": "--package",
    "start": "--start",
    "goal": "--goal",
    "intervals": "--intervals",
    "cost": "--cost",
    "velocity_limit": "--velocity-limit",
    "acceleration_limit": "--acceleration-limit",
    "reference": "--reference",
    "engine": "--engine",
    "control_period": "--control-period",
    "kp": "--kp",
    "kd": "--kd",
    "force": "--force",
    "surface": "--surface",
    "along": "--along",
    "frequency": "--frequency",
}

#: Boolean keyword arguments a message suggests -> the switch that sets them.
SWITCHES: dict[str, str] = {
    "floating_base=False": "--fixed-base",
    "floating_base=True": "--floating-base",
    "check_inertia=False": "--no-check-inertia",
    "strict=True": "--strict",
    "joint_friction=False": "--no-joint-friction",
    "xacro_env=True": "--xacro-env",
}

#: Boolean parameters whose switch turns them off: an error asking for ``False`` names the switch.
OFF_SWITCHES: dict[str, str] = {"joint_friction": "--no-joint-friction"}

#: ``name=`` or ``name='word'`` in a message: a keyword argument the library suggests.
_KEYWORD = re.compile(r"\b(" + "|".join(map(re.escape, FLAGS)) + r")=(?:'(\w+)'(?!\w))?")


def flag(parameter: str) -> str:
    """The flag of a library parameter (``"target"`` -> ``"--target"``); others unchanged.

    Args:
        parameter: The name of a library function's parameter.
    """
    return FLAGS.get(parameter, parameter)


def error_text(error: RobodynError) -> str:
    """The one-line message of ``error`` as the command line says it: flags, not parameters.

    An :class:`InputError` about a parameter in :data:`FLAGS` names its flag; a keyword
    argument the message suggests (``form='compact'``) becomes the flag (``--form compact``),
    a boolean one (``floating_base=False``) its switch (``--fixed-base``).

    Args:
        error: The library's error.
    """
    text = str(error)
    if isinstance(error, InputError) and error.argument in FLAGS:
        text = printable(f"{flag(error.argument)} must be {error.expected}, got {error.received}.")
    elif isinstance(error, InputError) and error.argument in OFF_SWITCHES and error.expected.startswith("False "):
        needed = error.expected.removeprefix("False ")
        text = printable(f"{OFF_SWITCHES[error.argument]} is needed {needed}, got {error.received}.")
    return command_line_text(text)


def command_line_text(text: str) -> str:
    """A library sentence as the command line says it: a keyword argument it suggests
    (``engine='compiled'``) becomes the flag (``--engine compiled``), a boolean one
    (``joint_friction=False``) its switch (``--no-joint-friction``).

    Args:
        text: The library's sentence (a warning, a note).
    """
    for keyword, switch in SWITCHES.items():
        text = text.replace(keyword, switch)
    return _KEYWORD.sub(_keyword_flag, text)


def _keyword_flag(match: re.Match[str]) -> str:
    name, value = match.group(1), match.group(2)
    if value:  # form='compact' -> --form compact
        return f"{FLAGS[name]} {value}"
    rest = match.string[match.end() :]
    return FLAGS[name] if not rest or rest[0] == " " else f"{FLAGS[name]} "  # scheduler='x' -> --scheduler 'x'
