"""Whether a robot's kernels are in the compile cache, without the code generator.

``engine="auto"`` asks this before choosing the compiled engine: the cache key of
:func:`robodyn.compiled.robot.robot_key` (the URDF text, gravity, armature and the
generator's sources) computed from the source files themselves, so deciding imports
neither sympy nor the generator. ``tests/compiled/test_lookup.py`` holds the two keys equal
(the key is written in :mod:`robodyn.compiled.robot`; this module reads the same files).
"""

from __future__ import annotations

import ast
import hashlib
import os
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from robodyn.dynamics.robot import Robot

_PACKAGE = Path(__file__).resolve().parents[1]
#: The generator's modules, in the order robot_key hashes them (robodyn.compiled.robot._generator_source).
_GENERATOR = (
    "compiled/codegen.py", "equations/c_printer.py", "equations/program.py", "equations/sharing.py",
    "equations/newton_euler.py", "equations/compact.py", "reference/tree.py", "reference/symbolic.py",
)  # fmt: skip


def cache_dir() -> Path:
    """The compile cache (:func:`robodyn.compiled.build.cache_dir`, the same folder)."""
    root = os.environ.get("ROBODYN_CACHE")
    if not root:
        xdg = os.environ.get("XDG_CACHE_HOME")
        root = str(Path(xdg) / "robodyn") if xdg else str(Path.home() / ".cache" / "robodyn")
    return Path(root).expanduser() / "compiled"


def _constant(path: Path, name: str) -> object:
    """A module-level constant of a source file, read without importing it."""
    for node in ast.parse(path.read_text(encoding="utf-8")).body:
        if isinstance(node, ast.Assign) and any(isinstance(target, ast.Name) and target.id == name for target in node.targets):
            return ast.literal_eval(node.value)
    raise LookupError(f"{name} not found in {path.name}")  # pragma: no cover - the generator's own edit


def robot_key(robot: Robot) -> str:
    """:func:`robodyn.compiled.robot.robot_key`, computed from the source files."""
    texts = [(_PACKAGE / name).read_text(encoding="utf-8") for name in _GENERATOR]
    generator = "".join(texts) + (_PACKAGE / "compiled" / "trig.c").read_text(encoding="utf-8")
    version = _constant(_PACKAGE / "compiled" / "codegen.py", "CODEGEN_VERSION")
    snap = _constant(_PACKAGE / "compiled" / "robot.py", "SNAP")
    gravity = ",".join(repr(float(g)) for g in robot.gravity_vector)
    armature = repr(tuple(robot.options.armature))
    parts = (robot.urdf, gravity, armature, str(version), f"compact snap={snap}", generator)
    hasher = hashlib.sha256()  # robodyn.compiled.build.digest
    for part in parts:
        hasher.update(part.encode("utf-8"))
        hasher.update(b"\0")
    return hasher.hexdigest()[:24]


def compiled_before(robot: Robot) -> bool:
    """Whether the robot's generated kernels are in the cache (loading them takes milliseconds;
    deriving them, seconds to minutes)."""
    return (cache_dir() / f"src-{robot_key(robot)}.c").is_file()
