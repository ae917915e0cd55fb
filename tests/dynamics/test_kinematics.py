"""robodyn.dynamics.kinematics: functions of the model handle, the Robot's methods delegate to them."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn.dynamics import kinematics
from tests.conftest import random_state


@pytest.mark.parametrize(("name", "floating"), [("ur5", False), ("panda", True)])
def test_kinematics_through_the_handle_functions_equal_the_robot_methods(name, floating, rng):
    robot = robodyn.load(name, floating_base=floating)
    handle, frame = robot.handle, robot.end_effector
    q, v, _ = random_state(robot, rng)
    Q = robot.random_configuration(rng, 4)
    assert kinematics.frame_id(handle, frame) == robot.frame_id(frame)
    np.testing.assert_array_equal(kinematics.frame_position(handle, q, frame), robot.frame_position(q, frame))
    np.testing.assert_array_equal(kinematics.frame_position(handle, Q, frame), robot.frame_position(Q, frame))
    np.testing.assert_array_equal(kinematics.frame_jacobian(handle, q, frame), robot.frame_jacobian(q, frame))
    np.testing.assert_array_equal(
        kinematics.frame_bias_acceleration(handle, q, v, frame), robot.frame_bias_acceleration(q, v, frame)
    )
    wrench = rng.normal(size=6)
    np.testing.assert_array_equal(kinematics.wrench_torques(handle, q, frame, wrench), robot.wrench_torques(q, frame, wrench))
    np.testing.assert_array_equal(kinematics.integrate(handle, q, 0.01 * v), robot.integrate(q, 0.01 * v))


def test_the_fast_path_gives_what_the_checked_path_gives(rng):
    robot = robodyn.load("ur5")
    Q = robot.random_configuration(rng, 3)
    frame = robot.end_effector
    one_by_one = [robot.frame_position(q, frame) for q in Q]
    as_lists = [robot.frame_position(list(q), frame) for q in Q]  # not arrays: the checked path
    np.testing.assert_array_equal(robot.frame_position(Q, frame), one_by_one)
    np.testing.assert_array_equal(as_lists, one_by_one)
    assert robot.frame_jacobian(Q, frame).shape == (3, 6, robot.nv)


@pytest.mark.parametrize("function", ["frame_position", "frame_jacobian"])
def test_the_fast_path_still_refuses_what_the_boundary_refuses(function):
    robot = robodyn.load("ur5")
    frame = robot.end_effector
    with pytest.raises(robodyn.InputError, match="q"):
        getattr(robot, function)(np.full(robot.nq, np.nan), frame)
    with pytest.raises(robodyn.InputError, match="q"):
        getattr(robot, function)(np.zeros(robot.nq + 1), frame)
    with pytest.raises(robodyn.FrameError):
        getattr(robot, function)(np.zeros(robot.nq), "no_such_frame")
    floating = robodyn.load("ur5", floating_base=True)
    q = floating.neutral_configuration()
    q[3:7] = [0.0, 0.0, 0.0, 1.5]  # Pinocchio takes it; robodyn refuses a non-unit quaternion
    with pytest.raises(robodyn.InputError, match="quaternion"):
        getattr(floating, function)(q, frame)


def test_a_robot_of_one_degree_of_freedom_has_a_six_by_one_jacobian_one_state_and_a_batch():
    """Pinocchio hands a 6×1 Jacobian back as a vector of 6: the shape rule holds anyway."""
    robot = robodyn.load("rp_arm", lock={"joint2": 0.1})
    q = robot.random_configuration(np.random.default_rng(3), 3)
    assert robot.nv == 1
    assert robot.frame_jacobian(q[0], "end_effector").shape == (6, 1)
    batch = robot.frame_jacobian(q, "end_effector")
    assert batch.shape == (3, 6, 1)
    np.testing.assert_array_equal(batch[1], robot.frame_jacobian(q[1], "end_effector"))
