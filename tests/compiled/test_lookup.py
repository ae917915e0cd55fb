"""The cache lookup of engine="auto": the same key as the compiler's, without the code generator."""

from __future__ import annotations

import subprocess
import sys

import robodyn
from robodyn.compiled import lookup
from robodyn.compiled.build import cache_dir
from robodyn.compiled.robot import robot_key
from tests.conftest import ROOT


def test_the_lookup_key_is_the_compilers_key(monkeypatch, tmp_path):
    monkeypatch.setenv("ROBODYN_CACHE", str(tmp_path))
    robots = [robodyn.load("rp_arm"), robodyn.load("rp_arm", gravity=[0.0, 1.0, -3.0]), robodyn.load("solo12")]
    assert [lookup.robot_key(robot) for robot in robots] == [robot_key(robot) for robot in robots]
    assert len({lookup.robot_key(robot) for robot in robots}) == 3  # negative control: the keys differ
    assert lookup.cache_dir() == cache_dir()
    assert not lookup.compiled_before(robots[0])


def test_looking_up_imports_no_code_generator():
    code = (
        "import sys, robodyn; from robodyn.compiled import lookup; "
        "print(lookup.compiled_before(robodyn.load('rp_arm')), 'sympy' in sys.modules)"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True, timeout=120)
    assert result.stdout.split()[-1] == "False"
