"""Where a URDF comes from: a path, URDF text, a zoo name, or a generated robot's name.

:func:`resolve_source` turns whatever the user passed to :func:`robodyn.load` (or to the
reference's ``load``) into the URDF text plus what is needed to read it: a label for
messages, the folder its relative mesh paths start from and the package folders for
``package://`` paths. This module does not import Pinocchio.
"""

from __future__ import annotations

import difflib
import os
from dataclasses import dataclass, field, replace
from pathlib import Path

from robodyn.exceptions import UnknownRobotError, URDFError
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


def _read_file(path: Path) -> URDFSource:
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise URDFError(str(path), "no such file") from None
    except (OSError, UnicodeDecodeError) as error:
        raise URDFError(str(path), f"cannot be read ({error.__class__.__name__}: {error})") from None
    return URDFSource(text, path.stem, str(path), path.resolve(), False, ())


def resolve_source(source: str | os.PathLike) -> URDFSource:
    """Find the URDF a source names.

    Args:
        source: A path to a URDF file, URDF XML text, a zoo robot name (``"panda"``) or a
            generated robot's name (``"rp_arm"``).

    Raises:
        URDFError: If a file cannot be read.
        UnknownRobotError: If a name is neither a robot nor an existing file.
    """
    if isinstance(source, os.PathLike):
        return _read_file(Path(source))
    if not isinstance(source, str):
        raise UnknownRobotError(repr(source))
    text = source.strip()
    if text.startswith("<"):
        return URDFSource(source, "robot", "<string>")
    if text in GENERATED:
        return URDFSource(GENERATED[text](), text, text)
    if text in zoo.ZOO:
        robot = zoo.zoo_robot(text)
        path = zoo.zoo_urdf_path(text)
        return URDFSource(path.read_text(encoding="utf-8"), text, text, path, robot.floating_base, tuple(zoo.package_dirs()))
    path = Path(text).expanduser()
    if path.is_file() or os.sep in text or text.endswith((".urdf", ".xml")):
        return _read_file(path)
    raise UnknownRobotError(text, difflib.get_close_matches(text, list(GENERATED) + list(zoo.ZOO), n=3))


def locked_source(
    resolved: URDFSource, lock: dict[str, float], *, floating_base: bool | None = None, check_inertia: bool = True
) -> URDFSource:
    """The same source with joints frozen at positions (see :func:`robodyn.urdf.edit.lock_joints`)."""
    floating = resolved.floating_base if floating_base is None else floating_base
    spec = parse_urdf(resolved.text, resolved.label, floating_base=floating, check_inertia=check_inertia)
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
        _, problems = lint_urdf(resolved.text, resolved.label, floating_base=floating, **resolved.mesh_context)
    except URDFError as error:
        return [Problem(error.element, error.rule)]
    return problems
