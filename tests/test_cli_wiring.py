"""Commands that join two parts of robodyn: equations --base-parameters, default states within limits."""

from __future__ import annotations

import json

import numpy as np

import robodyn
from robodyn.cli.app import main


def test_equations_prints_the_base_parameters(capsys):
    assert main(["equations", "rp_arm", "--base-parameters", "--format", "json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["count"] == robodyn.base_parameters(robodyn.load("rp_arm")).count == 6
    assert main(["equations", "rp_arm", "--base-parameters", "--format", "python"]) == 2
    assert capsys.readouterr().err.count("\n") == 1


def test_equations_at_the_default_state_lies_within_the_limits(capsys):
    robot = robodyn.load("panda")
    assert main(["equations", "panda", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    q = np.array(data["q"])
    assert np.all(q >= robot.lower_limits - 1e-12) and np.all(q <= robot.upper_limits + 1e-12)
    np.testing.assert_allclose(data["tau"], robot.gravity(q), atol=1e-12)
