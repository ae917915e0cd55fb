"""`robodyn linearize`: the library's (A, B) as text and JSON; errors as one line naming the flag."""

from __future__ import annotations

import json

import numpy as np

import robodyn
from robodyn.cli.app import main


def test_json_carries_the_librarys_matrices(capsys):
    arguments = [
        "linearize",
        "rp_arm",
        "--q",
        "0.5,0.1",
        "--v",
        "0.3,-0.2",
        "--dt",
        "0.01",
        "--integrator",
        "semi-implicit-euler",
    ]
    assert main([*arguments, "--json"]) == 0
    document = json.loads(capsys.readouterr().out)
    robot = robodyn.load("rp_arm")
    A, B = robodyn.linearize(robot, [0.5, 0.1], [0.3, -0.2], dt=0.01, integrator="semi-implicit-euler")
    np.testing.assert_array_equal(np.array(document["A"]), A)
    np.testing.assert_array_equal(np.array(document["B"]), B)
    assert document["state"] == ["q[joint1]", "q[joint2]", "v[joint1]", "v[joint2]"] and document["dt"] == 0.01
    assert main(arguments) == 0
    text = capsys.readouterr().out
    assert "semi-implicit-euler step of dt = 0.01 s" in text and "v[joint2]" in text


def test_actuated_joints_select_the_columns_of_b(capsys):
    assert main(["linearize", "double_pendulum_continuous", "--actuated", "joint2", "--json"]) == 0
    document = json.loads(capsys.readouterr().out)
    assert document["inputs"] == ["joint2"] and np.array(document["B"]).shape == (4, 1)


def test_errors_are_one_line_naming_the_flag(capsys):
    for arguments, flag in ((["--actuated", "elbow"], "--actuated"), (["--q", "1,2,3"], "--q"), (["--dt", "0"], "--dt")):
        assert main(["linearize", "rp_arm", *arguments]) == 2
        error = capsys.readouterr().err.strip()
        assert error.count("\n") == 0 and flag in error, error
