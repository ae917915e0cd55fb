"""SimulationSummary: the frozen result of a simulation run, its JSON and its text (issue 23)."""

from __future__ import annotations

import json

import numpy as np
import pytest

import robodyn
from robodyn.cli import main
from robodyn.cli.flags import command_line_text
from robodyn.common.text import json_text
from robodyn.sim.experiment import run_simulation
from robodyn.sim.limits import LimitViolation
from robodyn.sim.report import SimulationSummary
from tests.sim.robots import SLIDER_URDF

#: Differs from run to run (wall-clock time).
TIMED = {"real_time_factor", "loop_time_s", "compile_time_s", "startup_time_s"}


def _cli_json(capsys, argv: list[str]) -> dict:
    assert main([*argv, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def _without_timing(data: dict) -> dict:
    return {key: value for key, value in data.items() if key not in TIMED}


@pytest.mark.parametrize(
    ("argv", "options"),
    [
        (["--controller", "pd", "--target", "0.3,0.1", "--duration", "0.2"], {"controller": "pd", "target": [0.3, 0.1]}),
        (
            ["--controller", "task-space", "--target", "0.6,0.3", "--duration", "0.2"],
            {"controller": "task-space", "target": [0.6, 0.3]},
        ),
        (["--duration", "0.2", "--limits", "ignore"], {"limits": "ignore"}),
    ],
)
def test_the_summary_to_dict_is_the_json_the_cli_prints(capsys, argv, options):
    printed = _cli_json(capsys, ["simulate", "rp_arm", *argv])
    _, summary = run_simulation(robodyn.load("rp_arm"), duration=0.2, **options)
    assert isinstance(summary, SimulationSummary)
    expected = json.loads(json_text(summary.to_dict()))
    expected["engine_reason"] = command_line_text(expected["engine_reason"])  # the CLI names flags
    assert _without_timing(printed) == _without_timing(expected)
    assert list(printed) == list(summary.to_dict())  # same keys, same order


def test_the_summary_holds_limit_violation_objects_and_prints_each_one():
    robot = robodyn.load("rp_arm")
    _, summary = run_simulation(robot, controller="pd", target=[3.0, 0.9], duration=0.3)
    assert summary.violations and all(isinstance(item, LimitViolation) for item in summary.violations)
    assert summary.to_dict()["limit_violations"] == [item.as_dict() for item in summary.violations]
    text = summary.text()
    for item in summary.violations:
        assert f"limit violation: {item.text()}" in text
    assert summary.warnings() and summary.warnings()[0].startswith("rp_arm: ")


def test_the_summary_is_frozen_and_names_the_files_written_in_order():
    _, summary = run_simulation(robodyn.load("rp_arm"), duration=0.01)
    with pytest.raises(AttributeError):
        summary.steps = 3  # type: ignore[misc]
    named = summary.with_file("trajectory", "m.csv").with_file("plot", "m.png")
    assert summary.files == () and named.files == (("trajectory", "m.csv"), ("plot", "m.png"))
    assert list(named.to_dict())[-2:] == ["trajectory", "plot"]
    assert named.text().endswith("trajectory: m.csv\nplot: m.png")


def test_a_floating_base_with_a_prismatic_joint_gets_the_units_and_names_of_its_dofs(capsys):
    printed = _cli_json(capsys, ["simulate", SLIDER_URDF, "--floating-base", "--duration", "0.01"])
    assert printed["dof_names"] == ["base.x", "base.y", "base.z", "base.rx", "base.ry", "base.rz", "shoulder", "slide"]
    assert printed["torque_units"] == ["N", "N", "N", "N m", "N m", "N m", "N m", "N"]
    assert len(printed["final_q"]) == 9
    robot = robodyn.load(SLIDER_URDF, floating_base=True)
    assert printed["torque_units"] == [dof.effort_unit for dof in robot.dofs]
    assert main(["simulate", SLIDER_URDF, "--floating-base", "--duration", "0.01"]) == 0
    text = capsys.readouterr().out
    assert "peak |torque|: base.x 0 N, " in text and "base.rx 0 N m" in text and "slide 0 N\n" in text
    assert "(base position in m, quaternion x y z w, then joints in rad / m)" in text


def test_the_summary_reads_like_the_dict_for_code_written_against_it():
    _, summary = run_simulation(robodyn.load("rp_arm"), controller="task-space", target=[0.6, 0.3], duration=0.2)
    assert "target_m" in summary and "final_joint_error" not in summary
    np.testing.assert_allclose(summary["target_m"], [0.6, 0.0, 0.3])
    assert summary["frame"] == summary.task.frame
