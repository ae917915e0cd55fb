"""The compiled engine's cache: its folder, its keys and its files (no sympy, no code generator).

Everything the compiled engine generates for a robot (kernels' C source, the symbolic
programs, the built modules) is filed under the robot's key (:func:`robot_key`): a hash of
what the code depends on,

- the robot: its URDF text (locked joints, mimic joints, the file's armature are in it), its
  floating base, its gravity and the armature given to :func:`robodyn.load`;
- the generator: the source of every module the generated code can depend on, found by
  walking the whole package (every ``.py``, ``.c`` and ``.h`` file) but the subpackages
  of the layers above the code generator (:data:`ABOVE_GENERATOR`, which the import
  contracts forbid it to import): a change anywhere else, by anyone, in a package added
  later too, never reuses what was generated before it. Nobody keeps a list of modules or
  a version number.

The folder is ``$ROBODYN_CACHE``, else ``$XDG_CACHE_HOME/robodyn``, else ``~/.cache/robodyn``
(subfolder ``compiled/``). Every file is written under a temporary name and renamed into
place (``os.replace``), so two processes compiling the same robot at once both succeed and
the cache never holds a half-written file.

Computing a key costs microseconds once per process (a robot's key is memoised by its URDF
text and options; the generator's hash is read once per process, a few milliseconds), so the
question "is this robot compiled?" never imports sympy (:func:`robodyn.compiled.build.lookup`).
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import os
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING

from robodyn.common.files import atomic_write_text

if TYPE_CHECKING:
    from robodyn.dynamics.robot import Robot

#: The subpackages of robodyn that cannot decide the generated code: the layers above the
#: compiled engine (the import contracts in pyproject.toml; a test holds the two together),
#: except ``export``, which prints the same programs. Everything else is hashed, so a new
#: lower package is hashed without anyone adding it.
ABOVE_GENERATOR = ("cli", "viz", "scale", "optimize", "sim", "verify", "ident", "trajectory")
#: Rotation entries this close to 0, ±1, ±½, ... are taken as exact when the programs are
#: derived (:mod:`robodyn.compiled.programs`): float rounding only (cos(π/2) = 6e-17,
#: sin(π) = 1.2e-16), so the compiled model is the URDF's. Not more: URDFs write π to 12
#: digits (kinova's 3.14159265359, sin = -2e-13), and snapping that to 0 moved kinova's M by
#: 8e-14 and, through cond(M) ~ 1e4, its forward dynamics by 5e-10.
SNAP = 1e-15
_ROOT = Path(__file__).resolve().parent.parent
_KEYS: dict[tuple, str] = {}


def cache_dir() -> Path:
    """Where compiled robots are kept: ``$ROBODYN_CACHE``, else ``$XDG_CACHE_HOME/robodyn``,
    else ``~/.cache/robodyn`` (subfolder ``compiled``)."""
    root = os.environ.get("ROBODYN_CACHE")
    if not root:
        xdg = os.environ.get("XDG_CACHE_HOME")
        root = str(Path(xdg) / "robodyn") if xdg else str(Path.home() / ".cache" / "robodyn")
    return Path(root).expanduser() / "compiled"


def digest(*parts: str) -> str:
    """A short SHA-256 of text parts."""
    hasher = hashlib.sha256()
    for part in parts:
        hasher.update(part.encode("utf-8"))
        hasher.update(b"\0")
    return hasher.hexdigest()[:24]


def generator_files() -> list[Path]:
    """Every source file of robodyn (``.py``, ``.c``, ``.h``) outside :data:`ABOVE_GENERATOR`, sorted."""
    files = [
        path
        for path in _ROOT.rglob("*")
        if path.suffix in (".py", ".c", ".h")
        and "__pycache__" not in path.parts
        and path.relative_to(_ROOT).parts[0] not in ABOVE_GENERATOR
    ]
    return sorted(files)


@functools.lru_cache(maxsize=1)
def generator_hash() -> str:
    """The hash of the generator's source (:func:`generator_files`: names and bytes), once a process."""
    hasher = hashlib.sha256()
    for path in generator_files():
        hasher.update(str(path.relative_to(_ROOT)).encode("utf-8") + b"\0" + path.read_bytes() + b"\0")
    return hasher.hexdigest()[:24]


def robot_key(robot: Robot) -> str:
    """The cache key of a robot's generated code: its URDF text, floating base, gravity, the
    armature given to :func:`robodyn.load` (the file's is in the text) and the generator's
    source (:func:`generator_hash`). Memoised per process: microseconds after the first call.

    Args:
        robot: The loaded robot.
    """
    options = robot.options
    memo = (robot.urdf, options.floating_base, tuple(robot.gravity_vector.tolist()), tuple(options.armature))
    key = _KEYS.get(memo)
    if key is None:
        gravity = ",".join(repr(float(g)) for g in memo[2])
        key = digest(robot.urdf, f"floating={options.floating_base}", gravity, repr(memo[3]), generator_hash())
        _KEYS[memo] = key
    return key


def cached_kernels(key: str) -> str | None:
    """The generated kernels stored under a key, if any.

    Args:
        key: The robot's cache key (:func:`robot_key`).
    """
    path = cache_dir() / f"src-{key}.c"
    try:
        return path.read_text(encoding="utf-8")
    except OSError:
        return None


def store_kernels(key: str, kernels: str) -> None:
    """Keep the generated kernels for a key (atomically; a read-only cache is skipped).

    Args:
        key: The robot's cache key (:func:`robot_key`).
        kernels: The generated kernels' C source.
    """
    with contextlib.suppress(OSError):
        atomic_write_text(cache_dir() / f"src-{key}.c", kernels)


@contextlib.contextmanager
def locked(key: str) -> Iterator[None]:
    """Hold an exclusive lock on a key (``lock-<key>`` in the cache, ``flock``) while
    deriving and building it: a second process compiling the same robot waits, then finds it
    cached, instead of deriving and building it a second time. No lock where the cache is read-only or
    the platform has no ``fcntl``.

    Args:
        key: The cache key to lock (:func:`robot_key`, or a module's own key).
    """
    try:
        import fcntl

        folder = cache_dir()
        folder.mkdir(parents=True, exist_ok=True)
        handle = open(folder / f"lock-{key}", "a")  # noqa: SIM115 - held across the yield
    except (ImportError, OSError):
        yield
        return
    try:
        fcntl.flock(handle, fcntl.LOCK_EX)
        yield
    finally:
        handle.close()  # releases the lock
