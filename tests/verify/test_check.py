"""CheckReport: the result of ``robodyn check``, its JSON and its text (issue 23)."""

from __future__ import annotations

import json

import robodyn
from robodyn.cli import main
from robodyn.verify.check import check_robot


def test_to_dict_is_the_json_the_cli_prints(capsys):
    assert main(["check", "rp_arm", "--samples", "5", "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    report = check_robot(robodyn.load("rp_arm"), samples=5)
    assert printed == json.loads(json.dumps(report.to_dict()))
    assert printed["passed"] and set(printed["comparisons"]) == {"tau", "M", "Cv", "G", "C", "skew_pinocchio", "skew_reference"}


def test_the_text_is_what_the_cli_prints(capsys):
    assert main(["check", "rp_arm", "--samples", "5"]) == 0
    assert capsys.readouterr().out.rstrip("\n") == check_robot(robodyn.load("rp_arm"), samples=5).text()


def test_a_floating_base_is_compared_on_tau_m_cv_and_g(capsys):
    report = check_robot(robodyn.load("rp_arm", floating_base=True), samples=3)
    assert set(report.comparisons) == {"tau", "M", "Cv", "G"}
    assert report.passed, report.failures


def test_a_robot_whose_joints_differ_from_the_reference_fails_one_joints_comparison(tmp_path):
    robot = robodyn.load("rp_arm")
    renamed = robot.urdf.replace('name="joint2"', 'name="slider2"').replace("joint2", "slider2")
    path = tmp_path / "renamed.urdf"
    path.write_text(renamed)
    report = check_robot(robot, samples=2, reference_source=path)
    assert not report.passed and list(report.comparisons) == ["joints"]
    assert "'joint2' only in the robot" in report.comparisons["joints"].where
