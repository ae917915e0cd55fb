"""Stills of a real browser: an upright arm's first frame is not cropped (issue 29, item 5)."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn.trajectory import Trajectory
from robodyn.viz.recording import recording
from robodyn.viz.stills import capture, chromium


@pytest.mark.slow
def test_the_first_frame_of_an_upright_arm_shows_its_top():
    if chromium() is None:
        pytest.skip("no Chromium here (make chromium installs it)")
    robot = robodyn.load("ur5")
    upright = np.array([0.0, -np.pi / 2, 0.0, -np.pi / 2, 0.0, 0.0])
    t = np.linspace(0.0, 1.0, 11)
    q = upright + np.outer(t, [0.8, 0.3, 0.0, 0.0, 0.0, 0.0])
    zeros = np.zeros_like(q)
    made = recording(robot, Trajectory(t, q, zeros, zeros, zeros, robot.joint_names, robot.name))
    (frame,) = capture(made.html, [0.0], size=(480, 360), hide=("Axes", "task", "Grid", "Background"))
    mask = frame[..., 3] > 0
    assert mask.sum() > 1000  # the robot is drawn
    border = np.concatenate([mask[:3].ravel(), mask[-3:].ravel(), mask[:, :3].ravel(), mask[:, -3:].ravel()])
    assert not border.any(), "robot pixels touch the picture's edge"
