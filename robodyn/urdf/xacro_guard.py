"""What a xacro document may reach while it expands: files, the environment, and how much.

A :class:`XacroGuard` is the one place the expansion (:mod:`robodyn.urdf.xacro_files`) asks
before it reads a file, reads an environment variable or grows:

- **files** (``<xacro:include>``, ``xacro.load_yaml``): only inside :attr:`XacroGuard.roots`
  — the top file's folder tree, the package folders (``packages=``, ``$ROS_PACKAGE_PATH``
  entries) and the zoo's — after symlinks are resolved, and only through robodyn's file
  reader (regular files, the size cap, UTF-8); a YAML file at most :data:`MAX_YAML_BYTES`;
- **the environment** (``$(env NAME)``, ``$(optenv NAME)``): only with ``xacro_env=True``;
- **growth**: at most :data:`MAX_ELEMENTS` elements evaluated, the text produced within the
  URDF size cap (counted as it is produced), macros nested at most :data:`MAX_MACRO_DEPTH`
  deep, includes :data:`MAX_INCLUDE_DEPTH` deep, and :data:`MAX_SECONDS` of expansion.

Each refusal is one :class:`~robodyn.exceptions.URDFError` sentence. This module does not
import Pinocchio or the xacro package.
"""

from __future__ import annotations

import glob
import math
import os
import re
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from robodyn.exceptions import URDFError
from robodyn.urdf.xacro_eval import ExpressionError, checked, evaluate, size
from robodyn.urdf.xacro_names import base_names

#: Most elements a xacro expansion evaluates (a 300-link robot with transmissions and
#: gazebo tags needs about 9 300; xacro slows quadratically past that on flat documents).
MAX_ELEMENTS = 20_000
#: Deepest nesting of macro calls.
MAX_MACRO_DEPTH = 50
#: Deepest nesting of includes.
MAX_INCLUDE_DEPTH = 20
#: Longest expansion, in seconds (a backstop behind the counts above).
MAX_SECONDS = 10.0
#: Largest YAML file ``xacro.load_yaml`` reads, in bytes.
MAX_YAML_BYTES = 1 << 20

_GLOB = re.compile(r"[*?[]")
_UNITS = {"!radians": 1.0, "!degrees": math.pi / 180, "!meters": 1.0, "!millimeters": 1e-3, "!foot": 0.3048, "!inches": 0.0254}


class XacroGuard:
    """The limits of one expansion, and the counts so far.

    Args:
        label: The source's name for messages.
        roots: Folders whose trees files may be read from.
        read_file: Reads a file as text through robodyn's reader (raises ``URDFError``).
        limit: The URDF size cap, in bytes: the expansion's text may not exceed it.
        env: Whether ``$(env)`` / ``$(optenv)`` may read the environment.
    """

    def __init__(self, *, label: str, roots: tuple[Path, ...], read_file: Callable[[Path], str], limit: int, env: bool):
        self.label, self.read_file, self.limit, self.env = label, read_file, limit, env
        self.roots = tuple(_resolved(root) for root in roots)
        self.elements = 0
        self.produced = 0
        self.texts = 0
        self.started = time.monotonic()

    def refuse(self, rule: str) -> URDFError:
        """The error refusing the expansion (to raise), naming the file.

        Args:
            rule: What the file broke.
        """
        return URDFError(self.label, f"xacro: {rule}")

    def element(self, macro_depth: int, include_depth: int) -> None:
        """Count one element about to be evaluated.

        Args:
            macro_depth: How deep macro calls are nested at the element.
            include_depth: How deep includes are nested at the element.

        Raises:
            URDFError: Past :data:`MAX_ELEMENTS`, the depths, or :data:`MAX_SECONDS`.
        """
        self.elements += 1
        if self.elements > MAX_ELEMENTS:
            raise self.refuse(f"the expansion evaluates more than {MAX_ELEMENTS} elements (a runaway macro?)")
        if macro_depth > MAX_MACRO_DEPTH:
            raise self.refuse(f"macros are nested more than {MAX_MACRO_DEPTH} deep (a recursive macro?)")
        if include_depth > MAX_INCLUDE_DEPTH:
            raise self.refuse(f"includes are nested more than {MAX_INCLUDE_DEPTH} deep (an include loop?)")
        if self.elements % 256 == 0 and time.monotonic() - self.started > MAX_SECONDS:
            raise self.refuse(f"the expansion took more than {MAX_SECONDS:g} s")

    def text(self, value: Any) -> None:
        """Count the text an evaluation produced.

        Args:
            value: The evaluation's result (a string, or a value whose size is counted).

        Raises:
            URDFError: If the expansion's text passes the size cap.
        """
        self.produced += len(value) if isinstance(value, str) else size(value)
        self.texts += 1
        if self.texts % 64 == 0 and time.monotonic() - self.started > MAX_SECONDS:
            raise self.refuse(f"the expansion took more than {MAX_SECONDS:g} s")
        if self.produced > self.limit:
            raise self.refuse(
                f"the expansion is more than the limit of {self.limit} bytes (max_bytes= or $ROBODYN_MAX_URDF_BYTES raises it)"
            )

    def inside(self, filename: str, what: str) -> Path:
        """``filename`` if it is inside one of :attr:`roots` (after symlinks).

        Args:
            filename: The file's name.
            what: What the file is for, for the error (e.g. ``"the include"``).

        Raises:
            URDFError: Naming the file and the rule.
        """
        path = _resolved(Path(filename))
        if not any(path == root or root in path.parents for root in self.roots):
            places = ", ".join(str(root) for root in self.roots) or "none: XML text has no folder; packages= names one"
            raise self.refuse(
                f"{what} {filename!r} is outside the file's folder tree, the packages and the zoo (allowed: {places})"
            )
        return path

    def include_files(self, spec: str) -> list[str]:
        """The files an include's absolute ``spec`` names (a glob expands inside the roots only).

        Args:
            spec: The include's absolute file name, possibly a glob pattern.
        """
        if not _GLOB.search(spec):
            self.inside(spec, "the include")
            return [spec]
        fixed = _GLOB.split(spec, 1)[0]
        self.inside(os.path.dirname(fixed) or ".", "the include pattern")
        names = sorted(glob.glob(spec))[: MAX_ELEMENTS // 100]
        return [name for name in names if self.inside(name, "the include")]

    def load_yaml(self, filename: str) -> Any:
        """The data of a YAML file inside the roots (plain dicts, lists and scalars).

        Args:
            filename: The YAML file's name.

        Raises:
            URDFError: Outside the roots, not a regular file, too large, not YAML, or too large as data.
        """
        import yaml

        path = self.inside(filename, "xacro.load_yaml of")
        text = self.read_file(path)
        if len(text.encode("utf-8")) > MAX_YAML_BYTES:
            raise self.refuse(f"the YAML file {filename!r} is more than the limit of {MAX_YAML_BYTES} bytes")

        class Loader(yaml.SafeLoader):
            pass

        for tag, factor in _UNITS.items():
            Loader.add_constructor(tag, _unit(factor))
        try:
            data = yaml.load(text, Loader=Loader)  # a SafeLoader subclass: plain data only
            return checked(data)
        except (yaml.YAMLError, ExpressionError, RecursionError, ValueError, TypeError) as error:
            reason = " ".join(str(error).split())[:300]
            raise self.refuse(f"the YAML file {filename!r} cannot be read: {reason}") from None

    def environment(self, name: str, default: str | None = None) -> str:
        """``$(env NAME)`` / ``$(optenv NAME DEFAULT)``, with ``xacro_env=True`` only.

        Args:
            name: The environment variable's name.
            default: ``$(optenv)``'s default (``None`` for ``$(env)``).

        Raises:
            URDFError: Without the opt-in (naming the variable), or for an unset ``$(env)``.
        """
        if not self.env:
            raise self.refuse(
                f"the file reads the environment variable {name!r} ($(env)/$(optenv)); refused unless xacro_env=True"
            )
        if name in os.environ:
            return os.environ[name]
        if default is None:
            raise self.refuse(f"the environment variable {name!r} is not set")
        return default


def _unit(factor: float) -> Callable[[Any, Any], float]:
    def construct(loader: Any, node: Any) -> float:
        value = evaluate(str(loader.construct_scalar(node)), base_names().__getitem__)
        if not isinstance(value, int | float):
            raise ExpressionError(f"a unit value must be a number, not {value!r:.40}")
        return float(value) * factor

    return construct


def _resolved(path: Path) -> Path:
    try:
        return path.resolve()
    except (OSError, RuntimeError, ValueError):  # a symlink loop, a NUL byte
        return Path("/nonexistent-robodyn-path")
