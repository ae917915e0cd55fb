"""Recordings bound their frames before allocating them (issue 29, item 7)."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn.cli import main
from robodyn.exceptions import InputError
from robodyn.trajectory import Trajectory
from robodyn.viz.recording import MAX_FRAMES, frame_count, recording


def _motion(robot, end: float) -> Trajectory:
    t = np.array([0.0, 0.5, end])
    q = np.array([[0.0, 0.0], [0.3, 0.1], [0.5, 0.2]])
    return Trajectory(t, q, np.zeros_like(q), np.zeros_like(q), np.zeros_like(q), robot.joint_names, robot.name)


def test_the_frame_count_is_the_span_times_fps_and_bounded():
    robot = robodyn.load("rp_arm")
    assert frame_count(_motion(robot, 2.0), 30.0) == 61
    assert frame_count(_motion(robot, (MAX_FRAMES - 1) / 30.0), 30.0) == MAX_FRAMES
    with pytest.raises(InputError, match="trajectory") as raised:
        frame_count(_motion(robot, 1e9), 30.0)
    assert "3e+10 frames" in str(raised.value) and "\n" not in str(raised.value)
    with pytest.raises(InputError, match="trajectory"):
        recording(robot, _motion(robot, MAX_FRAMES / 30.0), fps=30.0)


def test_record_of_a_trajectory_ending_at_1e9_s_is_one_line(tmp_path, capsys):
    robot = robodyn.load("rp_arm")
    _motion(robot, 1e9).save(tmp_path / "long.csv")
    code = main(["record", "rp_arm", "--trajectory", str(tmp_path / "long.csv"), "--out", str(tmp_path / "m.html")])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "frames" in err
    assert not (tmp_path / "m.html").exists()
