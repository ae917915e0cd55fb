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


def _column_by_column(robot, trajectory):
    """The report column by column (the algorithm before the whole-array one): an independent
    reading of the same rules (tolerance TOLERANCE * (1 + |limit|), first time, worst sample)."""
    from robodyn.sim.limits import JointLimits

    limits, found = JointLimits(robot), []
    joints = robot.joints[1:] if robot.floating_base else robot.joints
    q_start, v_start = robot.nq - len(joints), robot.nv - len(joints)
    tau = np.zeros_like(trajectory.v) if trajectory.tau is None else trajectory.tau
    for index, dof in enumerate(robot.dofs[v_start:]):
        column = trajectory.q[:, q_start + index]
        for side, limit in (("lower", limits.lower[index]), ("upper", limits.upper[index])):
            outside = (
                column < limit - TOLERANCE * (1 + abs(limit))
                if side == "lower"
                else column > limit + TOLERANCE * (1 + abs(limit))
            )
            if np.isfinite(limit) and outside.any():
                worst = column[np.argmin(column) if side == "lower" else np.argmax(column)]
                found.append((dof.joint, "position", side, trajectory.t[np.argmax(outside)], worst, limit))
        for quantity, signed, limit in (
            ("velocity", trajectory.v[:, v_start + index], limits.velocity[v_start + index]),
            ("effort", tau[:, v_start + index], limits.effort[v_start + index]),
        ):
            outside = np.abs(signed) > limit + TOLERANCE * (1 + limit)
            if np.isfinite(limit) and outside.any():
                worst = signed[np.argmax(np.abs(signed))]
                found.append(
                    (dof.joint, quantity, "magnitude", trajectory.t[np.argmax(outside)], worst, np.copysign(limit, worst))
                )
    return found


@pytest.mark.parametrize("floating", [False, True])
def test_the_whole_array_report_is_the_column_by_column_one(floating):
    """Random motions around every limit (a NaN sample included): the same violations, in
    the same order, as a column-by-column reading; a calm motion reports none (negative control)."""
    robot = arm(floating=floating)
    rng = np.random.default_rng(7)
    for trial in range(6):
        slide = rng.uniform(-1.2, 0.7, size=40)
        speed = rng.uniform(-3.5, 3.5, size=40)
        tau = rng.uniform(-35.0, 35.0, size=(40, 2))
        if trial == 3:
            speed[5] = np.nan
        trajectory = motion(robot, slide, speed, tau)
        ours = [(v.joint, v.quantity, v.side, v.first_time, v.worst, v.limit) for v in limit_violations(robot, trajectory)]
        assert ours
        np.testing.assert_equal(
            ours, [tuple(x.item() if hasattr(x, "item") else x for x in row) for row in _column_by_column(robot, trajectory)]
        )  # NaN == NaN here
    calm = motion(robot, np.full(5, 0.1), np.full(5, 1.0), np.ones((5, 2)))
    assert limit_violations(robot, calm) == [] == _column_by_column(robot, calm)
