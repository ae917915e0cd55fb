"""Building, caching and loading a robot's compiled dynamics (a CPython extension module).

The generated kernels and ``runtime.c`` are compiled by the system C compiler into an
extension module (``PyInit_…``) that takes numpy arrays directly. An extension module and
not ctypes or cffi: on this machine a ctypes call passing four arrays costs 4.6 µs, twice
``pin.rnea`` itself, most of it in ``ndarray.ctypes``; a METH_FASTCALL function reads the
arrays' buffers and allocates the result in C, and is the thinnest binding there is.

The cache (:mod:`robodyn.compiled.cache`: ``$ROBODYN_CACHE``, else
``$XDG_CACHE_HOME/robodyn``, else ``~/.cache/robodyn``; subfolder ``compiled/``) holds:

- ``src-<key>.c``: the generated kernels, under the robot's key
  (:func:`robodyn.compiled.cache.robot_key`: its URDF text and options, and the hash of the
  generator's source; the sympy derivation is the slow part);
- ``rd_<hash>.<ext>``: the module, named by a hash of the robot's key, the SIMD variants
  built (:mod:`robodyn.compiled.simd`), the compiler's version, the flags and the
  Python/numpy ABI — all known without generating any source, so finding a compiled robot
  (:func:`lookup`) neither derives nor prints anything, and imports no sympy;

and a process keeps every module it loaded (:func:`loaded`): a second ``compile`` of the same
robot costs microseconds.
"""

from __future__ import annotations

import contextlib
import functools
import importlib.machinery
import importlib.util
import os
import shutil
import subprocess
import sys
import sysconfig
import tempfile
from collections.abc import Callable
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING

import numpy as np

from robodyn.compiled import simd
from robodyn.compiled.cache import cache_dir, cached_kernels, digest, locked, robot_key, store_kernels
from robodyn.exceptions import CompileError, CompilerNotFoundError

if TYPE_CHECKING:
    from robodyn.dynamics.robot import Robot

#: Compiler flags. No -ffast-math: results must match Pinocchio to 1e-12. -O1, not -O2/-O3:
#: on the generated straight-line code it runs as fast (measured, panda arm) and compiles in
#: half the time.
FLAGS = ("-O1", "-fPIC", "-shared", "-pthread", "-fno-math-errno", "-std=c99")
_RUNTIME = Path(__file__).with_name("runtime.c")
#: The C every module shares (the tree LDLᵀ, the thread pool), placed before its kernels.
CORE = Path(__file__).with_name("core.c")
_INCLUDES = """#define PY_SSIZE_T_CLEAN
#include <Python.h>
#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>
#include <math.h>
#include <pthread.h>
#include <string.h>
"""


def prelude() -> str:
    """What precedes every module's kernels: the includes and ``core.c``."""
    return _INCLUDES + CORE.read_text(encoding="utf-8") + "\n"


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
    """What besides the source decides the binary: compiler version, flags, Python and numpy ABI.

    Args:
        compiler: Path of the C compiler executable (:func:`find_compiler`).
    """
    identity = _compiler_identity(compiler, os.stat(compiler).st_mtime)
    return "\n".join([identity, " ".join(FLAGS), sysconfig.get_config_var("EXT_SUFFIX") or "", np.__version__, sys.version])


def runtime_source() -> str:
    """``runtime.c`` after the controllers' generated constants (kinds, parameter layouts:
    :func:`robodyn.compiled.controllers.c_constants`)."""
    from robodyn.compiled.controllers import c_constants

    return c_constants() + _RUNTIME.read_text(encoding="utf-8")


def module_source(kernels: str, module_name: str) -> str:
    """The full C source: includes, the robot's kernels, the runtime and the module init.

    Args:
        kernels: The robot's generated kernels' C source (:mod:`robodyn.compiled.codegen`).
        module_name: The extension module's name (``PyInit_<module_name>``).
    """
    init = f'PyMODINIT_FUNC PyInit_{module_name}(void) {{ return rd_module("{module_name}"); }}\n'
    return prelude() + kernels + "\n" + runtime_source() + "\n" + init


def _suffix() -> str:
    return sysconfig.get_config_var("EXT_SUFFIX") or ".so"


def module_path(key: str, compiler: str) -> Path:
    """Where the module of a robot key is (or would be) for this compiler, flags, ABI and
    SIMD variants (:func:`robodyn.compiled.simd.build_variants`): no source needed.

    Args:
        key: The robot's cache key (:func:`robodyn.compiled.cache.robot_key`).
        compiler: Path of the C compiler executable (:func:`find_compiler`).

    Raises:
        InputError: ``$ROBODYN_SIMD`` names no instruction set.
    """
    variants = " ".join(name for name, _, _ in simd.build_variants())
    return cache_dir() / f"rd_{digest(key, 'simd=' + variants, toolchain_key(compiler))}{_suffix()}"


#: The modules this process loaded, by robot key and the environment that chose them.
_LOADED: dict[tuple[str, tuple[str | None, ...]], ModuleType] = {}
_ENVIRONMENT = ("CC", "ROBODYN_CACHE", "XDG_CACHE_HOME", "HOME", simd.ENVIRONMENT)


def _memo(key: str) -> tuple[str, tuple[str | None, ...]]:
    environ = os.environ
    return key, tuple(environ.get(name) for name in _ENVIRONMENT)


def loaded(robot: Robot) -> ModuleType | None:
    """The robot's module if this process loaded it already (under the same compiler, cache
    folder and ``$ROBODYN_SIMD``): a dictionary look-up, microseconds.

    Args:
        robot: The loaded robot (its cache key, :func:`robodyn.compiled.cache.robot_key`).
    """
    return _LOADED.get(_memo(robot_key(robot)))


def lookup(robot: Robot) -> Path | None:
    """The robot's compiled module in the cache, or None if it is not compiled (or there is no
    C compiler). Computes the key only: imports no sympy and no code generator, generates no
    source (the engine choice of :func:`robodyn.simulate` asks this).

    Args:
        robot: The loaded robot (its cache key, :func:`robodyn.compiled.cache.robot_key`).

    Raises:
        InputError: ``$ROBODYN_SIMD`` names no instruction set.
    """
    try:
        path = module_path(robot_key(robot), find_compiler())
    except CompilerNotFoundError:
        return None
    return path if path.exists() else None


def is_compiled(robot: Robot) -> bool:
    """Whether :func:`robodyn.compiled.compile` would find the robot's module cached (:func:`lookup`)."""
    return lookup(robot) is not None


def robot_module(key: str, kernels: Callable[[], str], *, label: str) -> ModuleType:
    """The module of a robot key: loaded by this process, else cached, else built from
    ``kernels()`` (called only then: the generated kernels, cached or derived). The SIMD
    variants' source is generated only for a build; a build whose variants the compiler
    rejects is the scalar kernels' (batches then run scalar rows).

    Args:
        key: The robot's cache key (:func:`robodyn.compiled.cache.robot_key`).
        kernels: Returns the robot's generated kernels' C source; called only to build.
        label: The robot's name, for messages only.

    Raises:
        CompilerNotFoundError: No C compiler.
        CompileError: The compiler failed (its first error line is quoted).
        InputError: ``$ROBODYN_SIMD`` names an instruction set the module cannot run here.
    """
    memo = _memo(key)
    module = _LOADED.get(memo)
    if module is not None:
        return module
    compiler = find_compiler()
    target = module_path(key, compiler)
    name = target.name.split(".")[0]
    if not target.exists():
        with locked(key):
            if not target.exists():
                _build_robot(compiler, kernels(), target, label)
    module = _import(name, target)
    if hasattr(module, "simd"):
        simd.configure(module)
    _LOADED[memo] = module
    return module


def _build_robot(compiler: str, kernels: str, target: Path, label: str) -> None:
    """Compile a robot's module with its SIMD variants, or, if the compiler rejects them, without."""
    name = target.name.split(".")[0]
    variants = simd.vector_source(kernels)
    if variants:
        with contextlib.suppress(CompileError):
            _compile(compiler, module_source(kernels + variants, name), cache_dir(), target, label)
            return
    _compile(compiler, module_source(kernels, name), cache_dir(), target, label)


def build_module(kernels: str, *, label: str, vector: bool = True) -> ModuleType:
    """Compile (or find in the cache) and import the extension module for some kernels, named
    by a hash of their source (a robot's modules go through :func:`robot_module`, by key).

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
    runtime = _RUNTIME.read_text(encoding="utf-8")
    name = "rd_" + digest(kernels, runtime, CORE.read_text(encoding="utf-8"), toolchain_key(compiler))
    target = cache_dir() / f"{name}{_suffix()}"
    if not target.exists():
        _compile(compiler, module_source(kernels, name), cache_dir(), target, label)
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


def keyed_extension(key: str, source: Callable[[], str], *, init: str, label: str, prefix: str = "rd_") -> ModuleType:
    """A module of its own (the derivative kernels, a frame's kinematics) named by a cache
    key: found by the key alone, ``source()`` (its C after the includes and ``core.c``) asked
    for only to build it. The module is made by the C function ``init``
    (``PyObject *init(const char *name)``).

    Args:
        key: The cache key the module is named and locked by.
        source: Returns the module's C source (after the includes and ``core.c``); called
            only to build.
        init: Name of the C function that creates the module.
        label: What is compiled, for messages only.
        prefix: The start of the module's name (a hash of ``key`` follows).

    Raises:
        CompilerNotFoundError: No C compiler.
        CompileError: The compiler failed (its first error line is quoted).
    """
    compiler = find_compiler()
    name = prefix + digest(key, init, toolchain_key(compiler))
    target = cache_dir() / f"{name}{_suffix()}"
    if not target.exists():
        with locked(key):
            if not target.exists():
                entry = f'PyMODINIT_FUNC PyInit_{name}(void) {{ return {init}("{name}"); }}\n'
                _compile(compiler, prelude() + source() + "\n" + entry, cache_dir(), target, label)
    return _import(name, target)


__all__ = [
    "FLAGS",
    "build_module",
    "cache_dir",
    "cached_kernels",
    "digest",
    "find_compiler",
    "is_compiled",
    "keyed_extension",
    "loaded",
    "locked",
    "lookup",
    "module_path",
    "robot_key",
    "robot_module",
    "runtime_source",
    "store_kernels",
    "toolchain_key",
]
