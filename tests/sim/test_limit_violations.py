"""``limit_violations`` where each limit binds and just misses, on both sides, signed, on a
floating base, without torques; a stop given on one side only; the mode's refusal."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn.exceptions import InputError
from robodyn.sim.limits import TOLERANCE, check_mode, limit_violations
from robodyn.trajectory import Trajectory


def arm(*, floating: bool = False, lower: float = -1.0) -> robodyn.Robot:
    """A slider (limits ``lower``..0.5 m, 2 m/s, 30 N) then a hinge (±10 rad, 3 rad/s, 7 N m)."""
    box = '<inertial><mass value="1.5"/><inertia ixx="0.02" iyy="0.03" izz="0.025" ixy="0" ixz="0" iyz="0"/></inertial>'
    return robodyn.load(
        f"""<robot name="arm"><link name="base">{box}</link><link name="carriage">{box}</link><link name="tip">{box}</link>
        <joint name="slide" type="prismatic"><parent link="base"/><child link="carriage"/><axis xyz="1 0 0"/>
        <limit lower="{lower}" upper="0.5" velocity="2" effort="30"/></joint>
        <joint name="hinge" type="revolute"><parent link="carriage"/><child link="tip"/><origin xyz="0 0 0.2"/>
        <axis xyz="0 1 0"/><limit lower="-10" upper="10" velocity="3" effort="7"/></joint></robot>""",
        floating_base=floating,
    )


def motion(robot: robodyn.Robot, slide: np.ndarray, hinge_speed: np.ndarray, tau: np.ndarray | None) -> Trajectory:
    count = len(slide)
    q = np.zeros((count, robot.nq))
    v = np.zeros((count, robot.nv))
    if robot.floating_base:
        q[:, 6] = 1.0
    q[:, -2] = slide
    v[:, -1] = hinge_speed
    torques = None
    if tau is not None:
        torques = np.zeros((count, robot.nv))
        torques[:, -2:] = tau
    return Trajectory(np.arange(count) * 0.1, q, v, np.zeros_like(v), torques, list(robot.joint_names), robot.name)


@pytest.mark.parametrize("floating", [False, True], ids=["fixed", "floating"])
def test_each_limit_broken_is_reported_signed_with_its_worst_value_and_first_time(floating):
    robot = arm(floating=floating)
    slide = np.array([0.0, -1.2, -1.5, -1.1, 0.0])  # below the lower limit from t = 0.1, worst -1.5
    speed = np.array([0.0, 1.0, 2.5, -3.6, -3.2])  # beyond 3 rad/s from t = 0.3, worst -3.6
    tau = np.array([[0.0, 0.0], [0.0, 2.0], [40.0, -9.0], [0.0, 0.0], [-45.0, 0.0]])
    found = {(v.joint, v.quantity, v.side): v for v in limit_violations(robot, motion(robot, slide, speed, tau))}
    assert set(found) == {("slide", "position", "lower"), ("hinge", "velocity", "magnitude"),
                          ("slide", "effort", "magnitude"), ("hinge", "effort", "magnitude")}  # fmt: skip
    position = found["slide", "position", "lower"]
    assert (position.worst, position.limit, position.first_time, position.unit) == (-1.5, -1.0, 0.1, "m")
    velocity = found["hinge", "velocity", "magnitude"]
    assert (velocity.worst, velocity.limit, velocity.first_time, velocity.unit) == (-3.6, -3.0, 0.30000000000000004, "rad/s")
    assert (found["slide", "effort", "magnitude"].worst, found["slide", "effort", "magnitude"].limit) == (-45.0, -30.0)
    assert (found["hinge", "effort", "magnitude"].worst, found["hinge", "effort", "magnitude"].limit) == (-9.0, -7.0)
    assert found["slide", "effort", "magnitude"].unit == "N" and found["hinge", "effort", "magnitude"].unit == "N m"


def test_without_torques_only_positions_and_velocities_are_checked():
    robot = arm(floating=True)
    found = limit_violations(robot, motion(robot, np.array([0.0, 0.7]), np.array([0.0, 3.5]), None))
    assert [(v.joint, v.quantity, v.side, v.worst) for v in found] == [
        ("slide", "position", "upper", 0.7),
        ("hinge", "velocity", "magnitude", 3.5),
    ]


def test_a_value_within_the_tolerance_is_no_violation_and_just_past_it_is():
    robot = arm()
    slack = TOLERANCE * (1.0 + 0.5)
    for excess, reported in ((0.6 * slack, False), (1.4 * slack, True)):
        found = limit_violations(robot, motion(robot, np.array([0.0, 0.5 + excess]), np.zeros(2), None))
        assert bool(found) == reported, excess


def test_a_stop_on_one_side_only_is_enforced():
    """A slider alone, its lower limit a placeholder (−2000 m: unspecified), its upper one
    real: the stop holds."""
    box = '<inertial><mass value="1.5"/><inertia ixx="0.02" iyy="0.03" izz="0.025" ixy="0" ixz="0" iyz="0"/></inertial>'
    robot = robodyn.load(
        f"""<robot name="slider"><link name="base"/><link name="carriage">{box}</link>
        <joint name="slide" type="prismatic"><parent link="base"/><child link="carriage"/><axis xyz="1 0 0"/>
        <limit lower="-2000" upper="0.5" velocity="0" effort="0"/></joint></robot>"""
    )
    run = robodyn.simulate(
        robot, np.zeros(1), np.zeros(1), 1.0, 1e-3, controller=lambda t, q, v: np.array([10.0]), limits="enforce"
    )
    assert run.q[:, 0].max() == 0.5 and run.q[-1, 0] == 0.5


def test_a_position_limit_keeps_its_own_sign_whatever_the_worst_value():
    robot = arm(lower=0.2)  # a lower limit above zero, broken by a negative position
    (found,) = limit_violations(robot, motion(robot, np.array([0.3, -0.3]), np.zeros(2), None))
    assert (found.side, found.worst, found.limit) == ("lower", -0.3, 0.2)


def test_an_unknown_limits_mode_is_refused_naming_the_parameter_and_the_value():
    assert check_mode("enforce") == "enforce"
    with pytest.raises(InputError) as error:
        check_mode("clamp")
    assert error.value.argument == "limits"
    assert "one of warn, enforce, ignore" in str(error.value) and "'clamp'" in str(error.value)
