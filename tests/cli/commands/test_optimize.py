"""`robodyn optimize`: the motion written as a trajectory file, one summary line with units."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

import robodyn
from robodyn.cli.app import main


def test_optimize_writes_a_motion_that_satisfies_the_dynamics_and_says_its_units(tmp_path, capsys):
    out = tmp_path / "motion.csv"
    status = main(["optimize", "rp_arm", "--start", "0,0", "--goal", "0.8,0.12", "--duration", "1", "--out", str(out)])
    captured = capsys.readouterr()
    assert status == 0
    assert "Solve_Succeeded: effort cost" in captured.out
    assert "joint1" in captured.out and " N m" in captured.out and captured.out.rstrip().endswith(" N")  # joint2 slides
    robot = robodyn.load("rp_arm")
    motion = robodyn.Trajectory.load(out)
    np.testing.assert_allclose(motion.q[0], [0, 0], atol=1e-8)
    np.testing.assert_allclose(motion.q[-1], [0.8, 0.12], atol=1e-6)
    data = robot.model.createData()
    for q, v, a, tau in zip(motion.q, motion.v, motion.a, motion.tau, strict=True):
        np.testing.assert_allclose(pin.rnea(robot.model, data, q, v, a), tau, rtol=1e-9, atol=1e-9)


def test_optimize_refuses_a_duration_that_is_not_positive_in_one_line(tmp_path, capsys):
    out = tmp_path / "motion.csv"
    status = main(["optimize", "rp_arm", "--start", "0,0", "--goal", "0.8,0.12", "--duration", "-1", "--out", str(out)])
    err = capsys.readouterr().err
    assert status == 2 and err.count("\n") == 1 and "--duration" in err
    assert not out.exists()
