"""Issue 13, items 5 and 6: numbers on the command line as people write them, checked.

Reproductions: ``--q -0.5,0.1`` was "expected one argument"; ``--dt 5 --duration 1`` ran
0 steps; ``check --samples 0`` passed; ``whatif --payloads=-5`` printed a 0 kg row;
``--seed -1``, ``--fps 1e9``, ``--duration 1e9``, ``--dt 1e-300`` gave tracebacks;
``--debug`` after the command was refused.
"""

from __future__ import annotations

import io
import json

import numpy as np
import pytest

import robodyn
import robodyn.cli.common as cli_common
from robodyn.cli.app import main
from robodyn.common import text as common


def run(capsys, *argv):
    status = main(list(argv))
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def strict_json(text: str):
    def refuse(constant):
        raise ValueError(f"not JSON: {constant}")

    return json.loads(text, parse_constant=refuse)


@pytest.mark.parametrize(
    ("argv", "attached"),
    [
        (["equations", "rp_arm", "--q", "-0.5,0.1", "--json"], ["equations", "rp_arm", "--q=-0.5,0.1", "--json"]),
        (["equations", "rp_arm", "--gravity", "-9.81,0,0", "--json"], ["equations", "rp_arm", "--gravity=-9.81,0,0", "--json"]),
        (
            ["equations", "rp_arm", "--v", "-1,0", "--a", "-2,1", "--json"],
            ["equations", "rp_arm", "--v=-1,0", "--a=-2,1", "--json"],
        ),
        (["equations", "rp_arm", "--a", "-.5,-1e-3", "--json"], ["equations", "rp_arm", "--a=-.5,-1e-3", "--json"]),
    ],
)
def test_negative_numbers_follow_their_option(capsys, argv, attached):
    status, out, err = run(capsys, *argv)
    assert status == 0, err
    assert run(capsys, *attached)[1] == out


def test_negative_values_reach_the_library(capsys):
    status, out, _ = run(capsys, "equations", "rp_arm", "--q", "-0.5,0.1", "--gravity", "-9.81,0,0", "--json")
    assert status == 0
    result = strict_json(out)
    robot = robodyn.load("rp_arm", gravity=[-9.81, 0, 0])
    np.testing.assert_allclose(result["G"], robot.gravity(np.array([-0.5, 0.1])), rtol=1e-12)
    status, out, _ = run(capsys, "simulate", "rp_arm", "--controller", "task-space", "--target", "-0.5,0.3", "--json")
    assert status == 0 and strict_json(out)["target_m"] == [-0.5, 0.0, 0.3]
    status, out, _ = run(capsys, "whatif", "--force", "0,0,-10", "--payloads", "0", "--json")
    assert status == 0 and strict_json(out)["rows"][1]["force_N"] == [0.0, 0.0, -10.0]


@pytest.mark.parametrize(
    ("argv", "fragment"),
    [
        (["simulate", "rp_arm", "--dt", "0.5", "--duration", "0.2"], "--dt must be at most --duration"),
        (["simulate", "rp_arm", "--dt", "5", "--duration", "1"], "--dt must be a number in [1e-06, 1] s"),
        (["simulate", "rp_arm", "--dt", "1e-300"], "--dt must be"),
        (["simulate", "rp_arm", "--duration", "1e9"], "--duration must be a number in (0, 3600] s"),
        (["simulate", "rp_arm", "--duration", "0"], "--duration must be"),
        (["simulate", "rp_arm", "--duration", "nan"], "--duration must be"),
        (["simulate", "rp_arm", "--dt", "0.003", "--duration", "1"], "whole number of steps"),
        (["check", "rp_arm", "--samples", "0"], "--samples must be an integer in [1, 100000]"),
        (["check", "rp_arm", "--seed", "-1"], "--seed must be an integer"),
        (["check", "rp_arm", "--tolerance", "0"], "--tolerance must be"),
        (["whatif", "--payloads=-5"], "--payloads must be values each a number in [0, 10000] kg"),
        (["whatif", "--payloads", "-5"], "--payloads must be"),
        (["whatif", "--duration=-1"], "--duration must be"),
        (["whatif", "--force", "1,2"], "--force must be 3 values"),
        (["record", "rp_arm", "--trajectory", "x.csv", "--out", "x.html", "--fps", "1e9"], "--fps must be a number in (0, 240]"),
        (["equations", "rp_arm", "--precision", "-5"], "1 to 17"),
        (["simulate", "ur5", "--controller", "task-space", "--target", "0.3,0.2,0.4", "--frame", "world"], "no joint moves it"),
        (["simulate", "solo12", "--controller", "task-space", "--target", "0.3,0.2,0.4"], "FL_FOOT"),
        (["whatif", "ur5", "--frame", "base_link"], "no joint moves it"),
    ],
)
def test_out_of_range_options_are_one_line_errors(capsys, argv, fragment):
    status, out, err = run(capsys, *argv)
    assert status == 2
    assert out == ""
    assert err.count("\n") == 1 and fragment in err, err
    assert "Traceback" not in err


def test_debug_before_or_after_the_command(capsys):
    for argv in (["--debug", "info", "no_such_robot"], ["info", "no_such_robot", "--debug"]):
        status, _, err = run(capsys, *argv)
        assert status == 2 and "Traceback" in err
    status, _, err = run(capsys, "info", "no_such_robot")
    assert status == 2 and "Traceback" not in err


def test_json_is_always_strict(capsys):
    for argv in (["info", "solo12", "--json"], ["info", "kinova", "--json"], ["list", "--json"], ["whatif", "--json"]):
        status, out, _ = run(capsys, *argv)
        assert status == 0
        strict_json(out)
    status, out, _ = run(capsys, "simulate", "rp_arm", "--duration", "0.5", "--json")
    summary = strict_json(out)
    assert summary["duration_s"] == 0.5 and summary["steps"] == 500
    assert common.json_text({"a": float("inf"), "b": [float("nan"), 1.0]}) == common.json_text({"a": None, "b": [None, 1.0]})


def test_simulate_summary_has_units_and_sensible_precision(capsys):
    status, out, _ = run(capsys, "simulate", "rp_arm", "--controller", "task-space", "--target", "0.7,0.7", "--duration", "2")
    assert status == 0
    assert "final error:" in out and " m (reached)" in out
    assert "peak |torque|: joint1" in out and "N m" in out and "joint2" in out
    assert "energy change:" in out and " J" in out
    assert "0.700000000" not in out  # six significant digits, not seventeen


HOSTILE = """<robot name="evil&#10;robot&#x202E;">
  <link name="base"/>
  <joint name="j&#10;1&#x202E;" type="revolute"><parent link="base"/><child link="l&#10;1"/><axis xyz="0 0 1"/>
    <origin rpy="1.2 0 0"/><limit lower="-0.5" upper="0.5" effort="1" velocity="1"/></joint>
  <link name="l&#10;1"><inertial><origin xyz="0.3 0 0"/><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
</robot>"""


def test_names_from_the_urdf_reach_the_terminal_escaped(capsys, tmp_path):
    path = tmp_path / "evil.urdf"
    path.write_text(HOSTILE)
    for argv in (["info", str(path)], ["simulate", str(path), "--duration", "0.5"], ["whatif", str(path), "--payloads", "0,1"]):
        status, out, err = run(capsys, *argv)
        assert status == 0
        assert "\u202e" not in out + err and "\\u202e" in out  # escaped, not raw
        assert all(not line.startswith("1") for line in out.splitlines())  # no name broken over two lines
    assert err.count("\n") <= 1


# --------------------------------------------------------------------------------------
# Issue 29: Terminal hygiene of the command line: progress only on a terminal, an error alon
# --------------------------------------------------------------------------------------
class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


@pytest.fixture
def no_delay(monkeypatch):
    monkeypatch.setattr(cli_common.Progress, "DELAY", 0.0)


def test_progress_draws_only_on_a_terminal(no_delay, monkeypatch):
    for stream, shown in ((_Terminal(), True), (io.StringIO(), False)):
        monkeypatch.setattr("sys.stderr", stream)
        progress = cli_common.Progress("deriving")
        progress("mass matrix", 3, 10)
        progress("mass matrix", 10, 10)
        progress.close()
        written = stream.getvalue()
        if shown:
            assert written.count("\r") == 2 and written.endswith("10/10\n")
        else:
            assert written == ""


def test_a_failed_write_prints_its_error_alone_on_a_captured_stderr(no_delay, capsys):
    # stderr captured (not a terminal), output to a full disk: one line, no carriage returns
    assert main(["equations", "rp_arm", "--symbolic", "--format", "python", "--out", "/dev/full"]) == 2
    err = capsys.readouterr().err
    assert "\r" not in err and err.count("\n") == 1 and err.startswith("robodyn: error:")
