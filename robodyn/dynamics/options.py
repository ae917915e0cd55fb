"""How a robot is built from its URDF: every option :func:`robodyn.load` takes, in one record.

A :class:`LoadOptions` goes with the robot (:attr:`robodyn.Robot.options`) and is passed
everywhere a robot is built again from its source: :func:`robodyn.dynamics.loading.rebuild`
(copies, payloads, identified models) and unpickling, so a rebuilt robot is built exactly
as the original was.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from robodyn.common.constants import STANDARD_GRAVITY
from robodyn.common.inputs import as_state
from robodyn.common.text import quoted
from robodyn.constraints import Constraint, as_constraints
from robodyn.dynamics.engines import check_engine
from robodyn.exceptions import InputError
from robodyn.urdf.sources import max_urdf_bytes

#: Most degrees of freedom loaded by default. Pinocchio's data grows with njoints × nv²
#: (:func:`robodyn.dynamics.loading.data_memory_estimate`): about 1.8 GB a thread at 300,
#: so the few copies a program holds (one a thread, the mimic expansion) fit on a 24 GB
#: machine, where a 400-joint star needs 4 GB a copy and a 999-joint chain exhausted
#: 24 GB. ``max_dof=`` overrides it.
MAX_DOF = 300


@dataclass(frozen=True)
class LoadOptions:
    """How a robot was built from its source (what :func:`robodyn.load` was given, resolved).

    Attributes:
        floating_base: Whether the root got a free-flyer joint.
        gravity: Gravity in the world frame, in [m/s²]: ``gravity=`` if given, else the
            file's (MJCF ``<option gravity>``), else (0, 0, −9.81).
        check_inertia: Whether impossible inertias on moving links were refused.
        threads: Native threads for batches (``None``: every available core).
        strict: Whether warnings of the validator were treated as errors.
        lock: Joints frozen, as ``(name, position in [rad] or [m])`` pairs. They are fixed
            joints of the robot's source (:attr:`robodyn.Robot.urdf`) already, so building
            from that source does not lock them again.
        max_dof: Most degrees of freedom accepted (:data:`MAX_DOF` by default).
        max_bytes: Largest URDF accepted when it was read, in bytes (the source, read
            once, carries the text: building from it reads no file).
        xacro_args: Arguments a ``.xacro`` source was expanded with, as ``(name, value)``
            pairs (the source carries the expanded text).
        packages: Package folders ``package://`` and ``$(find …)`` resolved through, as
            ``(package name, folder)`` pairs, before ``$ROS_PACKAGE_PATH`` and the zoo's.
        armature: Rotor inertia added at joints, as ``(joint name, value in [kg m²] or
            [kg])`` pairs (on top of what the file says).
        constraints: Constraints added to the robot (:mod:`robodyn.constraints`), after
            those its file declares.
        xacro_env: Whether a xacro source could read environment variables (the source
            carries the expanded text).
        engine: Who answers the single calls (:mod:`robodyn.dynamics.engines`): ``"auto"``
            the robot's compiled kernels when they are built already (never building them),
            else Pinocchio; ``"pinocchio"`` always Pinocchio.
    """

    floating_base: bool
    gravity: tuple[float, float, float] = STANDARD_GRAVITY
    check_inertia: bool = True
    threads: int | None = None
    strict: bool = False
    lock: tuple[tuple[str, float], ...] = ()
    max_dof: int = MAX_DOF
    max_bytes: int | None = None
    xacro_args: tuple[tuple[str, str], ...] = ()
    packages: tuple[tuple[str, str], ...] = ()
    armature: tuple[tuple[str, float], ...] = ()
    constraints: tuple[Constraint, ...] = ()
    xacro_env: bool = False
    engine: str = "auto"


def load_options(
    *,
    floating_base: bool,
    gravity: Sequence[float] | None = None,
    check_inertia: bool = True,
    strict: bool = False,
    lock: Mapping[str, float] | None = None,
    threads: int | None = None,
    max_dof: int | None = None,
    max_bytes: int | None = None,
    xacro_args: Mapping[str, str] | None = None,
    packages: Mapping[str, str] | None = None,
    armature: Mapping[str, float] | None = None,
    constraints: object = None,
    xacro_env: bool = False,
    engine: str | None = None,
) -> LoadOptions:
    """The options :func:`robodyn.load` was given, with the defaults filled in.

    Arguments as for :func:`robodyn.load` (``floating_base`` already decided).

    Raises:
        InputError: If ``gravity`` is not 3 finite numbers, ``constraints`` not constraints,
            or ``engine`` not one of :data:`robodyn.dynamics.engines.ENGINES`.
    """
    vector = STANDARD_GRAVITY if gravity is None else tuple(float(g) for g in as_state(gravity, "gravity", 3))
    return LoadOptions(
        floating_base=bool(floating_base),
        gravity=(vector[0], vector[1], vector[2]),
        check_inertia=bool(check_inertia),
        threads=threads,
        strict=bool(strict),
        lock=tuple((name, float(position)) for name, position in (lock or {}).items()),
        max_dof=MAX_DOF if max_dof is None else max_dof,
        max_bytes=max_urdf_bytes(max_bytes),
        xacro_args=tuple((str(name), str(value)) for name, value in (xacro_args or {}).items()),
        packages=tuple((str(name), str(folder)) for name, folder in (packages or {}).items()),
        armature=tuple((str(name), _armature(name, value)) for name, value in (armature or {}).items()),
        constraints=as_constraints(constraints),
        xacro_env=bool(xacro_env),
        engine=check_engine(engine),
    )


def _armature(name: object, value: object) -> float:
    """One ``armature=`` value as a float in [kg m²] / [kg].

    Raises:
        InputError: If it is not a finite number ≥ 0 (naming the joint).
    """
    try:
        number = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        number = math.nan
    if not (math.isfinite(number) and number >= 0):
        raise InputError(f"armature[{quoted(str(name))}]", "a finite number >= 0 in [kg m²] or [kg]", repr(value))
    return number


__all__ = ["MAX_DOF", "LoadOptions", "load_options"]
