"""Issue 42, `robodyn simulate --controller stand`: solo12 stands on the ground, its base
where it started (its feet put on the ground: computed here from the feet's heights), its
feet carrying m g; what it cannot do is one stderr line naming the flag, exit 2."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

import robodyn
from robodyn.cli.app import main

FEET = ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")


def test_solo12_stands_on_the_ground_for_a_second(tmp_path, capsys):
    out = tmp_path / "stand.csv"
    status = main(["simulate", "solo12", "--ground", "--controller", "stand", "--duration", "1", "--out", str(out), "--json"])
    assert status == 0
    summary = json.loads(capsys.readouterr().out)
    robot = robodyn.load("solo12")
    start = robot.default_configuration()
    start[2] -= min(robot.frame_position(start, foot)[2] for foot in FEET)  # the lowest foot on z = 0
    assert np.abs(np.array(summary["final_q"][:3]) - start[:3]).max() < 1e-4
    with out.open() as file:
        rows = [row for row in csv.reader(file) if row and not row[0].startswith("#")]
    header, last = rows[0], rows[-1]
    normal = sum(float(value) for name, value in zip(header, last, strict=True) if name.startswith("f[") and name.endswith(".z"))
    weight = robot.total_mass * 9.81
    assert abs(normal - weight) <= 1e-6 * weight
    assert summary["com_error_m"] < 1e-6 and summary["support_margin_m"] > 0


@pytest.mark.parametrize(
    ("arguments", "flag"),
    [
        (["solo12", "--ground", "--target", "0,0.5,0"], "--target"),
        (["solo12"], "--ground"),
        (["panda", "--ground"], "--controller"),
        (["solo12", "--ground", "--contact", "FL_FOOT,HR_FOOT"], "--contact"),
        (["solo12", "--ground", "--friction", "0"], "--friction"),
    ],
)
def test_a_stand_it_cannot_do_is_one_line_naming_the_flag(arguments, flag, capsys):
    status = main(["simulate", *arguments, "--controller", "stand", "--duration", "0.01"])
    assert status == 2
    error = capsys.readouterr().err.strip()
    assert error.count("\n") == 0 and flag in error
    if arguments[0] == "panda":
        assert "'panda'" in error


def test_named_feet_stand_and_a_shift_not_reached_is_one_warning_line(capsys):
    feet = "FL_FOOT,FR_FOOT,HL_FOOT,HR_FOOT"
    status = main(
        [
            "simulate",
            "solo12",
            "--ground",
            "--contact",
            feet,
            "--controller",
            "stand",
            "--target",
            "0,0.02,0",
            "--duration",
            "0.05",
        ]
    )
    assert status == 0
    captured = capsys.readouterr()
    assert "support margin" in captured.out and "4 contact points" in captured.out
    warning = captured.err.strip()
    assert warning.count("\n") == 0 and "centre of mass missed its target" in warning
