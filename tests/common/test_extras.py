"""`pip install robodyn` alone loads a URDF and computes τ; a missing extra is named in one line."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from robodyn.common.extras import require
from robodyn.exceptions import MissingExtraError, RobodynError

ROOT = Path(__file__).resolve().parents[2]
CORE = ("pin", "yourdfpy", "numpy", "sympy")


def test_require_names_the_extra():
    with pytest.raises(MissingExtraError, match=r"'robodyn\[viewer\]' extra \(pip install '\.\[viewer\]' in a clone") as caught:
        require("robodyn_no_such_module", extra="viewer", purpose="recordings")
    assert isinstance(caught.value, RobodynError) and caught.value.extra == "viewer"
    assert "\n" not in str(caught.value)
    assert require("json", extra="none", purpose="x").__name__ == "json"


def _locked(names: tuple[str, ...]) -> list[str]:
    pins = {
        line.split("==")[0].lower(): line.strip()
        for line in (ROOT / "requirements.lock").read_text().splitlines()
        if "==" in line
    }
    return [pins[name] for name in names]


@pytest.mark.slow
def test_a_core_only_install_loads_a_urdf_and_computes_torques(tmp_path):
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    python = venv / "bin" / "python"
    # The core's dependencies, as pinned, and robodyn itself without its declared dependencies.
    install = subprocess.run(
        [str(python), "-m", "pip", "install", "--quiet", *_locked(CORE)], capture_output=True, text=True, timeout=900
    )
    if install.returncode != 0:
        pytest.skip(f"could not install the core dependencies here: {install.stderr.strip()[-300:]}")
    subprocess.run(
        [str(python), "-m", "pip", "install", "--quiet", "--no-deps", str(ROOT)],
        check=True,
        timeout=900,
        capture_output=True,
    )
    script = f"""
import numpy as np, robodyn
robot = robodyn.load({str(ROOT / "urdf" / "rp_arm.urdf")!r})
print(robot.inverse_dynamics(np.array([0.5, 0.1]), np.array([1.0, 0.2]), np.array([0.5, -0.3])))
try:
    robodyn.load("ur5")
except robodyn.RobodynError as error:
    print("ZOO:", error)
"""
    result = subprocess.run([str(python), "-c", script], capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "[" in result.stdout and "ZOO:" in result.stdout
    assert "robodyn[zoo]" in result.stdout
    for module in ("example_robot_data", "meshcat", "matplotlib"):
        missing = subprocess.run([str(python), "-c", f"import {module}"], capture_output=True, timeout=60)
        assert missing.returncode != 0, f"{module} should not be installed in a core-only venv"
