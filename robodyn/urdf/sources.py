"""Where a URDF comes from: a path, URDF text, a zoo name, or a generated robot's name.

:func:`resolve_source` turns whatever the user passed to :func:`robodyn.load` (or to the
reference's ``load``) into the URDF text plus what is needed to read it: a label for
messages, the folder its relative mesh paths start from and the package folders for
``package://`` paths. This module does not import Pinocchio.
"""

from __future__ import annotations

import difflib
import os
import stat
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path

from robodyn.exceptions import RobodynWarning, UnknownRobotError, URDFError
from robodyn.urdf import zoo
from robodyn.urdf.edit import lock_joints
from robodyn.urdf.models import GENERATED
from robodyn.urdf.validation import Problem, lint_urdf, parse_urdf


@dataclass(frozen=True)
class URDFSource:
    """A URDF document and where it came from.

    Attributes:
        text: The URDF document.
        name: A short name for the robot (zoo or generated name, file stem, ``"robot"``).
        label: Where it came from, for messages: a path, a robot name or ``"<string>"``.
        path: The file it was read from, if any.
        floating_base: Whether the robot is floating by default (zoo robots that walk or fly).
        package_dirs: Folders under which ``package://`` paths resolve.
    """

    text: str
    name: str
    label: str
    path: Path | None = None
    floating_base: bool = False
    package_dirs: tuple[Path, ...] = field(default_factory=tuple)

    @property
    def mesh_context(self) -> dict:
        """Keyword arguments locating mesh files (for :func:`robodyn.urdf.validation.parse_urdf`)."""
        return {"base_dir": self.path.parent if self.path is not None else None, "package_dirs": self.package_dirs}


def robot_names() -> list[str]:
    """Names :func:`robodyn.load` accepts: generated robots first, then the zoo."""
    return sorted(GENERATED) + zoo.zoo_names()


#: Largest URDF accepted by default, in bytes (the largest zoo URDF is under 1 MB);
#: ``max_bytes=`` or the ``ROBODYN_MAX_URDF_BYTES`` environment variable overrides it.
MAX_URDF_BYTES = 64 * 1024 * 1024


def max_urdf_bytes(max_bytes: int | None = None) -> int:
    """The size cap in force: ``max_bytes``, else ``$ROBODYN_MAX_URDF_BYTES``, else the default."""
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


def _read_file(path: Path, max_bytes: int) -> URDFSource:
    data = read_regular_file(path, max_bytes)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as error:
        raise URDFError(str(path), f"is not UTF-8 text (byte {error.start})") from None
    return URDFSource(text, path.stem, str(path), path.resolve(), False, ())


def resolve_source(
    source: str | os.PathLike,
    *,
    max_bytes: int | None = None,
    xacro_args: Mapping[str, str] | None = None,
    packages: Mapping[str, str] | None = None,
) -> URDFSource:
    """Find the URDF a source names.

    Args:
        source: A path to a URDF file, URDF XML text, a zoo robot name (``"panda"``) or a
            generated robot's name (``"rp_arm"``).
        max_bytes: Largest URDF accepted, in bytes (files and text); default
            ``$ROBODYN_MAX_URDF_BYTES`` or :data:`MAX_URDF_BYTES` (64 MiB).
        xacro_args: Arguments of a ``.xacro`` source (not yet expanded: see issue 24).
        packages: Package folders by package name (not yet used: see issue 24).

    Raises:
        URDFError: If a file cannot be read, is not a regular file or is too large.
        UnknownRobotError: If a name is neither a robot nor an existing file.
    """
    limit = max_urdf_bytes(max_bytes)
    if isinstance(source, os.PathLike):
        return _read_file(Path(source), limit)
    if not isinstance(source, str):
        raise UnknownRobotError(f"{type(source).__name__} {source!r:.60}")
    text = source.lstrip("\ufeff \t\r\n").strip()
    if text.startswith("<"):
        if len(source) > limit:  # characters: a lower bound of the UTF-8 size
            raise URDFError("<string>", f"is more than the limit of {limit} bytes ({_OVERRIDE})")
        return URDFSource(source, "robot", "<string>")
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
    if exists or os.sep in text or text.endswith((".urdf", ".xml")):
        if "\x00" in text:
            raise URDFError(text, "a file name cannot contain a NUL character")
        return _read_file(path, limit)
    raise UnknownRobotError(text, difflib.get_close_matches(text, list(GENERATED) + list(zoo.ZOO), n=3))


def locked_source(
    resolved: URDFSource,
    lock: dict[str, float],
    *,
    floating_base: bool | None = None,
    check_inertia: bool = True,
    strict: bool = False,
) -> URDFSource:
    """The same source with joints frozen at positions (see :func:`robodyn.urdf.edit.lock_joints`)."""
    floating = resolved.floating_base if floating_base is None else floating_base
    with warnings.catch_warnings():  # the locked model is validated (and warns) again
        warnings.simplefilter("ignore", RobodynWarning)
        spec = parse_urdf(resolved.text, resolved.label, floating_base=floating, check_inertia=check_inertia, strict=strict)
    text = lock_joints(spec, lock, resolved.label)
    return replace(resolved, text=text, label=f"{resolved.label} (locked {', '.join(lock)})")


def lint_source(source: str | os.PathLike, *, floating_base: bool | None = None) -> list[Problem]:
    """Every problem of a URDF (a path, text or robot name), errors and warnings.

    A document that is not even well-formed XML gives one error problem.

    Raises:
        UnknownRobotError, URDFError: If the source cannot be found or read.
    """
    resolved = resolve_source(source)
    floating = resolved.floating_base if floating_base is None else floating_base
    try:
        _, problems = lint_urdf(resolved.text, resolved.label, floating_base=floating, strict=True, **resolved.mesh_context)
    except URDFError as error:
        return [Problem(error.element, error.rule)]
    return problems
