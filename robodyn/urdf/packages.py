"""Where ROS packages are: the one lookup behind ``package://`` paths and ``$(find name)``.

A package named ``NAME`` is searched, in order, in

1. the folders the caller gave (``load(packages={"NAME": "/path/to/NAME"})``,
   or its command-line equivalent): the folder *is* the package;
2. ``$ROS_PACKAGE_PATH`` (colon-separated): each entry is searched for ``NAME/package.xml``,
   as ROS does (the entry itself if it is the package, or a folder up to
   :data:`SEARCH_DEPTH` levels below it);
3. the zoo's folders (example-robot-data's share folder, when installed).

:func:`package_roots` gives the folders *holding* packages (what
:func:`robodyn.urdf.meshes.resolve_mesh` searches ``NAME/...`` under): for an explicit
folder, its parent is not used; the lookup keeps the ``NAME -> folder`` map instead.

A package name is a name: empty, ``.``, ``..`` and names with ``/``, ``\\`` or NUL are
refused (:func:`name_problem`) by :meth:`PackageLookup.require` (``$(find NAME)``) and
:func:`package_folders` (``package://NAME/...``) alike, before any folder is looked at.
This module does not import Pinocchio.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path

from robodyn.exceptions import InputError, MeshPathError, MissingExtraError, URDFError

#: How deep below a ``$ROS_PACKAGE_PATH`` entry a ``package.xml`` is searched for (a
#: catkin / colcon workspace's ``src/`` holds packages one or two levels down).
SEARCH_DEPTH = 3
#: Most folders visited below one ``$ROS_PACKAGE_PATH`` entry (a path to ``/`` must not
#: make robodyn walk the whole disk).
MAX_VISITS = 5000


class PackageLookup(tuple[Path, ...]):
    """Where packages are found: explicit folders, then ``$ROS_PACKAGE_PATH``, then the zoo.

    As a tuple it is the folders holding packages (:meth:`roots`, what code expecting
    ``package_dirs`` iterates, e.g. :attr:`robodyn.Robot.package_dirs`); :meth:`find` is the
    lookup itself, which also knows explicit packages whose folder is named otherwise.

    Attributes:
        explicit: ``(package name, folder)`` pairs the caller gave, in order.
        ros_path: The ``$ROS_PACKAGE_PATH`` entries in force when the lookup was made.
        zoo_dirs: Folders holding the zoo's packages (empty if example-robot-data is absent).
    """

    explicit: tuple[tuple[str, Path], ...]
    ros_path: tuple[Path, ...]
    zoo_dirs: tuple[Path, ...]

    def __new__(
        cls, explicit: tuple[tuple[str, Path], ...] = (), ros_path: tuple[Path, ...] = (), zoo_dirs: tuple[Path, ...] = ()
    ) -> PackageLookup:
        roots = tuple(folder.parent for _, folder in explicit) + tuple(ros_path) + tuple(zoo_dirs)
        self = super().__new__(cls, roots)
        self.explicit, self.ros_path, self.zoo_dirs = tuple(explicit), tuple(ros_path), tuple(zoo_dirs)
        return self

    def __getnewargs__(self) -> tuple:
        return (self.explicit, self.ros_path, self.zoo_dirs)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, PackageLookup) and self.__getnewargs__() == other.__getnewargs__()

    def __ne__(self, other: object) -> bool:
        return not self == other

    def __hash__(self) -> int:
        return hash(self.__getnewargs__())

    def __repr__(self) -> str:
        return f"PackageLookup(explicit={self.explicit!r}, ros_path={self.ros_path!r}, zoo_dirs={self.zoo_dirs!r})"

    def find(self, name: str) -> Path | None:
        """The folder of package ``name``, or ``None`` if no place holds it (or it is not a
        package name: :func:`name_problem`).

        Args:
            name: The package's name.
        """
        if name_problem(name) is not None:
            return None
        for package, folder in self.explicit:
            if package == name:
                return folder
        for entry in self.ros_path:
            found = _search(entry, name)
            if found is not None:
                return found
        for folder in self.zoo_dirs:
            if (folder / name).is_dir():
                return folder / name
        return None

    def places(self, name: str) -> list[str]:
        """Where ``name`` was looked for, for a message.

        Args:
            name: The package's name.
        """
        places = [f"{folder} (packages=)" for package, folder in self.explicit if package == name]
        places += [f"{entry} ($ROS_PACKAGE_PATH)" for entry in self.ros_path]
        places += [f"{folder} (the zoo)" for folder in self.zoo_dirs]
        return places or ["nowhere: no packages=, no $ROS_PACKAGE_PATH, no zoo"]

    def require(self, name: str, label: str) -> Path:
        """The folder of package ``name``.

        Args:
            name: The package's name.
            label: The file or robot name, for the error.

        Raises:
            URDFError: Naming the package and the places looked in, or why ``name`` is not
                a package name.
        """
        problem = name_problem(name)
        if problem is not None:
            raise URDFError(label, f"package {name!r} {problem}")
        found = self.find(name)
        if found is None:
            raise URDFError(
                label, f"package {name!r} not found (looked in {'; '.join(self.places(name))}; packages= gives its folder)"
            )
        return found

    def roots(self) -> tuple[Path, ...]:
        """Folders that hold a package's folder ``NAME/`` (what mesh paths are searched under)."""
        return tuple(self)

    def as_dict(self) -> dict[str, list[str]]:
        """The lookup as JSON-ready lists (``robodyn info --json``)."""
        return {
            "packages": [f"{name}={folder}" for name, folder in self.explicit],
            "ros_package_path": [str(entry) for entry in self.ros_path],
            "zoo": [str(folder) for folder in self.zoo_dirs],
        }


def name_problem(name: str) -> str | None:
    """Why ``name`` is not a package name (empty, ``.``, ``..``, a ``/``, ``\\`` or NUL), or ``None``.

    Args:
        name: The name to check.
    """
    if name in ("", ".", ".."):
        return "is not a package name (empty, '.' and '..' name folders, not packages)"
    if any(character in name for character in "/\\\x00"):
        return "is not a package name (it contains '/', '\\' or NUL)"
    return None


def package_folders(name: str, package_dirs: Sequence[Path] | PackageLookup, *, path: str) -> list[Path]:
    """The folders package ``name`` may be, for the ``package://`` path ``path``: the
    lookup's one, or ``NAME`` under each folder of a plain sequence (the zoo's folders).

    Args:
        name: The package's name.
        package_dirs: A :class:`PackageLookup`, or folders each holding packages as subfolders.
        path: The ``package://`` path, for the error.

    Raises:
        MeshPathError: If ``name`` is not a package name (:func:`name_problem`).
    """
    problem = name_problem(name)
    if problem is not None:
        raise MeshPathError(path, f"names package {name!r}, which {problem}")
    if isinstance(package_dirs, PackageLookup):
        found = package_dirs.find(name)
        return [found] if found is not None else []
    return [Path(folder) / name for folder in package_dirs]


def package_lookup(packages: Mapping[str, str | os.PathLike] | None = None, *, zoo: bool = True) -> PackageLookup:
    """The lookup in force: ``packages``, then ``$ROS_PACKAGE_PATH``, then the zoo's folders.

    Args:
        packages: Package folders by name (each folder is the package itself).
        zoo: Whether to search the zoo's folders last.

    Raises:
        InputError: If a package name is empty or contains ``/``, or its folder does not exist.
    """
    explicit = []
    for name, folder in (packages or {}).items():
        name = str(name)
        if name_problem(name) is not None:
            raise InputError("packages", "package names (no '/', '\\', '.' or '..') with their folders", repr(name))
        path = Path(os.fspath(folder)).expanduser()
        if "\x00" in str(path) or not path.is_dir():
            raise InputError("packages", f"an existing folder for package {name!r}", repr(str(path)))
        explicit.append((name, path.resolve()))
    ros = tuple(
        Path(entry).expanduser().absolute() for entry in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if entry.strip()
    )
    return PackageLookup(tuple(explicit), ros, tuple(_zoo_dirs()) if zoo else ())


def _zoo_dirs() -> list[Path]:
    from robodyn.urdf import zoo

    try:
        return zoo.package_dirs()
    except MissingExtraError:
        return []


def _search(entry: Path, name: str) -> Path | None:
    """The folder ``NAME`` holding a ``package.xml`` at or below ``entry`` (breadth-first)."""
    layer, visits = [entry], 0
    for _ in range(SEARCH_DEPTH + 1):
        following = []
        for folder in layer:
            if folder.name == name and (folder / "package.xml").is_file():
                return folder
            if (folder / "package.xml").is_file():
                continue  # a package: ROS does not look inside it for others
            try:
                children = sorted(child for child in folder.iterdir() if child.is_dir() and not child.name.startswith("."))
            except OSError:
                continue
            visits += len(children)
            if visits > MAX_VISITS:
                return None
            following += children
        layer = following
    return None
