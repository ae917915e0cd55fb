"""TorquesRun: the result of ``robodyn torques`` with its units, JSON and text (issue 23)."""

from __future__ import annotations

import csv
import json
import warnings

import numpy as np
import pytest

import robodyn
from robodyn.cli import main
from robodyn.exceptions import InputError
from robodyn.scale.torques import TorquesRun, torques_file
from robodyn.sim.simulation import simulate
from robodyn.trajectory import Trajectory
from tests.sim.robots import SLIDER_URDF


@pytest.fixture
def slider_run(tmp_path):
    """A floating-base robot with a revolute and a prismatic joint, and a motion of it."""
    robot = robodyn.load(SLIDER_URDF, floating_base=True)
    q0 = robot.default_configuration()
    v0 = np.linspace(-0.5, 0.5, robot.nv)
    path = tmp_path / "motion.csv"
    simulate(robot, q0, v0, 0.05, 1e-3).save(path)
    return robot, path


def test_the_csv_header_and_the_text_carry_the_dofs_names_and_units(slider_run, tmp_path, capsys):
    robot, path = slider_run
    out = tmp_path / "tau.csv"
    assert main(["torques", SLIDER_URDF, "--floating-base", str(path), "--out", str(out)]) == 0
    text = capsys.readouterr().out
    with out.open() as handle:
        header = next(row for row in csv.reader(handle) if row and not row[0].startswith("#"))
    names = ["base.x", "base.y", "base.z", "base.rx", "base.ry", "base.rz", "shoulder", "slide"]
    assert [column for column in header if column.startswith("tau[")] == [f"tau[{name}]" for name in names]
    assert [column for column in header if column.startswith("q[")][3:7] == [
        "q[base.qx]",
        "q[base.qy]",
        "q[base.qz]",
        "q[base.qw]",
    ]
    lines = {line.split(":")[0].strip(): line for line in text.splitlines() if line.startswith("  ")}
    assert set(lines) == set(names)
    for dof in robot.dofs:
        assert lines[dof.name].endswith(f" {dof.effort_unit}") and f" {dof.effort_unit}, " in lines[dof.name]
    assert lines["base.x"].endswith(" N") and lines["base.rx"].endswith(" N m")
    assert lines["slide"].endswith(" N") and lines["shoulder"].endswith(" N m")


def test_to_dict_is_the_json_the_cli_prints(slider_run, capsys):
    robot, path = slider_run
    assert main(["torques", SLIDER_URDF, "--floating-base", str(path), "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    run = torques_file(robot, path)
    assert isinstance(run, TorquesRun)
    assert printed == run.to_dict()
    assert list(printed["peak_abs_torque"]) == [dof.name for dof in robot.dofs]
    assert run.units == tuple(dof.effort_unit for dof in robot.dofs)


def test_an_overflow_is_refused_by_the_library_naming_trajectory_and_leaves_no_file(tmp_path):
    robot = robodyn.load("rp_arm")
    count = 5
    t = np.arange(count) * 0.01
    q = np.zeros((count, 2))
    v = np.full((count, 2), 1e80)  # C(q, v) v ≈ 1e160: finite; its square is not
    source, out = tmp_path / "fast.npz", tmp_path / "out.csv"
    Trajectory(t, q, v, np.zeros_like(v), None, list(robot.joint_names), robot.name).save(source)
    with warnings.catch_warnings(), pytest.raises(InputError) as raised:
        warnings.simplefilter("error")  # refused, not warned about
        torques_file(robot, source, out)
    assert raised.value.argument == "trajectory" and "finite" in str(raised.value)
    assert not out.exists() and not list(tmp_path.glob("*.part"))
