"""The robodyn command, run in-process through main(argv).

Also here:

- Commands that join two parts of robodyn: equations --base-parameters, default states within limits.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import robodyn
from robodyn.cli.app import main


def run(capsys, *argv: str) -> tuple[int, str, str]:
    status = main(list(argv))
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def test_list_names_generated_and_zoo_robots(capsys):
    status, out, _ = run(capsys, "list")
    assert status == 0
    assert {line.split()[0] for line in out.splitlines()[:2]} == {"pendulum", "rp_arm"}
    assert "panda" in out and "floating base" in out


def test_info_shows_joints_limits_and_masses(capsys):
    status, out, _ = run(capsys, "info", "rp_arm")
    assert status == 0
    assert "2 degrees of freedom" in out
    assert "joint2" in out and "prismatic" in out and "0.3 m" in out
    assert "total" in out and "3 kg" in out


def test_equations_json_matches_the_library(capsys):
    status, out, _ = run(capsys, "equations", "rp_arm", "--q", "0.5,0.1", "--v", "1,0.2", "--a", "0.5,-0.3", "--json")
    assert status == 0
    data = json.loads(out)
    robot = robodyn.load("rp_arm")
    assert data["joint_names"] == ["joint1", "joint2"]
    np.testing.assert_allclose(data["tau"], robot.inverse_dynamics([0.5, 0.1], [1, 0.2], [0.5, -0.3]))
    np.testing.assert_allclose(data["M"], robot.mass_matrix([0.5, 0.1]))
    np.testing.assert_allclose(data["G"], robot.gravity([0.5, 0.1]))
    np.testing.assert_allclose(np.array(data["C"]) @ [1, 0.2], robot.nonlinear_effects([0.5, 0.1], [1, 0.2]) - data["G"])


def test_equations_default_to_neutral_and_rest(capsys):
    status, out, _ = run(capsys, "equations", "rp_arm", "--json")
    data = json.loads(out)
    assert status == 0 and data["q"] == [0.0, 0.0] and data["v"] == [0.0, 0.0]


def test_equations_text_has_units(capsys):
    status, out, _ = run(capsys, "equations", "rp_arm", "--q", "0.5,0.1")
    assert status == 0
    assert "0.5 rad" in out and "0.1 m" in out and "N m" in out and "M(q)" in out


@pytest.mark.parametrize(
    ("argv", "fragment"),
    [
        (["info", "no_such_robot"], "unknown robot 'no_such_robot'"),
        (["info", "/no/such/file.urdf"], "no such file"),
        (["equations", "rp_arm", "--q", "1,2,3"], "--q must be 2 values"),
        (["equations", "rp_arm", "--v", "nan,0"], "v must be finite"),
        (["info", "<robot name='x'>"], "not well-formed XML"),
    ],
)
def test_errors_are_one_line_and_status_2(capsys, argv, fragment):
    status, out, err = run(capsys, *argv)
    assert status == 2
    assert out == ""
    assert err.count("\n") == 1 and fragment in err
    assert "Traceback" not in err


def test_usage_error_is_status_2(capsys):
    status, _, err = run(capsys, "equations")
    assert status == 2 and "usage" in err


def test_debug_shows_the_traceback(capsys):
    status, _, err = run(capsys, "--debug", "info", "no_such_robot")
    assert status == 2 and "Traceback" in err


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


def test_a_commands_optional_positional_may_follow_its_options(capsys):
    """``identify MODEL --floating-base DATA``: argparse alone refused DATA after an option
    ("unrecognized arguments"); the file is read (here: named missing) wherever it stands."""
    for argv in (
        ["identify", "rp_arm", "--floating-base", "/no/such.csv"],
        ["identify", "rp_arm", "/no/such.csv", "--floating-base"],
    ):
        assert main(argv) == 2
        error = capsys.readouterr().err
        assert "/no/such.csv" in error and "unrecognized" not in error, error
    assert main(["identify", "rp_arm", "a.csv", "b.csv"]) == 2  # negative control: one DATA only
    assert "unrecognized arguments: b.csv" in capsys.readouterr().err
