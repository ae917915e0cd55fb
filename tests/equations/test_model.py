"""Symbolic equations honour gravity and mimic joints, and refuse what they cannot do."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

import robodyn
from robodyn.cli.app import main
from robodyn.equations import derive_equations, render
from robodyn.exceptions import DerivationTooExpensiveError
from tests.equations.derived import derived

DATA = Path(__file__).parents[1] / "data"
RRP = str(DATA / "rrp_arm.urdf")
MIMIC = str(DATA / "mimic_arm.urdf")
SIDEWAYS = (9.81, 0.0, 0.0)


def module_of(equations) -> dict:
    namespace: dict = {}
    exec(render(equations, "python"), namespace)
    return namespace


def relative(a, b) -> float:
    return float(np.max(np.abs(a - b)) / max(1.0, np.max(np.abs(b))))


@pytest.mark.parametrize("name", ["rp_arm", RRP, "ur5"], ids=["rp_arm", "rrp_arm", "ur5"])
def test_generated_gravity_is_robots_gravity_under_sideways_gravity(name, rng):
    equations = derive_equations(name, gravity=SIDEWAYS)
    module = module_of(equations)
    robot = robodyn.load(name, gravity=SIDEWAYS)
    q = robot.random_configuration(rng, 20)
    assert relative(module["gravity"](q), robot.gravity(q)) < 1e-9
    # Negative control: the default gravity's equations disagree with this robot.
    default = module_of(derived(name))
    assert relative(default["gravity"](q), robot.gravity(q)) > 1e-3


def test_kept_gravity_is_a_symbol_along_its_axis_and_a_vector_otherwise():
    along = derive_equations("rp_arm", keep_params=True, gravity=(0, 0, -3.7))
    assert {s.name for s in along.parameters} >= {"g"} and along.parameters[sp.Symbol("g", real=True)] == 3.7
    oblique = derive_equations("rp_arm", keep_params=True, gravity=(1.0, 0, -9.0))
    names = {s.name for s in oblique.parameters}
    assert {"g_x", "g_z"} <= names and "g" not in names


@pytest.mark.parametrize("form", [pytest.param("closed", marks=pytest.mark.slow), "compact"])
def test_mimic_joints_follow_the_linear_map(form, rng):
    """The mimic arm: wrist = -1.5 elbow + 0.2, so two coordinates; M, C, G equal Robot's."""
    equations = derive_equations(MIMIC, form=form)
    robot = robodyn.load(MIMIC)
    assert equations.joint_names == robot.joint_names == ["shoulder", "elbow"]
    module = module_of(equations)
    q = robot.random_configuration(rng, 20)
    v, a = rng.normal(size=(2, 20, robot.nv))
    assert relative(module["mass_matrix"](q), robot.mass_matrix(q)) < 1e-9
    assert relative(module["coriolis_matrix"](q, v), robot.coriolis_matrix(q, v)) < 1e-9
    assert relative(module["gravity"](q), robot.gravity(q)) < 1e-9
    assert relative(module["inverse_dynamics"](q, v, a), robot.inverse_dynamics(q, v, a)) < 1e-9
    # Negative control: the same arm with the wrist free is a different robot.
    free = robodyn.load(Path(MIMIC).read_text().replace('<mimic joint="elbow" multiplier="-1.5" offset="0.2"/>', ""))
    q3 = np.column_stack([q, -1.5 * q[:, 1] + 0.2])
    assert relative(module["gravity"](q), free.gravity(q3)[:, :2]) > 1e-6


@pytest.mark.slow
def test_panda_with_its_mimic_finger_matches_robot(rng, capsys):
    assert main(["equations", "panda", "--symbolic", "--format", "json"]) == 0
    assert json.loads(capsys.readouterr().out)["form"] == "compact"
    equations = derive_equations("panda")
    module = module_of(equations)
    robot = robodyn.load("panda")
    q = robot.random_configuration(rng, 10)
    v, a = rng.normal(size=(2, 10, robot.nv))
    assert relative(module["inverse_dynamics"](q, v, a), robot.inverse_dynamics(q, v, a)) < 1e-9


def test_an_expensive_closed_form_is_refused_at_once(capsys):
    with pytest.raises(DerivationTooExpensiveError, match="form='compact'"):
        derive_equations("ur5", form="closed")
    assert main(["equations", "ur5", "--symbolic", "--form", "closed"]) == 2
    err = capsys.readouterr().err
    assert "--form compact" in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("option", [["--q", "0.1,0.2"], ["--v=0,1"], ["--a", "1,2"]])
def test_a_state_with_symbolic_is_an_error_not_ignored(option, capsys):
    assert main(["equations", "rp_arm", "--symbolic", *option]) == 2
    err = capsys.readouterr().err
    assert "--symbolic" in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("precision", ["0", "-5", "18"])
@pytest.mark.parametrize("symbolic", [True, False])
def test_precision_out_of_range_is_one_line(precision, symbolic, capsys):
    assert main(["equations", "rp_arm", f"--precision={precision}", *(["--symbolic"] if symbolic else [])]) == 2
    err = capsys.readouterr().err
    assert "1 to 17" in err and len(err.strip().splitlines()) == 1


def test_cli_gravity_reaches_the_symbolic_equations(capsys):
    assert main(["equations", "rp_arm", "--symbolic", "--gravity=9.81,0,0", "--format", "json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["gravity"] == [9.81, 0.0, 0.0]
    symbols = {name: sp.Symbol(name, real=True) for name in data["q"]}
    G = [sp.sympify(e, locals=symbols) for e in data["G"]]
    q = np.array([0.4, 0.1])
    values = np.array([float(g.subs(dict(zip(symbols.values(), q, strict=True)))) for g in G])
    assert relative(values, robodyn.load("rp_arm", gravity=SIDEWAYS).gravity(q)) < 1e-9
