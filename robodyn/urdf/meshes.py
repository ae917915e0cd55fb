"""Mesh paths of a URDF: where they point, and that they stay inside the model's folders.

A URDF's ``<mesh filename=...>`` may be ``package://NAME/...`` (resolved under the package
folders, e.g. example-robot-data's share folder), ``file://...``, absolute, or relative
to the URDF file's folder. :func:`resolve_mesh` finds the file and refuses any path that
leaves those folders (``../``, absolute paths elsewhere): a URDF must not make robodyn
read arbitrary files. A mesh inside those folders that cannot be drawn — missing, or not a
regular file (a FIFO, a device, a directory) — is a warning: the model still loads (only
drawings need meshes) and drawings show a placeholder box (``robodyn.viz.mesh_files``
refuses it without opening it). This module does not import Pinocchio.
"""

from __future__ import annotations

import os
import stat
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from pathlib import Path
from urllib.parse import unquote, urlparse

from robodyn.exceptions import MeshPathError
from robodyn.urdf.packages import PackageLookup, package_folders


def _roots(package_dirs: Sequence[Path] | PackageLookup) -> tuple[Path, ...]:
    return package_dirs.roots() if isinstance(package_dirs, PackageLookup) else tuple(Path(d) for d in package_dirs)


def looked_in(filename: str, package_dirs: Sequence[Path] | PackageLookup) -> str:
    """Where a missing ``package://`` mesh was looked for, for a message.

    Args:
        filename: The mesh's ``package://`` file name.
        package_dirs: A package lookup, or folders each holding packages as subfolders.
    """
    package = filename[len("package://") :].lstrip("/").partition("/")[0]
    if isinstance(package_dirs, PackageLookup):
        return "; ".join(package_dirs.places(package))
    return "; ".join(str(Path(folder) / package) for folder in package_dirs) or "no package folder given"


def _inside(path: Path, folder: Path) -> bool:
    try:
        path.resolve().relative_to(folder.resolve())
    except (ValueError, OSError):  # elsewhere, or a symlink loop / name too long
        return False
    return True


def resolve_mesh(filename: str, *, base_dir: Path | None, package_dirs: Sequence[Path] | PackageLookup) -> Path | None:
    """The file a mesh path names (which may not be a regular file: see
    :func:`is_regular_file`), or ``None`` if it cannot be found.

    Args:
        filename: The ``filename`` attribute of a ``<mesh>``.
        base_dir: Folder of the URDF file (``None`` for URDF text).
        package_dirs: The package lookup (:class:`~robodyn.urdf.packages.PackageLookup`:
            ``packages=``, ``$ROS_PACKAGE_PATH``, the zoo), or folders holding the
            packages ``package://`` names.

    Raises:
        MeshPathError: If the path leaves the URDF's folder or the package folders.
    """
    roots = list(_roots(package_dirs)) + ([Path(base_dir)] if base_dir is not None else [])
    if filename.startswith("package://"):
        relative = filename[len("package://") :].lstrip("/")
        package, _, rest = relative.partition("/")
        for folder in package_folders(package, package_dirs, path=filename):
            candidate = folder / rest
            if not _inside(candidate, folder):
                raise MeshPathError(filename, f"leaves its package {package!r}")
            if _exists(candidate):
                return candidate
        return None
    if filename.startswith("file://"):
        candidate = Path(unquote(urlparse(filename).path))
    elif os.path.isabs(filename):
        candidate = Path(filename)
    elif base_dir is None:
        return None
    else:
        candidate = Path(base_dir) / filename
        if not _inside(candidate, Path(base_dir)):
            raise MeshPathError(filename, "leaves the URDF's folder")
    if not any(_inside(candidate, root) for root in roots):
        raise MeshPathError(filename, "is outside the URDF's folder and package folders")
    return candidate if _exists(candidate) else None


def _mode(candidate: Path) -> int | None:
    """The file's mode through symlinks (``os.stat`` never opens it, so a FIFO cannot
    block), or ``None`` if it is missing or its name impossible."""
    try:
        return os.stat(candidate).st_mode
    except (OSError, ValueError):  # missing, a name too long, a NUL byte
        return None


def _exists(candidate: Path) -> bool:
    return _mode(candidate) is not None


def is_regular_file(path: Path) -> bool:
    """Whether ``path`` is a regular file (not a FIFO, a device or a directory, which
    reading would block on or never finish), following symlinks.

    Args:
        path: The path.
    """
    mode = _mode(path)
    return mode is not None and stat.S_ISREG(mode)


def mesh_problems(
    root: ET.Element, *, base_dir: Path | None, package_dirs: Sequence[Path] | PackageLookup
) -> list[tuple[str, str, str]]:
    """Problems of every ``<mesh>``: ``(element, rule, severity)`` tuples.

    Args:
        root: The URDF's ``<robot>`` element.
        base_dir: The URDF file's folder (``None`` for text).
        package_dirs: A package lookup, or folders each holding packages as subfolders.
    """
    problems = []
    for link in root.findall("link"):
        for kind in ("visual", "collision"):
            for mesh in link.findall(f"{kind}/geometry/mesh"):
                filename = mesh.get("filename") or ""
                where = f'link "{link.get("name")}"'
                if not filename:
                    problems.append((where, f"a {kind} <mesh> has no filename", "error"))
                    continue
                try:
                    found = resolve_mesh(filename, base_dir=base_dir, package_dirs=package_dirs)
                except MeshPathError as error:
                    problems.append((where, str(error), "error"))
                    continue
                if found is None:
                    places = looked_in(filename, package_dirs) if filename.startswith("package://") else str(base_dir)
                    problems.append(
                        (where, f"{kind} mesh {filename!r} not found (looked in {places}; the model loads without it)", "warning")
                    )
                elif not is_regular_file(found):
                    problems.append(
                        (where, f"{kind} mesh {filename!r} is not a regular file (a FIFO, device or directory): "
                         "the model loads without it, drawings show a placeholder box", "warning")
                    )  # fmt: skip
    return problems
