"""Closed-form forward kinematics and Jacobians agree with Pinocchio's."""

from __future__ import annotations

import ctypes
import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

import robodyn
from robodyn.cli.app import main
from robodyn.equations.kinematics import derive_kinematics, render_kinematics

DATA = Path(__file__).parents[1] / "data"
CASES = [(str(DATA / "rrp_arm.urdf"), "slider"), (str(DATA / "mimic_arm.urdf"), "tip"), ("rp_arm", "link2")]


def module_of(kinematics) -> dict:
    namespace: dict = {}
    exec(render_kinematics(kinematics, "python"), namespace)
    return namespace


@pytest.mark.parametrize(("name", "frame"), CASES, ids=[f for _, f in CASES])
def test_generated_kinematics_agree_with_pinocchio(name, frame, rng):
    module = module_of(derive_kinematics(name, frame))
    robot = robodyn.load(name)
    q = robot.random_configuration(rng, 10)
    assert np.max(np.abs(module["frame_position"](q) - robot.frame_position(q, frame))) < 1e-12
    assert np.max(np.abs(module["frame_jacobian"](q) - robot.frame_jacobian(q, frame))) < 1e-12
    assert np.max(np.abs(module["frame_jacobian"](q[0]) - robot.frame_jacobian(q[0], frame))) < 1e-12
    # Negative control: another frame's kinematics differ.
    assert np.max(np.abs(module["frame_position"](q) - robot.frame_position(q, robot.frame_names[0]))) > 1e-3


@pytest.mark.slow
def test_ur5_tool_frame_through_fixed_joints(rng):
    module = module_of(derive_kinematics("ur5", "tool0"))
    robot = robodyn.load("ur5")
    q = robot.random_configuration(rng, 10)
    assert np.max(np.abs(module["frame_jacobian"](q) - robot.frame_jacobian(q, "tool0"))) < 1e-9


def test_cli_kinematics(capsys):
    assert main(["equations", "rp_arm", "--symbolic", "--kinematics", "link2", "--format", "json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["frame"] == "link2" and len(data["jacobian"]) == 6
    assert main(["equations", "rp_arm", "--symbolic", "--kinematics", "link2"]) == 0
    assert "J[1,1] = " in capsys.readouterr().out
    assert main(["equations", "rp_arm", "--symbolic", "--kinematics", "no_such_link"]) == 2
    assert main(["equations", "rp_arm", "--symbolic", "--kinematics", "link2", "--format", "pdf", "--out", "x.pdf"]) == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 2


@pytest.mark.skipif(shutil.which("gcc") is None, reason="needs a C compiler")
def test_generated_c_kinematics_compile_and_agree(tmp_path, rng):
    name, frame = CASES[0]
    source, library = tmp_path / "kinematics.c", tmp_path / "libkinematics.so"
    source.write_text(render_kinematics(derive_kinematics(name, frame), "c"))
    subprocess.run(
        ["gcc", "-std=c99", "-Wall", "-Werror", "-shared", "-fPIC", str(source), "-o", str(library), "-lm"], check=True
    )
    lib = ctypes.CDLL(str(library))
    robot = robodyn.load(name)
    pointer = ctypes.POINTER(ctypes.c_double)
    q = robot.random_configuration(rng)
    p, J = np.zeros(3), np.zeros(6 * robot.nv)
    lib.frame_position(q.ctypes.data_as(pointer), p.ctypes.data_as(pointer))
    lib.frame_jacobian(q.ctypes.data_as(pointer), J.ctypes.data_as(pointer))
    assert np.max(np.abs(p - robot.frame_position(q, frame))) < 1e-12
    assert np.max(np.abs(J.reshape(6, -1) - robot.frame_jacobian(q, frame))) < 1e-12
