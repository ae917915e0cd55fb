"""Issue 42, `robodyn simulate --controller hybrid`: the RP arm's tip presses the wall
``x = 1`` with 10 N while sliding up and down it. Read back from the CSV (the measured force
is the constraint's, the tip's height the robot's forward kinematics of the written ``q``):
the normal force is the command within 1e-6 relative, and the error along the wall obeys
``ë + Kd ė + Kp e = 0`` (its exact solution computed here). What it cannot do is one stderr
line naming the flag, exit 2."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest
from scipy.linalg import expm

import robodyn
from robodyn.cli.app import main

WALL, FORCE, AMPLITUDE, FREQUENCY, MIDDLE, KP, KD = 1.0, 10.0, 0.1, 0.5, 0.03, 100.0, 20.0
COMMAND = [
    "simulate", "rp_arm", "--controller", "hybrid", "--force", str(FORCE), "--surface", f"{WALL},0,0:-1,0,0",
    "--along", f"0,0,{AMPLITUDE}", "--frequency", str(FREQUENCY), "--target", f"{WALL},0,{MIDDLE}",
    "--kp", str(KP), "--kd", str(KD), "--duration", "0.4", "--dt", "0.008",
]  # fmt: skip


@pytest.fixture(scope="module")
def wall(tmp_path_factory) -> dict[str, np.ndarray]:
    """The CSV's columns of the run, by name."""
    out = tmp_path_factory.mktemp("hybrid") / "wall.csv"
    assert main([*COMMAND, "--out", str(out)]) == 0
    with out.open() as file:
        rows = [row for row in csv.reader(file) if row and not row[0].startswith("#")]
    return {name: np.array([float(row[k]) for row in rows[1:]]) for k, name in enumerate(rows[0])}


def law(times: np.ndarray, e0: float, de0: float, kp: float = KP, kd: float = KD) -> np.ndarray:
    """The solution of ``ë + kd ė + kp e = 0`` from ``e₀``, ``ė₀``."""
    system = np.array([[0.0, 1.0], [-kp, -kd]])
    return np.array([(expm(system * t) @ [e0, de0])[0] for t in times])


def tangential_error(columns: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Times and ``e = z_d − z`` of the tip, ``z`` from the written ``q`` by forward kinematics."""
    robot = robodyn.load("rp_arm")
    t = columns["t"]
    q = np.column_stack([columns["q[joint1]"], columns["q[joint2]"]])
    tip = robot.frame_position(q, "end_effector")
    assert np.abs(tip[:, 0] - WALL).max() <= 1e-9  # on the wall
    return t, MIDDLE + AMPLITUDE * np.sin(2 * np.pi * FREQUENCY * t) - tip[:, 2]


def test_the_wall_force_read_from_the_csv_is_the_command_within_1e_6(wall):
    measured = -wall["f[surface].x"]  # the wall's force on the robot along its normal (-1, 0, 0)
    commanded = -wall["f_cmd[surface].x"]
    assert np.abs(commanded - FORCE).max() == 0.0
    assert np.abs(measured - FORCE).max() <= 1e-6 * FORCE
    assert np.abs(wall["f[surface].y"]).max() == 0.0 and np.abs(wall["f[surface].z"]).max() == 0.0  # frictionless
    assert wall["contact[surface]"].min() == 1.0


def test_the_motion_along_the_wall_follows_its_closed_loop_law(wall):
    t, error = tangential_error(wall)
    expected = law(t, MIDDLE, 2 * np.pi * FREQUENCY * AMPLITUDE)  # the tip starts at rest at z = 0
    assert np.abs(error - expected).max() <= 1e-3 * MIDDLE


def test_the_commanded_force_does_no_work_along_the_motion(wall):
    robot = robodyn.load("rp_arm")
    q = np.column_stack([wall["q[joint1]"], wall["q[joint2]"]])
    v = np.column_stack([wall["v[joint1]"], wall["v[joint2]"]])
    velocity = np.einsum("nij,nj->ni", robot.frame_jacobian(q, "end_effector")[:, :3], v)
    commanded = np.column_stack([wall[f"f_cmd[surface].{axis}"] for axis in "xyz"])
    assert np.abs(velocity[:, 2]).max() > 0.1  # it slides
    assert np.abs(np.einsum("ni,ni->n", commanded, velocity)).max() <= 1e-9 * FORCE  # [W]


def test_a_path_out_of_reach_is_one_warning_line(capsys):
    arguments = [*COMMAND[:-4], "--duration", "0.1", "--dt", "0.01", "--limits", "ignore"]
    arguments[arguments.index("--target") + 1] = f"{WALL},0,0.9"
    assert main(arguments) == 0
    warnings = [line for line in capsys.readouterr().err.splitlines() if "warning" in line]
    assert len(warnings) == 1 and "missed its path" in warnings[0]
    assert main([*COMMAND[:-4], "--duration", "1", "--dt", "0.02"]) == 0  # e(1 s) = 3e-5 m
    assert "missed" not in capsys.readouterr().err  # negative control: on its path, no warning


def test_the_law_checker_sees_other_gains(wall):  # negative control
    t, error = tangential_error(wall)
    wrong = law(t, MIDDLE, 2 * np.pi * FREQUENCY * AMPLITUDE, kd=0.8 * KD)
    assert np.abs(error - wrong).max() > 1e-3 * MIDDLE


def test_the_summary_says_commanded_and_measured_force(tmp_path, capsys):
    assert main([*COMMAND[:-4], "--duration", "0.04", "--dt", "0.004"]) == 0
    text = capsys.readouterr().out
    assert "contact force (normal, on the robot): commanded 10 N, measured 10 N at the end" in text
    assert "contact force error: final" in text and "peak" in text
    assert main([*COMMAND[:-4], "--duration", "0.04", "--dt", "0.004", "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["force_commanded_N"] == FORCE and summary["force_peak_error_N"] <= 1e-6 * FORCE
    assert summary["controller"] == "hybrid" and summary["limit_violations"] == []


@pytest.mark.parametrize(
    ("change", "flag"),
    [
        ({"--q0": "0,0.2"}, "--q0"),  # the tip at x = 1.1, off the wall
        ({"--along": "0.1,0,0"}, "--along"),  # into the wall
        ({"--target": "0.9,0,0"}, "--target"),  # off the wall
        ({"--surface": "1,0,0"}, "--surface"),  # no normal
        ({"--surface": "1,0,0:0,0,0"}, "--surface"),
        ({"--surface": "1,0,0:-1,0,x"}, "--surface"),
        ({"--along": "0,0,0.1:0,0"}, "--along"),
        ({"--frequency": "-1"}, "--frequency"),
        ({"--q0": "0"}, "--q0"),
        ({"--posture": "0"}, "--posture"),
        ({"--kp": "1,2"}, "--kp"),
        ({"--q0": None, "--surface": "5,0,0:-1,0,0"}, "--q0"),  # out of reach within the joint limits
        ({"--force": "-1"}, "--force"),
        ({"--force": None}, "--force"),
        ({"--engine": "compiled"}, "--engine"),
        ({"--limits": "enforce"}, "--limits"),
        ({"--ground": "0"}, "--ground"),
        ({"--out": "x.npz"}, "--out"),
        ({"--frame": "nowhere"}, "nowhere"),
    ],
)
def test_a_hybrid_run_it_cannot_do_is_one_line_naming_the_flag(change, flag, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    arguments = list(COMMAND)
    for key, value in change.items():
        if key in arguments:
            index = arguments.index(key)
            del arguments[index : index + 2]
        if value is not None:
            arguments += [key, value]
    assert main(arguments) == 2
    error = capsys.readouterr().err.strip()
    assert error.count("\n") == 0 and flag in error
    assert not (tmp_path / "x.npz").exists()


@pytest.mark.parametrize("arguments", [["rp_arm", "--controller", "pd", "--target", "0,0.1", "--force", "3"], ["solo12"]])
def test_hybrid_options_elsewhere_and_a_floating_robot_are_refused(arguments, capsys):
    if arguments == ["solo12"]:
        arguments = ["solo12", "--controller", "hybrid", "--force", "1", "--surface", "0,0,0:0,0,1"]
    assert main(["simulate", *arguments, "--duration", "0.01"]) == 2
    error = capsys.readouterr().err.strip()
    assert error.count("\n") == 0 and ("--force" in error or "--controller" in error)


PANDA_Q0 = "0,-0.785,0,-2.356,0,1.571,0.785,0.02"


@pytest.mark.slow
def test_the_panda_wipes_a_table_with_five_newtons_along_a_circle(tmp_path):
    """The issue's wiping case through the command line: after 0.5 s the normal force is
    within 1 % of 5 N and the hand within 1 mm of the circle (both read from the CSV)."""
    out = tmp_path / "wipe.csv"
    start = robodyn.load("panda").frame_position(np.array([float(x) for x in PANDA_Q0.split(",")]), "panda_hand_tcp")
    table = f"{start[0]},{start[1]},0.4869"  # the hand 3e-5 m above it: projected onto it
    status = main([
        "simulate", "panda", "--controller", "hybrid", "--frame", "panda_hand_tcp", "--force", "5", "--surface",
        f"{table}:0,0,1", "--q0", PANDA_Q0, "--along", "0.05,0,0:0,0.05,0", "--target", f"{start[0]},{start[1] - 0.05},0.4869",
        "--duration", "1.5", "--dt", "0.002", "--out", str(out),
    ])  # fmt: skip
    assert status == 0
    with out.open() as file:
        rows = [row for row in csv.reader(file) if row and not row[0].startswith("#")]
    columns = {name: np.array([float(row[k]) for row in rows[1:]]) for k, name in enumerate(rows[0])}
    robot = robodyn.load("panda")
    q = np.column_stack([columns[f"q[{name}]"] for name in robot.configuration_names])
    hand = robot.frame_position(q, "panda_hand_tcp")
    late = columns["t"] >= 0.5
    assert np.abs(columns["f[surface].z"][late] - 5.0).max() <= 0.01 * 5.0
    centre = np.array([start[0], start[1] - 0.05])
    assert np.abs(np.linalg.norm(hand[late, :2] - centre, axis=1) - 0.05).max() <= 1e-3
    assert np.abs(hand[:, 2] - 0.4869).max() <= 1e-9  # on the table
