"""Where a URDF comes from: a path, URDF text, a zoo name, or a generated robot's name.

:func:`resolve_source` turns whatever the user passed to :func:`robodyn.load` (or to the
reference's ``load``) into the URDF text plus what is needed to read it: a label for
messages, the folder its relative mesh paths start from and the package folders for
``package://`` paths. This module does not import Pinocchio.
"""

from __future__ import annotations

import difflib
import math
import os
import re
import stat
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path

from robodyn.exceptions import RobodynWarning, UnknownRobotError, URDFError
from robodyn.urdf import zoo
from robodyn.urdf.edit import lock_joints
from robodyn.urdf.mjcf import mjcf_source
from robodyn.urdf.models import GENERATED
from robodyn.urdf.packages import PackageLookup, package_lookup
from robodyn.urdf.source_type import URDFSource
from robodyn.urdf.validation import Problem, URDFSpec, lint_urdf, parse_urdf
from robodyn.urdf.xacro_files import expand_xacro, is_xacro_text
from robodyn.urdf.xmltext import parse_number


def robot_names() -> list[str]:
    """Names :func:`robodyn.load` accepts: generated robots first, then the zoo."""
    return sorted(GENERATED) + zoo.zoo_names()


#: Largest URDF accepted by default, in bytes (the largest zoo URDF is under 1 MB);
#: ``max_bytes=`` or the ``ROBODYN_MAX_URDF_BYTES`` environment variable overrides it.
MAX_URDF_BYTES = 64 * 1024 * 1024


def max_urdf_bytes(max_bytes: int | None = None) -> int:
    """The size cap in force: ``max_bytes``, else ``$ROBODYN_MAX_URDF_BYTES``, else the default.

    Args:
        max_bytes: The cap asked for in bytes, or ``None``.
    """
    if max_bytes is not None:
        return int(max_bytes)
    setting = os.environ.get("ROBODYN_MAX_URDF_BYTES", "").strip()
    if setting.isascii() and setting.isdigit():
        return int(setting)
    return MAX_URDF_BYTES


def read_regular_file(path: Path, max_bytes: int, label: str | None = None) -> bytes:
    """The bytes of a regular file of at most ``max_bytes`` bytes, read without blocking.

    A FIFO, a device (``/dev/zero``, ``/dev/urandom``), a socket or a directory — also
    behind a symlink — is refused before it is opened (``os.stat`` follows links), then the
    file is opened with ``O_NONBLOCK`` and checked again (``fstat``: no swap between the
    two), and at most ``max_bytes + 1`` bytes are read.

    Args:
        path: The file.
        max_bytes: Largest size accepted, in bytes.
        label: The name in messages (``None``: the path).

    Raises:
        URDFError: If the file does not exist, is not a regular file, is larger than
            ``max_bytes`` or cannot be read (the message names the reason).
    """
    label = str(path) if label is None else label
    label = label if len(label) <= 300 else label[:300] + "..."  # a name too long to show
    try:
        if not stat.S_ISREG(os.stat(path).st_mode):
            raise URDFError(label, f"is not a regular file ({_kind(os.stat(path).st_mode)}); robodyn reads only files")
        descriptor = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
        with os.fdopen(descriptor, "rb") as stream:
            status = os.fstat(stream.fileno())
            if not stat.S_ISREG(status.st_mode):
                raise URDFError(label, f"is not a regular file ({_kind(status.st_mode)}); robodyn reads only files")
            if status.st_size > max_bytes:
                raise URDFError(label, f"is {status.st_size} bytes, more than the limit of {max_bytes} ({_OVERRIDE})")
            data = stream.read(max_bytes + 1)
    except FileNotFoundError:
        raise URDFError(label, "no such file") from None
    except OSError as error:
        raise URDFError(label, f"cannot be read ({error.__class__.__name__}: {error.strerror or error})") from None
    if len(data) > max_bytes:
        raise URDFError(label, f"is more than the limit of {max_bytes} bytes ({_OVERRIDE})")
    return data


_OVERRIDE = "max_bytes= or $ROBODYN_MAX_URDF_BYTES raises it"


def _kind(mode: int) -> str:
    for test, name in (
        (stat.S_ISDIR, "a directory"),
        (stat.S_ISFIFO, "a FIFO"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISSOCK, "a socket"),
    ):
        if test(mode):
            return name
    return "a special file"


def read_text(path: Path, max_bytes: int, label: str | None = None) -> str:
    """The UTF-8 text of a regular file of at most ``max_bytes`` bytes (see
    :func:`read_regular_file`).

    Args:
        path: The file.
        max_bytes: Largest size accepted, in bytes.
        label: The name in messages (``None``: the path).

    Raises:
        URDFError: As :func:`read_regular_file`, or if the file is not UTF-8 text.
    """
    data = read_regular_file(path, max_bytes, label)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as error:
        raise URDFError(str(path) if label is None else label, f"is not UTF-8 text (byte {error.start})") from None


def _read_file(path: Path, max_bytes: int, reading: _Reading | None = None) -> URDFSource:
    text = read_text(path, max_bytes)
    source = URDFSource(text, path.stem, str(path), path.resolve(), False, ())
    return _interpret(source, reading) if reading is not None else source


@dataclass(frozen=True)
class _Reading:
    """How a file or text is read: its limit, xacro arguments, package lookup, strictness."""

    limit: int
    xacro_args: Mapping[str, str] | None
    lookup: PackageLookup
    strict: bool
    interpret: bool = True
    max_dof: int | None = None
    xacro_env: bool = False


_ROOT_TAG = re.compile(r"<([A-Za-z_][\w.:-]*)")
_PROLOG = re.compile(r"<\?.*?\?>|<!--.*?-->", re.DOTALL)


def root_tag(text: str) -> str | None:
    """The name of the first element of XML text (after its declaration and comments).

    Args:
        text: The XML text.
    """
    head = _PROLOG.sub("", text[: 1 << 20])
    match = _ROOT_TAG.search(head)
    return match.group(1) if match else None


def _interpret(source: URDFSource, reading: _Reading) -> URDFSource:
    """A source read as what it is: xacro expanded, MJCF converted, SDF refused (as it was
    read, with ``reading.interpret`` false)."""
    if not reading.interpret:
        return source
    tag = root_tag(source.text)
    if tag == "sdf":
        raise URDFError(
            source.label,
            "the root element must be <robot>, not <sdf>: robodyn does not read SDF; convert it to URDF "
            "first (e.g. 'gz sdf -p model.sdf > model.urdf')",
        )
    if tag == "mujoco":
        return mjcf_source(
            source,
            strict=reading.strict,
            lookup=reading.lookup,
            max_dof=reading.max_dof,
            read_file=lambda path: read_text(path, reading.limit),
            max_bytes=reading.limit,
        )
    source = replace(source, package_dirs=reading.lookup)
    is_xacro = source.path is not None and source.path.suffix == ".xacro"
    if is_xacro or (tag == "robot" and is_xacro_text(source.text)):
        text = expand_xacro(
            path=source.path,
            text=source.text,
            label=source.label,
            args=reading.xacro_args,
            lookup=reading.lookup,
            read_file=lambda path: read_text(path, reading.limit),
            limit=reading.limit,
            env=reading.xacro_env,
        )
        name = source.name.removesuffix(".urdf") if is_xacro else source.name
        return replace(source, text=text, name=name, file_format="xacro")
    return source


def resolve_source(
    source: str | os.PathLike,
    *,
    max_bytes: int | None = None,
    xacro_args: Mapping[str, str] | None = None,
    packages: Mapping[str, str] | None = None,
    strict: bool = False,
    interpret: bool = True,
    max_dof: int | None = None,
    xacro_env: bool = False,
) -> URDFSource:
    """Find the URDF a source names.

    Args:
        source: A path to a URDF, ``.xacro`` or MJCF file, URDF / xacro / MJCF text, a zoo
            robot name (``"panda"``) or a generated robot's name (``"rp_arm"``).
        max_bytes: Largest file accepted, in bytes (files, text and each file a xacro
            includes); default ``$ROBODYN_MAX_URDF_BYTES`` or :data:`MAX_URDF_BYTES` (64 MiB).
        xacro_args: Arguments of a xacro source, ``{name: value}``.
        packages: Package folders by package name, searched before ``$ROS_PACKAGE_PATH``
            and the zoo (:mod:`robodyn.urdf.packages`) for ``$(find)`` and ``package://``.
        strict: Refuse MJCF elements robodyn cannot take instead of warning.
        interpret: Expand a xacro, convert an MJCF file and refuse SDF (``False``: the text
            as read, for telling reading errors from the document's own problems).
        max_dof: Most degrees of freedom of an MJCF file, counted while it is read
            (default 300, :data:`robodyn.dynamics.options.MAX_DOF`).
        xacro_env: Let a xacro read environment variables (``$(env NAME)``,
            ``$(optenv NAME)``); refused otherwise.

    Raises:
        URDFError: If a file cannot be read, is not a regular file or is too large, a
            xacro does not expand, an MJCF cannot be read, or the file is SDF.
        UnknownRobotError: If a name is neither a robot nor an existing file.
    """
    limit = max_urdf_bytes(max_bytes)
    reading = _Reading(limit, xacro_args, package_lookup(packages), strict, interpret, max_dof=max_dof, xacro_env=bool(xacro_env))
    if isinstance(source, os.PathLike):
        return _read_file(Path(source), limit, reading)
    if not isinstance(source, str):
        raise UnknownRobotError(f"{type(source).__name__} {source!r:.60}")
    text = source.lstrip("\ufeff \t\r\n").strip()
    if text.startswith("<"):
        if len(source) > limit:  # characters: a lower bound of the UTF-8 size
            raise URDFError("<string>", f"is more than the limit of {limit} bytes ({_OVERRIDE})")
        return _interpret(URDFSource(source, "robot", "<string>"), reading)
    if text in GENERATED:
        return URDFSource(GENERATED[text](), text, text)
    if text in zoo.ZOO:
        robot = zoo.zoo_robot(text)
        path = zoo.zoo_urdf_path(text)
        data = read_regular_file(path, limit, text).decode("utf-8")
        return URDFSource(data, text, text, path, robot.floating_base, tuple(zoo.package_dirs()))
    path = Path(text).expanduser()
    try:
        exists = path.exists()
    except (OSError, ValueError):  # a name too long for the file system, a NUL byte
        exists = False
    if exists or os.sep in text or text.endswith((".urdf", ".xml", ".xacro", ".mjcf", ".sdf")):
        if "\x00" in text:
            raise URDFError(text, "a file name cannot contain a NUL character")
        return _read_file(path, limit, reading)
    raise UnknownRobotError(text, difflib.get_close_matches(text, list(GENERATED) + list(zoo.ZOO), n=3))


def locked_source(
    resolved: URDFSource,
    lock: dict[str, float],
    *,
    floating_base: bool | None = None,
    check_inertia: bool = True,
    strict: bool = False,
) -> URDFSource:
    """The same source with joints frozen at positions (see :func:`robodyn.urdf.edit.lock_joints`).

    Args:
        resolved: The source read.
        lock: Joints to freeze, by name, at positions in [rad] / [m].
        floating_base: Read with a free-flyer root (``None``: the source's choice).
        check_inertia: Refuse inertias that are not positive semi-definite on moving links.
        strict: Refuse what otherwise loads with a warning.
    """
    floating = resolved.floating_base if floating_base is None else floating_base
    with warnings.catch_warnings():  # the locked model is validated (and warns) again
        warnings.simplefilter("ignore", RobodynWarning)
        spec = parse_urdf(resolved.text, resolved.label, floating_base=floating, check_inertia=check_inertia, strict=strict)
    text = lock_joints(spec, lock, resolved.label)
    return replace(resolved, text=text, label=f"{resolved.label} (locked {', '.join(lock)})")


def with_file_dynamics(spec: URDFSpec, label: str) -> URDFSpec:
    """The spec with each joint's ``<dynamics armature=...>`` (robodyn's extension of URDF,
    what its MJCF reader writes for MuJoCo's ``armature``), and ``damping`` / ``friction``
    where the spec has none, read from the spec's XML.

    Args:
        spec: The validated URDF (its XML is read).
        label: The file or robot name, for the error.

    Raises:
        URDFError: If a value is not a finite number ≥ 0.
    """
    joints = dict(spec.joints)
    for node in spec.xml.findall("joint"):
        name, dynamics = node.get("name"), node.find("dynamics")
        if dynamics is None or name not in joints:
            continue
        values: dict[str, float] = {}
        for attribute in ("damping", "friction", "armature"):
            text = dynamics.get(attribute)
            value = None if text is None else parse_number(text)
            if text is not None and (value is None or not math.isfinite(value) or value < 0):
                raise URDFError(label, f"joint {name!r}: <dynamics {attribute}={text!r}> must be a finite number >= 0")
            if value is not None and getattr(joints[name], attribute) == 0:
                values[attribute] = value
        joints[name] = replace(
            joints[name],
            damping=values.get("damping", joints[name].damping),
            friction=values.get("friction", joints[name].friction),
            armature=values.get("armature", joints[name].armature),
        )
    return URDFSpec(spec.name, spec.root, spec.links, joints, spec.xml)


def lint_source(
    source: str | os.PathLike,
    *,
    floating_base: bool | None = None,
    xacro_args: Mapping[str, str] | None = None,
    packages: Mapping[str, str] | None = None,
    xacro_env: bool = False,
) -> list[Problem]:
    """Every problem of a robot file (a path, text or robot name), errors and warnings.

    A document that is not even well-formed XML gives one error problem, and so does one
    robodyn cannot read as a robot (SDF, a xacro that does not expand, an MJCF element it
    refuses). A xacro is linted as its expansion, an MJCF file as the URDF robodyn reads it
    into; what the import reports (MJCF elements left out) is among the warnings.

    Args:
        source: A URDF, ``.xacro`` or MJCF file path, such XML text, or a robot name (as for :func:`robodyn.load`).
        floating_base: Lint as with a free-flyer root. ``None``: true for zoo robots that walk, swim or fly, false otherwise.
        xacro_args: Arguments of a ``.xacro`` source, ``{name: value}``.
        packages: Package folders, ``{package name: folder}``, for ``package://`` paths and ``$(find name)``.
        xacro_env: Let a xacro source read environment variables (``$(env NAME)``, ``$(optenv NAME)``).

    Raises:
        UnknownRobotError, URDFError: If the source cannot be found or read.
    """
    resolve_source(source, interpret=False)  # a file that cannot be read is an error, not a problem
    try:
        with warnings.catch_warnings(record=True) as caught:  # what the import reports is reported here
            warnings.simplefilter("always", RobodynWarning)
            resolved = resolve_source(source, xacro_args=xacro_args, packages=packages, xacro_env=xacro_env)
    except URDFError as error:
        return [Problem(error.element, error.rule)]
    reported = [_import_problem(str(item.message)) for item in caught if issubclass(item.category, RobodynWarning)]
    floating = resolved.floating_base if floating_base is None else floating_base
    try:
        _, problems = lint_urdf(resolved.text, resolved.label, floating_base=floating, strict=True, **resolved.mesh_context)
    except URDFError as error:
        return [*reported, Problem(error.element, error.rule)]
    return [*reported, *problems]


def _import_problem(message: str) -> Problem:
    """A warning of the import (``"label: what"``) as a warning problem."""
    element, _, rule = message.partition(": ")
    return Problem(element, rule or message, "warning")
