"""Building, caching and loading a robot's compiled dynamics (a CPython extension module).

The generated kernels and ``runtime.c`` are compiled by the system C compiler into an
extension module (``PyInit_…``) that takes numpy arrays directly. An extension module and
not ctypes or cffi: on this machine a ctypes call passing four arrays costs 4.6 µs, twice
``pin.rnea`` itself, most of it in ``ndarray.ctypes``; a METH_FASTCALL function reads the
arrays' buffers and allocates the result in C, and is the thinnest binding there is.

The cache (``$ROBODYN_CACHE``, else ``$XDG_CACHE_HOME/robodyn``, else
``~/.cache/robodyn``; subfolder ``compiled/``) holds:

- ``src-<key>.c``: the generated kernels, keyed by a hash of the URDF text, gravity and the
  code generator's version (the sympy derivation is the slow part);
- ``rd_<hash>.<ext>``: the module, keyed by a hash of the full source, the compiler's
  version, the flags and the Python/numpy ABI.

Every file is written under a temporary name and renamed into place (``os.replace``), so
two processes compiling the same robot at once both succeed and the cache never holds a
half-written file.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import importlib.machinery
import importlib.util
import os
import shutil
import subprocess
import sys
import sysconfig
import tempfile
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType

import numpy as np

from robodyn.common.files import atomic_write_text
from robodyn.compiled import simd
from robodyn.exceptions import CompileError, CompilerNotFoundError

#: Compiler flags. No -ffast-math: results must match Pinocchio to 1e-12. -O1, not -O2/-O3:
#: on the generated straight-line code it runs as fast (measured, panda arm) and compiles in
#: half the time.
FLAGS = ("-O1", "-fPIC", "-shared", "-pthread", "-fno-math-errno", "-std=c99")
_RUNTIME = Path(__file__).with_name("runtime.c")
_PRELUDE = """#define PY_SSIZE_T_CLEAN
#include <Python.h>
#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>
#include <math.h>
#include <pthread.h>
#include <string.h>
"""


def cache_dir() -> Path:
    """Where compiled robots are kept: ``$ROBODYN_CACHE``, else ``$XDG_CACHE_HOME/robodyn``,
    else ``~/.cache/robodyn`` (subfolder ``compiled``)."""
    root = os.environ.get("ROBODYN_CACHE")
    if not root:
        xdg = os.environ.get("XDG_CACHE_HOME")
        root = str(Path(xdg) / "robodyn") if xdg else str(Path.home() / ".cache" / "robodyn")
    return Path(root).expanduser() / "compiled"


def find_compiler() -> str:
    """The C compiler: ``$CC``, else ``cc``, ``gcc`` or ``clang`` on the PATH.

    Raises:
        CompilerNotFoundError: If there is none.
    """
    candidates = [os.environ["CC"]] if os.environ.get("CC") else ["cc", "gcc", "clang"]
    for candidate in candidates:
        path = shutil.which(candidate)
        if path:
            return path
    raise CompilerNotFoundError(candidates[0])


@functools.lru_cache(maxsize=8)
def _compiler_identity(compiler: str, mtime: float) -> str:
    """The compiler's ``--version`` banner (cached per process and compiler binary)."""
    try:
        result = subprocess.run([compiler, "--version"], capture_output=True, text=True, timeout=30, check=False)
    except OSError as error:
        raise CompilerNotFoundError(compiler, str(error)) from None
    return result.stdout.strip()


def toolchain_key(compiler: str) -> str:
    """What besides the source decides the binary: compiler version, flags, Python and numpy ABI."""
    identity = _compiler_identity(compiler, os.stat(compiler).st_mtime)
    return "\n".join([identity, " ".join(FLAGS), sysconfig.get_config_var("EXT_SUFFIX") or "", np.__version__, sys.version])


def digest(*parts: str) -> str:
    """A short SHA-256 of text parts."""
    hasher = hashlib.sha256()
    for part in parts:
        hasher.update(part.encode("utf-8"))
        hasher.update(b"\0")
    return hasher.hexdigest()[:24]


def runtime_source() -> str:
    """``runtime.c`` after the controllers' generated constants (kinds, parameter layouts:
    :func:`robodyn.compiled.controllers.c_constants`)."""
    from robodyn.compiled.controllers import c_constants

    return c_constants() + _RUNTIME.read_text(encoding="utf-8")


def module_source(kernels: str, module_name: str) -> str:
    """The full C source: includes, the robot's kernels, the runtime and the module init."""
    init = f'PyMODINIT_FUNC PyInit_{module_name}(void) {{ return rd_module("{module_name}"); }}\n'
    return _PRELUDE + kernels + "\n" + runtime_source() + "\n" + init


def cached_kernels(key: str) -> str | None:
    """The generated kernels stored under a robot key, if any."""
    path = cache_dir() / f"src-{key}.c"
    try:
        return path.read_text(encoding="utf-8")
    except OSError:
        return None


@contextlib.contextmanager
def locked(key: str) -> Iterator[None]:
    """Hold an exclusive lock on a robot key (``lock-<key>`` in the cache, ``flock``) while
    deriving and building it: a second process compiling the same robot waits, then finds it
    cached, instead of deriving and building it a second time. No lock where the cache is read-only or
    the platform has no ``fcntl``."""
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


def store_kernels(key: str, kernels: str) -> None:
    """Keep the generated kernels for a robot key (atomically; a read-only cache is skipped)."""
    with contextlib.suppress(OSError):
        atomic_write_text(cache_dir() / f"src-{key}.c", kernels)


def build_module(kernels: str, *, label: str, vector: bool = True) -> ModuleType:
    """Compile (or find in the cache) and import the extension module for some kernels.

    Args:
        kernels: The robot's generated kernels (:mod:`robodyn.compiled.codegen`).
        label: The robot's name, for messages only.
        vector: Add the kernels' SIMD variants for batches (:mod:`robodyn.compiled.simd`).

    Raises:
        CompilerNotFoundError: No C compiler.
        CompileError: The compiler failed (its first error line is quoted).
        InputError: ``$ROBODYN_SIMD`` names an instruction set the module cannot run here.
    """
    if vector and (variants := simd.vector_source(kernels)):
        # The SIMD batches (robodyn.compiled.simd); if a compiler cannot build them, scalar batches.
        with contextlib.suppress(CompileError):
            return simd.configure(build_module(kernels + variants, label=label, vector=False))
    compiler = find_compiler()
    runtime = runtime_source()
    name = "rd_" + digest(kernels, runtime, toolchain_key(compiler))
    suffix = sysconfig.get_config_var("EXT_SUFFIX") or ".so"
    folder = cache_dir()
    target = folder / f"{name}{suffix}"
    if not target.exists():
        _compile(compiler, module_source(kernels, name), folder, target, label)
    return _import(name, target)


def _compile(compiler: str, source: str, folder: Path, target: Path, label: str) -> None:
    try:
        folder.mkdir(parents=True, exist_ok=True)
        work = Path(tempfile.mkdtemp(prefix=".build-", dir=folder))
    except OSError as error:
        raise CompileError(label, f"the cache folder {folder} is not writable ({error.strerror}); set ROBODYN_CACHE") from None
    try:
        c_file = work / "module.c"
        c_file.write_text(source, encoding="utf-8")
        output = work / target.name
        includes = [f"-I{sysconfig.get_paths()['include']}", f"-I{np.get_include()}"]
        command = [compiler, *FLAGS, *includes, str(c_file), "-o", str(output), "-lm"]
        try:
            result = subprocess.run(command, capture_output=True, text=True, timeout=600, check=False)
        except (OSError, subprocess.TimeoutExpired) as error:
            raise CompileError(label, f"the C compiler {compiler} could not run ({error})") from None
        if result.returncode != 0:
            lines = [line for line in result.stderr.splitlines() if "error" in line] or result.stderr.splitlines() or ["?"]
            raise CompileError(label, f"the C compiler failed: {lines[0][:200]}")
        os.replace(output, target)
    finally:
        shutil.rmtree(work, ignore_errors=True)


def _import(name: str, path: Path) -> ModuleType:
    if name in sys.modules:
        return sys.modules[name]
    loader = importlib.machinery.ExtensionFileLoader(name, str(path))
    spec = importlib.util.spec_from_file_location(name, str(path), loader=loader)
    assert spec is not None  # an explicit loader always yields a spec
    module = importlib.util.module_from_spec(spec)
    loader.exec_module(module)
    sys.modules[name] = module
    return module


def build_extension(kernels: str, runtime: str, *, init: str, label: str) -> ModuleType:
    """Like :func:`build_module`, for a module of its own: ``runtime`` (more C, with its own
    method table) follows ``runtime.c``, and the module is made by the C function ``init``
    (``PyObject *init(const char *name)``). Used by the derivative kernels
    (:mod:`robodyn.compiled.derivatives`), built only when first asked for.

    Raises:
        CompilerNotFoundError: No C compiler.
        CompileError: The compiler failed (its first error line is quoted).
    """
    compiler = find_compiler()
    base = runtime_source()
    name = "rd_" + digest(kernels, base, runtime, init, toolchain_key(compiler))
    target = cache_dir() / f"{name}{sysconfig.get_config_var('EXT_SUFFIX') or '.so'}"
    if not target.exists():
        entry = f'PyMODINIT_FUNC PyInit_{name}(void) {{ return {init}("{name}"); }}\n'
        source = _PRELUDE + kernels + "\n" + base + "\n" + runtime + "\n" + entry
        _compile(compiler, source, cache_dir(), target, label)
    return _import(name, target)
