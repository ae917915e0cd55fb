"""``robodyn.load``: the one door from a URDF (path, text, zoo or generated name) to a Robot.

The URDF is validated first (:mod:`robodyn.urdf.validation`); Pinocchio then builds the
model from the copy robodyn writes from the validated spec
(:func:`robodyn.urdf.normalised.normalised_urdf`: every number written by robodyn,
continuous joints as unbounded revolute ones, unit axes, canonical joint names ordered so
that a mimic's source comes first), with ``<mimic>`` honoured (Pinocchio's
``mimic=True``). Joint and frame names are restored after the build.

Before Pinocchio allocates its data, the memory it needs is estimated
(:func:`data_memory_estimate`); a model above ``max_dof`` degrees of freedom is refused
instead of exhausting the machine.

Every option of :func:`load` is kept in the robot's :class:`~robodyn.dynamics.options.LoadOptions`,
and every later build from the robot's source takes them all: :func:`rebuild` and
unpickling. A robot pickles by its source and options (registered with :mod:`copyreg`
here, beside the loader), never by Pinocchio pointers; :func:`restore` builds it again
once per process (:mod:`robodyn.dynamics.pickling`).
"""

from __future__ import annotations

import contextlib
import copyreg
import os
import sys
import tempfile
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import Any

import numpy as np
import pinocchio as pin

from robodyn.common.text import printable
from robodyn.constraints import check_frames, equality_notes, from_equalities
from robodyn.dynamics import engines, pickling
from robodyn.dynamics.inertia_rank import inertialess_joints
from robodyn.dynamics.joint_dynamics import apply_joint_dynamics
from robodyn.dynamics.mimic import has_mimic, mimic_expansion
from robodyn.dynamics.options import MAX_DOF, LoadOptions, load_options
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import RobodynWarning, URDFError
from robodyn.urdf.normalised import normalised_urdf
from robodyn.urdf.sources import URDFSource, locked_source, resolve_source, with_file_dynamics
from robodyn.urdf.validation import URDFSpec, parse_urdf


def pinocchio_xml(spec: URDFSpec) -> str:
    """The URDF text Pinocchio builds the model from (see :mod:`robodyn.urdf.normalised`).

    Args:
        spec: The validated URDF.
    """
    return normalised_urdf(spec)[0]


def data_memory_estimate(nv: int, njoints: int) -> int:
    """Bytes one Pinocchio ``Data`` needs for a model of ``nv`` velocities and ``njoints``
    joints (universe included), an upper bound of ``60 njoints nv² + 1600 nv² + 3.5 MB``.

    Fitted on Pinocchio 4.1 (growth of the peak resident size in ``createData``): chains
    and stars of 25, 40, 50, 100 and 150 joints took 5.0, 8.9, 13.5, 74.6 and 234 MB (chains
    and stars alike; measured in a process that imports Pinocchio only); the fit gives 4.0 GB
    for a 400-joint star (measured: 4.1 GB).

    Args:
        nv: Number of velocity coordinates.
        njoints: Number of joints, the universe included.
    """
    return int(60 * njoints * nv * nv + 1600 * nv * nv + 3_500_000)


def load(
    source: str | os.PathLike,
    *,
    floating_base: bool | None = None,
    gravity: Sequence[float] | None = None,
    check_inertia: bool = True,
    strict: bool = False,
    lock: dict[str, float] | None = None,
    threads: int | None = None,
    max_dof: int | None = None,
    max_bytes: int | None = None,
    xacro_args: Mapping[str, str] | None = None,
    packages: Mapping[str, str | os.PathLike] | None = None,
    armature: Mapping[str, float] | None = None,
    constraints: object = None,
    xacro_env: bool = False,
    engine: str | None = None,
) -> Robot:
    """Load a robot.

    Args:
        source: A URDF, ``.xacro`` or MJCF (``<mujoco>``) file path, such XML text, a zoo
            robot name (``"panda"``, ``"ur5"``, ...) or a generated robot's name
            (``"rp_arm"``); ``robodyn list`` prints the names. See docs/robot-files.md.
        floating_base: Give the root link a free-flyer joint. ``None``: true for zoo
            robots that walk, swim or fly, false otherwise.
        gravity: Gravity acceleration in the world frame, in [m/s²]; default the
            file's (MJCF ``<option gravity>``, zero under ``<flag gravity="disable"/>``),
            else ``(0, 0, -9.81)``.
        check_inertia: Refuse inertias that are not positive semi-definite on moving links
            (set false to load published models that have them).
        strict: Refuse what loads with a :class:`~robodyn.exceptions.RobodynWarning`
            otherwise (an inertia breaking the triangle inequality, a mimic of a joint
            that does not exist).
        lock: Joints to freeze, by name, at positions in [rad] / [m] (e.g. a gripper's
            fingers): they become fixed joints, and joints mimicking them follow.
        threads: Native threads for batches of states; default every available core.
        max_dof: Most degrees of freedom accepted; default :data:`MAX_DOF` (300). Above
            it the model is refused before Pinocchio allocates its data (which grows with
            the cube of the size: about 1.8 GB a thread at 300).
        max_bytes: Largest URDF accepted, in bytes; default 64 MiB or
            ``$ROBODYN_MAX_URDF_BYTES``.
        xacro_args: Arguments of a ``.xacro`` source, ``{name: value}`` (its ``<xacro:arg>``
            defaults otherwise).
        packages: Package folders, ``{package name: folder}``: where ``package://`` paths
            and ``$(find name)`` resolve, before ``$ROS_PACKAGE_PATH`` and the zoo's folders.
        armature: Rotor inertia reflected to joints, ``{joint name: value in [kg m²] or
            [kg]}``, added to what the file says.
        constraints: Constraints to add (:mod:`robodyn.constraints`: a ``PointAnchor``,
            ``FrameAnchor``, ``PointContact`` or a list of them), after those the file
            declares (MJCF ``<equality>``); :attr:`Robot.constraints` lists them all. See
            docs/constraints.md.
        xacro_env: Let a xacro source read environment variables (``$(env NAME)``,
            ``$(optenv NAME)``); without it they are refused. See docs/robot-files.md for
            everything a xacro may do.
        engine: ``"auto"`` (default; ``$ROBODYN_ENGINE`` may set another): the single
            calls (``tau``, ``M``, ``G``, ``C v + G``, forward dynamics) go through the robot's compiled kernels when they are built
            already (``robodyn.compile`` once, in any process: the cache), never building
            them, else through Pinocchio; the same checks, errors and numbers (to 1e-13),
            and ``robot.model`` is then read-only. ``"pinocchio"``: always Pinocchio (what
            a reference to compare compiled code with needs). See docs/compiled.md.

    Returns:
        The robot.

    Raises:
        UnknownRobotError: If the name is not a file or known robot.
        URDFError: If the URDF cannot be read, describes an impossible robot or is too
            large for the limits above.
        InputError: If ``gravity`` is not 3 finite numbers or ``lock`` not numbers, a
            constraint names a link the robot does not have (listing its links), or
            ``engine`` is not ``"auto"`` or ``"pinocchio"``.

    Warns:
        RobodynWarning: For what ``strict=True`` refuses.
    """
    folders = {str(name): os.fspath(folder) for name, folder in (packages or {}).items()}
    resolved = resolve_source(
        source,
        max_bytes=max_bytes,
        xacro_args=xacro_args,
        packages=folders,
        strict=strict,
        max_dof=max_dof,
        xacro_env=xacro_env,
    )
    floating = resolved.floating_base if floating_base is None else bool(floating_base)
    _report_equalities(resolved, strict)
    if lock:
        resolved = locked_source(resolved, lock, floating_base=floating, check_inertia=check_inertia, strict=strict)
    options = load_options(
        floating_base=floating,
        gravity=resolved.gravity if gravity is None else gravity,
        check_inertia=check_inertia,
        strict=strict,
        lock=lock,
        threads=threads,
        max_dof=max_dof,
        max_bytes=max_bytes,
        xacro_args=xacro_args,
        packages=folders,
        armature=armature,
        constraints=constraints,
        xacro_env=xacro_env,
        engine=engine,
    )
    return build_robot(resolved, options)


def _report_equalities(resolved: URDFSource, strict: bool) -> None:
    """Say in one line each what of a file's ``<equality>`` elements robodyn does not model
    (:func:`robodyn.constraints.equality_notes`); ``strict`` refuses it."""
    for note in equality_notes(resolved.equalities):
        if strict:
            raise URDFError(resolved.label, note)
        warnings.warn(printable(f"{resolved.label}: {note}"), RobodynWarning, stacklevel=3)


def rebuild(robot: Robot, *, urdf: str | None = None, label: str | None = None) -> Robot:
    """A new robot from ``robot``'s source and options: an independent copy, or (with
    ``urdf``) the same robot edited (a payload welded on, ...), named ``label``.

    Args:
        robot: The robot to copy.
        urdf: The edited URDF text, or ``None`` for an unchanged copy.
        label: The new robot's name (``None``: the source's).
    """
    source = (
        robot.source
        if urdf is None
        else replace(robot.source, text=urdf, label=label or robot.source.label, name=label or robot.name)
    )
    return build_robot(source, robot.options)


def restore(source: URDFSource, options: LoadOptions) -> Robot:
    """The robot built from ``source`` with ``options``, built once per process: what
    unpickling a robot calls (see :mod:`robodyn.dynamics.pickling`).

    Args:
        source: Where the URDF came from (:attr:`Robot.source`).
        options: How it was built (:attr:`Robot.options`).

    Returns:
        The (shared) robot.
    """
    return pickling.shared(source, options, build_robot)


def _reduce(robot: Robot) -> tuple[Any, ...]:
    """Pickle a robot by its source and options (:func:`restore` rebuilds it)."""
    return restore, (robot.source, robot.options)


copyreg.pickle(Robot, _reduce)


def build_model(spec: URDFSpec, label: str, *, floating: bool, mimic: bool) -> pin.Model:
    """The Pinocchio model of a validated spec, with the URDF's joint names.

    Args:
        spec: The validated URDF.
        label: The file or robot name, for the error.
        floating: Give the root a free-flyer joint.
        mimic: Build mimic joints as Pinocchio mimic joints (else every joint is free).

    Raises:
        URDFError: If Pinocchio refuses the model (with Pinocchio's reason).
    """
    xml, names = normalised_urdf(spec)
    with _captured_stderr() as captured:
        try:
            if floating:
                model = pin.buildModelFromXML(xml, pin.JointModelFreeFlyer(), "root_joint", mimic=mimic)
            else:
                model = pin.buildModelFromXML(xml, mimic=mimic)
        except (RuntimeError, ValueError) as error:
            model, refusal = None, str(error).strip()
    if model is None:
        reason = " ".join(line.strip() for line in captured.text().splitlines() if line.strip())
        raise URDFError(label, f"Pinocchio refused the model ({refusal}{'; ' + reason if reason else ''})")
    for index, name in enumerate(model.names):
        if name in names:
            model.names[index] = names[name]
    for frame in model.frames:  # joint frames only: a link may be named like a canonical joint
        if frame.type in (pin.FrameType.JOINT, pin.FrameType.FIXED_JOINT) and frame.name in names:
            frame.name = names[frame.name]
    return model


def build_robot(resolved: URDFSource, options: LoadOptions) -> Robot:
    """Build a robot from a resolved URDF source (what :func:`load` does after resolving).

    Args:
        resolved: The URDF and where it came from (its joints already locked).
        options: Every option of :func:`load` (``lock`` and ``max_bytes`` were applied
            when the source was resolved).

    Raises:
        URDFError: If the URDF describes an impossible robot or one above ``max_dof``.
    """
    floating = options.floating_base
    spec = parse_urdf(
        resolved.text,
        resolved.label,
        floating_base=floating,
        check_inertia=options.check_inertia,
        strict=options.strict,
        **resolved.mesh_context,
    )
    spec = with_file_dynamics(spec, resolved.label)
    _check_size(spec, resolved.label, floating, options.max_dof)
    model = build_model(spec, resolved.label, floating=floating, mimic=True)
    mimic = None
    if has_mimic(model, spec, floating):
        mimic = mimic_expansion(model, spec, build_model(spec, resolved.label, floating=floating, mimic=False))
    model.gravity.linear = np.array(options.gravity)
    if mimic is not None:
        mimic.model.gravity.linear = model.gravity.linear
    if model.nv == 0:
        raise URDFError(
            resolved.label, "the robot has no moving joint (floating_base=True gives its root six degrees of freedom)"
        )
    spec = apply_joint_dynamics(spec, model, mimic, options, resolved.label)
    name = spec.name if resolved.name == "robot" else resolved.name
    check_frames((*from_equalities(resolved.equalities), *options.constraints), list(spec.links), name)
    robot = Robot(model, spec=spec, source=resolved, options=options, name=name, mimic=mimic)
    engines.attach(robot)  # engine="auto": its compiled kernels, if they are built
    _report_inertialess(robot, resolved.label)
    return robot


def _report_inertialess(robot: Robot, label: str) -> None:
    """One warning line naming the joints whose motions together move no inertia at the
    neutral configuration (a singular mass matrix there; massless subtrees are reported
    by the URDF's validation)."""
    if robot.massless_joints:
        return
    joints = inertialess_joints(robot, robot.neutral_configuration())
    if joints:
        shown = ", ".join(repr(joint) for joint in joints)
        warnings.warn(
            printable(
                f"{label}: joints {shown} together move no inertia at the neutral configuration (point masses, "
                "no rotational inertia behind them): the mass matrix is singular there (forward dynamics there is refused)"
            ),
            RobodynWarning,
            stacklevel=4,
        )


def _check_size(spec: URDFSpec, label: str, floating: bool, max_dof: int) -> None:
    """Refuse a model whose Pinocchio data would not fit (before Pinocchio allocates it)."""
    nv = (6 if floating else 0) + sum(joint.type != "fixed" for joint in spec.joints.values())
    njoints = 1 + (1 if floating else 0) + sum(joint.type != "fixed" for joint in spec.joints.values())
    estimate = data_memory_estimate(nv, njoints)
    if nv > max_dof:
        raise URDFError(
            label,
            f"{nv} degrees of freedom need about {estimate / 1e9:.2g} GB for Pinocchio's data per thread, "
            f"above the limit of {max_dof} degrees of freedom (max_dof= raises it)",
        )


class _Captured:
    """What was written to stderr, read when the capture ends."""

    def __init__(self) -> None:
        self.content = ""

    def text(self) -> str:
        return self.content


@contextlib.contextmanager
def _captured_stderr():
    """Capture what C++ code writes to the process's stderr (file descriptor 2).

    Pinocchio's URDF parser prints its reason for refusing a model there, where Python
    cannot catch it; robodyn puts it into the error message instead.
    """
    with tempfile.TemporaryFile() as stream:
        sys.stderr.flush()
        saved = os.dup(2)
        captured = _Captured()
        try:
            os.dup2(stream.fileno(), 2)
            yield captured
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            stream.seek(0)
            captured.content = stream.read(4000).decode("utf-8", "replace")


__all__ = ["MAX_DOF", "build_model", "build_robot", "data_memory_estimate", "load", "pinocchio_xml", "rebuild", "restore"]
