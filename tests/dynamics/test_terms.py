"""DynamicsTerms: tau, M, C, G at one state, with names and units from robot.dofs (issue 23)."""

from __future__ import annotations

import json

import numpy as np

import robodyn
from robodyn.cli import main
from robodyn.dynamics.terms import dynamics_terms
from tests.sim.robots import SLIDER_URDF


def test_the_terms_make_up_the_inverse_dynamics():
    robot = robodyn.load(SLIDER_URDF, floating_base=True)
    rng = np.random.default_rng(3)
    q = robot.random_configuration(rng)
    v, a = rng.normal(size=(2, robot.nv))
    terms = dynamics_terms(robot, q, v, a)
    np.testing.assert_allclose(terms.M @ a + terms.C @ v + terms.G, terms.tau, atol=1e-10)


def test_to_dict_is_the_json_the_cli_prints_with_the_units_of_the_dofs(capsys):
    assert main(["equations", SLIDER_URDF, "--floating-base", "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    robot = robodyn.load(SLIDER_URDF, floating_base=True)
    terms = dynamics_terms(robot, robot.default_configuration(), np.zeros(robot.nv), np.zeros(robot.nv))
    assert printed == json.loads(json.dumps(terms.to_dict()))
    assert printed["units"]["tau"] == ["N", "N", "N", "N m", "N m", "N m", "N m", "N"]
    assert printed["units"]["v"] == ["m/s"] * 3 + ["rad/s"] * 4 + ["m/s"]
    assert printed["units"]["a"] == [dof.acceleration_unit for dof in robot.dofs]


def test_the_text_names_each_dof_with_its_units_and_marks_the_base():
    robot = robodyn.load(SLIDER_URDF, floating_base=True)
    q = robot.default_configuration()
    q[-1] = 0.125
    text = dynamics_terms(robot, q, np.zeros(robot.nv), np.zeros(robot.nv)).text()
    rows = {line.split()[0]: line for line in text.splitlines()[3 : 3 + robot.nv]}
    assert list(rows) == [dof.name for dof in robot.dofs]
    assert "(base)" in rows["base.x"] and "(base)" in rows["base.rz"]
    assert "0.125 m" in rows["slide"] and " m/s " in rows["slide"] and rows["slide"].rstrip().endswith("N")
    assert " rad " in rows["shoulder"] and rows["shoulder"].rstrip().endswith("N m")
    assert "base vx" not in text  # one naming scheme: the dofs'
