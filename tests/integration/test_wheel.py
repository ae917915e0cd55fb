"""robodyn as a user installs it from a clone: the wheel, built and installed in a fresh
virtual environment (issue 29, item 12; robodyn is on no package index).

The wheel is built from a copy of the repository's tracked files (so no ``build/`` or
``*.egg-info`` lands in the checkout) with pip's build isolation, as ``pip install .`` does.
It is installed with ``--no-deps`` into a new venv whose only other packages are those of
the running environment (the pinned lock), reached through path files (all but the
editable install's): so the robodyn that runs there is the wheel's, nothing of the
checkout, and only the build's own requirements (setuptools) may be fetched.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import sys
import sysconfig
import venv
import zipfile
from pathlib import Path

import numpy as np
import pytest

import robodyn
from tests.conftest import ROOT

pytestmark = pytest.mark.slow

STATE = "q = np.array([0.4, 0.1]); v = np.array([0.3, -0.2]); a = np.array([0.5, 0.25])"


def _tracked(prefix: str) -> list[str]:
    listed = subprocess.run(["git", "ls-files", "-z", prefix], cwd=ROOT, capture_output=True, check=True).stdout
    return [name for name in listed.decode().split("\0") if name and (ROOT / name).is_file()]


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    """``(wheel, python, robodyn script)`` of a fresh venv with the wheel installed."""
    if shutil.which("git") is None or not (ROOT / ".git").exists():
        pytest.skip("needs the git checkout (the wheel is built from its tracked files)")
    work = tmp_path_factory.mktemp("wheel")
    source = work / "source"
    for name in _tracked("."):
        if name.startswith(("tests/", "docs/")):
            continue
        (source / name).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / name, source / name)
    built = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "--quiet", "-w", str(work / "dist"), str(source)],
        capture_output=True, text=True, timeout=600,
    )  # fmt: skip
    assert built.returncode == 0, built.stderr[-2000:]
    (wheel,) = (work / "dist").glob("robodyn-*.whl")
    fresh = work / "venv"
    venv.EnvBuilder(with_pip=False).create(fresh)
    python = fresh / "bin" / "python"
    site = Path(subprocess.run([python, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                               capture_output=True, text=True, check=True).stdout.strip())  # fmt: skip
    here = Path(sysconfig.get_paths()["purelib"])
    (site / "00_dependencies.pth").write_text(f"{here}\n")  # first: the others import from there
    for path_file in here.glob("*.pth"):  # e.g. cmeel's, which puts Pinocchio on the path
        if not path_file.name.startswith("__editable__"):  # never the checkout's robodyn
            shutil.copy(path_file, site / path_file.name)
    pip = [sys.executable, "-m", "pip", "--python", str(python), "install", "--no-deps", "--no-index", "--quiet"]
    done = subprocess.run([*pip, f"{wheel}[zoo]"], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    return wheel, python, fresh / "bin" / "robodyn"


def _run(command, **options) -> subprocess.CompletedProcess:
    env = {key: value for key, value in os.environ.items() if key not in ("PYTHONPATH", "PYTHONHOME")}
    return subprocess.run(command, capture_output=True, text=True, timeout=300, env=env, **options)


def test_the_wheel_holds_every_module_and_data_file_of_the_package(installed):
    wheel, _python, _script = installed
    with zipfile.ZipFile(wheel) as archive:
        names = set(archive.namelist())
        package = [name for name in _tracked("robodyn") if not name.endswith(".pyc")]
        assert package and set(package) <= names, sorted(set(package) - names)[:10]
        assert "robodyn/compiled/runtime.c" in names  # the C runtime of the compiled engine
        for name in package:
            assert hashlib.sha256(archive.read(name)).digest() == hashlib.sha256((ROOT / name).read_bytes()).digest()
        metadata = archive.read(next(n for n in names if n.endswith(".dist-info/METADATA"))).decode()
    for requirement in ("pin", "numpy", "sympy", "yourdfpy"):
        assert f"Requires-Dist: {requirement}" in metadata
    assert "example-robot-data" in metadata and 'extra == "zoo"' in metadata


def test_the_installed_command_and_library_answer_from_the_wheel(installed, tmp_path):
    _wheel, python, script = installed
    version = _run([str(script), "--version"], cwd=tmp_path)
    assert version.returncode == 0 and version.stdout.strip() == f"robodyn {robodyn.__version__}"
    code = (
        "import numpy as np, robodyn, robodyn.compiled.build as build; "
        f"{STATE}; "
        "print(robodyn.__file__); print(build._RUNTIME.is_file()); "
        "print(*robodyn.load('rp_arm').inverse_dynamics(q, v, a)); "
        "print(robodyn.load('ur5').nv)"
    )
    answer = _run([str(python), "-c", code], cwd=tmp_path)
    assert answer.returncode == 0, answer.stderr[-2000:]
    location, runtime, tau, ur5 = answer.stdout.strip().splitlines()
    assert Path(location).is_relative_to(python.parent.parent) and not Path(location).is_relative_to(ROOT / "robodyn")
    assert runtime == "True" and ur5 == "6"  # the C runtime is there; the zoo extra loads
    namespace: dict = {"np": np}
    exec(STATE, namespace)
    expected = robodyn.load("rp_arm").inverse_dynamics(namespace["q"], namespace["v"], namespace["a"])
    np.testing.assert_allclose([float(x) for x in tau.split()], expected, rtol=1e-12)
