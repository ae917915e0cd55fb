"""The runnable examples in scripts/ run headless and say what they did."""

from __future__ import annotations

import subprocess
import sys

import pytest

from tests.conftest import ROOT


@pytest.mark.parametrize(
    ("script", "arguments", "expected"),
    [
        ("example_dynamics.py", ["ur5"], "largest static torque"),
        ("example_control.py", ["{tmp}"], "from the target"),
        ("example_whatif.py", [], "steel"),
    ],
)
def test_example_runs(script, arguments, expected, tmp_path):
    arguments = [a.format(tmp=tmp_path) for a in arguments]
    result = subprocess.run(
        [sys.executable, str(ROOT / "scripts" / script), *arguments], capture_output=True, text=True, timeout=300, cwd=tmp_path
    )
    assert result.returncode == 0, result.stderr
    assert expected in result.stdout
    if script == "example_control.py":
        assert (tmp_path / "control.png").stat().st_size > 10_000 and (tmp_path / "control.html").stat().st_size > 100_000
