"""casadi_functions and module_source: printed once per robot, built once per process."""

from __future__ import annotations

import pytest

import robodyn
from robodyn.export import casadi_functions, functions, module_source
from tests.conftest import random_states
from tests.export.cases import CASES, differences


def test_a_second_call_prints_and_builds_nothing_and_gives_the_same_functions(monkeypatch, rng):
    path, options = CASES["gripper_locked_prismatic"]
    robot = robodyn.load(path, **options)
    first = casadi_functions(robot)
    text = module_source(robot, "casadi")

    def fail(*args, **kwargs):
        pytest.fail("printed or built again")

    monkeypatch.setattr(functions, "module_text", fail)
    monkeypatch.setattr(functions, "export_programs", fail)
    again = casadi_functions(robot)
    assert again is not first and again.keys() == first.keys()
    assert all(again[name] is first[name] for name in first)
    assert module_source(robot, "casadi") == text
    q, v, a = (x[0] for x in random_states(robot, rng, 1))
    assert max(differences(robot, again, q, v, a).values()) <= 1e-12
    with pytest.raises(pytest.fail.Exception, match="printed or built again"):  # negative control: other frames
        casadi_functions(robot, frames=[robot.frame_names[-1]])
