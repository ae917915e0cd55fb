"""`robodyn simulate --controller lqr --target Q_EQ [--actuated ...]`: balances, and refuses
what it cannot hold in one line naming the flag."""

from __future__ import annotations

import json

import numpy as np

from robodyn.cli.app import main
from tests.sim.test_lqr import ACROBOT, DOUBLE


def test_lqr_balances_the_double_pendulum_from_the_command_line(tmp_path, capsys):
    path = tmp_path / "double.urdf"
    path.write_text(DOUBLE)
    up = f"{np.pi:.12f},0"
    tilted = f"{np.pi + 0.15:.12f},0"
    arguments = ["simulate", str(path), "--controller", "lqr", "--target", up, "--q0", tilted, "--duration", "4", "--json"]
    assert main([*arguments, "--gravity", "1.5,0,-9.6"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["controller"] == "lqr" and summary["final_joint_error"] < 1e-5
    assert max(summary["peak_abs_torque"]) <= 20.0


def test_an_unheld_target_and_a_misplaced_actuated_flag_are_one_line_errors(tmp_path, capsys):
    path = tmp_path / "acrobot.urdf"
    path.write_text(ACROBOT)
    common = ["simulate", str(path), "--duration", "0.1"]
    for arguments, flag in (
        (["--controller", "lqr", "--actuated", "joint2", "--target", "3.4,0"], "--target"),
        (["--controller", "task-space", "--actuated", "joint2", "--target", "0.1,0.2"], "--actuated"),
        (["--controller", "lqr", "--actuated", "elbow", "--target", "0,0"], "--actuated"),
    ):
        assert main([*common, *arguments]) == 2
        error = capsys.readouterr().err.strip()
        assert error.count("\n") == 0 and flag in error, error


def test_the_default_weights_suit_a_light_zoo_pendulum(capsys):
    """double_pendulum_continuous (0.7 kg, no effort limits, upright at q = 0): gains bounded
    by its inertia, so a millisecond RK4 step stays stable and it balances."""
    arguments = ["simulate", "double_pendulum_continuous", "--controller", "lqr", "--target", "0,0", "--q0", "0.15,0"]
    assert main([*arguments, "--duration", "4", "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["final_joint_error"] < 1e-5
