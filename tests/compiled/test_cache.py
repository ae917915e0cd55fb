"""The compiled engine's cache key is nobody's chore, and a cached compile generates nothing."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

import robodyn
from robodyn.compiled import build, cache, simd
from robodyn.compiled import robot as compiled_robot
from tests.compiled_helpers import compiled_pair
from tests.conftest import ROOT

#: Modules no generated code depends on (the package's front door and the error classes).
_OUTSIDE = {"robodyn", "robodyn.exceptions"}


@pytest.fixture(scope="module")
def rp_arm():
    return compiled_pair("rp_arm")


def test_the_key_hashes_every_module_the_generator_imports():
    """Found by walking the packages, not by a list: every robodyn module the code generator,
    the derivatives, the frames and the export load (in a fresh process) is hashed, and the
    C files too."""
    script = textwrap.dedent(
        """
        import sys
        import robodyn.compiled.robot, robodyn.compiled.codegen, robodyn.compiled.programs
        import robodyn.compiled.derivatives, robodyn.compiled.kinematics, robodyn.export.source
        for name, module in sorted(sys.modules.items()):
            if name.startswith("robodyn") and getattr(module, "__file__", None):
                print(name, module.__file__)
        """
    )
    output = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True, cwd=ROOT)
    loaded = dict(line.split(" ", 1) for line in output.stdout.splitlines())
    hashed = set(cache.generator_files())
    missing = sorted(name for name, path in loaded.items() if Path(path).resolve() not in hashed and name not in _OUTSIDE)
    assert missing == []
    assert len(loaded) > 40  # negative control: the generator's imports were really loaded
    folder = Path(compiled_robot.__file__).parent
    for c_file in ("runtime.c", "simd.c", "trig.c", "derivatives.c", "frames.c", "core.c"):
        assert folder / c_file in hashed


def _copy(tmp_path: Path) -> Path:
    """A copy of the package's sources, to edit."""
    copy = tmp_path / "robodyn"
    shutil.copytree(Path(robodyn.__file__).parent, copy, ignore=shutil.ignore_patterns("__pycache__"))
    return copy


def test_an_edit_to_any_generator_file_changes_the_key_and_an_edit_elsewhere_does_not(tmp_path, monkeypatch):
    copy = _copy(tmp_path)
    monkeypatch.setattr(cache, "_ROOT", copy)

    def key() -> str:
        cache.generator_hash.cache_clear()
        return cache.generator_hash()

    before = key()
    (copy / "sim" / "simulation.py").write_text("# not the generator\n", encoding="utf-8")
    assert key() == before  # negative control: a module the kernels do not depend on
    for edited in ("equations/sharing.py", "compiled/runtime.c", "reference/tree.py", "compiled/new_module.py"):
        path = copy / edited
        path.write_text((path.read_text(encoding="utf-8") if path.exists() else "") + "\n# edited\n", encoding="utf-8")
        assert key() != before, edited
        before = key()
    cache.generator_hash.cache_clear()


def test_the_robot_key_tells_options_apart(rp_arm):
    robot, _ = rp_arm
    keys = {
        cache.robot_key(robodyn.load("ur5")),
        cache.robot_key(robodyn.load("ur5", floating_base=True)),
        cache.robot_key(robodyn.load("ur5", gravity=(0.0, 0.0, -9.80665))),
        cache.robot_key(robodyn.load("ur5", armature={"shoulder_pan_joint": 0.1})),
        cache.robot_key(robot),
    }
    assert len(keys) == 5
    assert cache.robot_key(robodyn.load("ur5")) in keys  # the same robot, the same key


def test_a_cached_compile_generates_no_source_in_this_process_or_a_new_one(rp_arm, monkeypatch):
    """The module is found by its key: neither the kernels' nor the SIMD variants' source is
    generated or read, whether this process loaded it already or only the disk has it."""
    robot, compiled = rp_arm

    def fail(*args, **kwargs):
        pytest.fail("generated or read source on a cached compile")

    for where, name in ((simd, "vector_source"), (compiled_robot, "robot_kernels"), (compiled_robot, "generate_kernels")):
        monkeypatch.setattr(where, name, fail)
    monkeypatch.setattr(build, "cached_kernels", fail)
    assert robodyn.compiled.compile(robot).module is compiled.module
    monkeypatch.setattr(build, "_LOADED", {})  # as a new process: only the disk knows it
    again = robodyn.compiled.compile(robot)
    q = np.array([0.3, -0.2])
    assert np.array_equal(again.gravity(q), compiled.gravity(q))


def test_lookup_finds_a_compiled_robot_without_sympy(rp_arm):
    robot, _ = rp_arm
    assert build.lookup(robot) is not None and build.is_compiled(robot)
    script = textwrap.dedent(
        """
        import sys
        import robodyn
        from robodyn.compiled import build
        found = build.lookup(robodyn.load("rp_arm"))
        tilted = build.lookup(robodyn.load("rp_arm", gravity=(1.0, 2.0, -3.0)))
        print(found is not None, tilted is None, "sympy" in sys.modules, "robodyn.compiled.codegen" in sys.modules)
        """
    )
    output = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True, cwd=ROOT)
    assert output.stdout.split() == ["True", "True", "False", "False"]


def test_lookup_in_an_empty_cache_or_without_a_compiler_is_none(rp_arm, tmp_path, monkeypatch):
    robot, _ = rp_arm
    compiled_in = os.environ.get("ROBODYN_CACHE")  # where the fixture compiled it (None: the default)
    monkeypatch.setenv("ROBODYN_CACHE", str(tmp_path))
    assert build.lookup(robot) is None
    if compiled_in is None:
        monkeypatch.delenv("ROBODYN_CACHE")
    else:
        monkeypatch.setenv("ROBODYN_CACHE", compiled_in)
    assert build.lookup(robot) is not None  # negative control: the fixture compiled it
    monkeypatch.setenv("CC", "no-such-compiler-robodyn")
    assert build.lookup(robot) is None


def test_the_packages_left_out_of_the_key_are_the_layers_above_the_generator():
    """``ABOVE_GENERATOR`` is read off the import contracts, not kept by hand: exactly the
    packages of the layers above ``robodyn.compiled`` (but ``export``, which prints the same
    programs), so a package added below is hashed by default."""
    import tomllib

    layers = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]["contracts"][0]["layers"]
    above: set[str] = set()
    for layer in layers:
        names = [part.strip() for part in layer.replace(":", "|").split("|")]
        if "robodyn.compiled" in names:
            break
        above.update(name.removeprefix("robodyn.") for name in names)
    assert above - {"export"} == set(cache.ABOVE_GENERATOR)
    assert "constraints" not in cache.ABOVE_GENERATOR  # negative control: a lower package is hashed
    assert any(path.parent.name == "constraints" for path in cache.generator_files())
