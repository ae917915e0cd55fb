"""robodyn.optimize.point_to_point where each limit binds: the optimum sits on it, exactly.

A rotor (one revolute joint about the vertical, no gravity torque: a double integrator of
inertia ``I``) has closed-form optima: minimum effort over ``T`` for a distance ``D`` peaks
at ``v = 1.5 D / T``; minimum time under an effort limit ``E`` is bang-bang,
``T = 2 √(I D / E)``, and with a velocity limit ``V`` too, trapezoidal,
``T = D / V + V I / E``. A pendulum (gravity) swung from −0.5 to 0.3 rad over 2 s
overshoots the goal when nothing stops it: its position limit binds. Each binding case
sits beside the same problem with the limit removed (slack), whose answer differs.
"""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn.optimize import point_to_point

INERTIA, DISTANCE = 0.5, 1.0
#: IPOPT's tolerance on a bound (bound_relax_factor 0: a bound is never crossed by more than round-off).
ON_BOUND = 1e-6


def rotor(*, velocity: float = 0.0, effort: float = 0.0) -> robodyn.Robot:
    """One revolute joint about z (gravity along −z: no gravity torque), inertia 0.5 kg m²;
    0 is the URDF's "unspecified" (the limit does not count)."""
    text = f"""<robot name="rotor"><link name="base"/><link name="disc"><inertial><mass value="1"/>
    <inertia ixx="0.3" iyy="0.3" izz="{INERTIA}" ixy="0" ixz="0" iyz="0"/></inertial></link>
    <joint name="spin" type="revolute"><parent link="base"/><child link="disc"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" velocity="{velocity}" effort="{effort}"/></joint></robot>"""
    return robodyn.load(text)


def pendulum(*, upper: float = 3.0) -> robodyn.Robot:
    """A 1 kg bob 0.5 m below a revolute joint about y; no velocity or effort limit."""
    text = f"""<robot name="pendulum"><link name="base"/><link name="bob"><inertial>
    <origin xyz="0 0 -0.5"/><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/>
    </inertial></link><joint name="swing" type="revolute"><parent link="base"/><child link="bob"/>
    <axis xyz="0 1 0"/><limit lower="-3" upper="{upper}" velocity="0" effort="0"/></joint></robot>"""
    return robodyn.load(text)


def peak(values: np.ndarray) -> float:
    return float(np.max(np.abs(values)))


def test_minimum_effort_is_the_closed_form_where_no_limit_binds():
    motion = point_to_point(rotor(velocity=5.0, effort=5.0), [0.0], [DISTANCE], 2.0, intervals=20)
    # Slack: the closed form's 1.5 D / T = 0.75 rad/s (the grid's torque is piecewise constant:
    # its peak is below the continuous 6 I D / T² = 0.75 N m, its speed the same).
    assert abs(peak(motion.trajectory.v) - 1.5 * DISTANCE / 2.0) < 5e-3
    assert peak(motion.trajectory.tau) < 0.75


def test_a_binding_velocity_limit_is_reached_and_never_crossed():
    slack = point_to_point(rotor(velocity=5.0, effort=5.0), [0.0], [DISTANCE], 2.0, intervals=20)
    bound = point_to_point(rotor(velocity=0.6, effort=5.0), [0.0], [DISTANCE], 2.0, intervals=20)
    v = bound.trajectory.v
    assert peak(v) <= 0.6 + 1e-9 and peak(v) > 0.6 - ON_BOUND  # on the limit, not past it
    assert peak(slack.trajectory.v) > 0.7  # without the limit the answer is another one
    assert bound.cost > slack.cost * 1.05
    assert np.max(np.abs(bound.trajectory.q[-1] - DISTANCE)) < 1e-9


def test_a_binding_effort_limit_is_reached_and_never_crossed():
    # 4 I D / T² = 0.5 N m is the least peak torque that makes it (bang-bang); 0.6 binds.
    slack = point_to_point(rotor(velocity=5.0, effort=5.0), [0.0], [DISTANCE], 2.0, intervals=20)
    bound = point_to_point(rotor(velocity=5.0, effort=0.6), [0.0], [DISTANCE], 2.0, intervals=20)
    tau = bound.trajectory.tau
    assert peak(tau) <= 0.6 + 1e-9 and peak(tau) > 0.6 - ON_BOUND
    assert peak(slack.trajectory.tau) > 0.7
    # The torque sits on the limit over whole intervals (a plateau), not at one sample.
    assert np.sum(np.abs(tau[:, 0]) > 0.6 - ON_BOUND) >= 4


def test_a_binding_position_limit_is_reached_and_never_crossed():
    slack = point_to_point(pendulum(), [-0.5], [0.3], 2.0, intervals=30)
    assert slack.trajectory.q.max() > 0.38  # the free optimum swings past the goal
    bound = point_to_point(pendulum(upper=0.35), [-0.5], [0.3], 2.0, intervals=30)
    q = bound.trajectory.q
    assert q.max() <= 0.35 + 1e-9 and q.max() > 0.35 - ON_BOUND
    assert bound.cost > slack.cost


@pytest.mark.parametrize(
    ("velocity", "expected"),
    [
        (0.0, 2.0 * np.sqrt(INERTIA * DISTANCE / 1.0)),  # bang-bang: only the effort limit binds
        (0.6, DISTANCE / 0.6 + 0.6 * INERTIA / 1.0),  # trapezoid: both bind
    ],
    ids=["effort-binds", "effort-and-velocity-bind"],
)
def test_minimum_time_is_the_closed_form_on_the_limits(velocity, expected):
    motion = point_to_point(rotor(velocity=velocity, effort=1.0), [0.0], [DISTANCE], 4.0, intervals=20, cost="time")
    # Never faster than physics allows; the grid (switch times between samples) and the
    # 1e-3 effort regularisation cost at most 1 %.
    assert expected - 1e-6 <= motion.duration <= expected * 1.01
    assert 1.0 - ON_BOUND < peak(motion.trajectory.tau) <= 1.0 + 1e-9
    if velocity:
        assert 0.6 - ON_BOUND < peak(motion.trajectory.v) <= 0.6 + 1e-9
    else:
        assert peak(motion.trajectory.v) > 1.3  # √(E D / I) = 1.41 rad/s at the switch


def test_minimum_time_with_slack_limits_takes_the_duration_bound_off():
    # A generous effort limit: the optimum is far shorter than the 4 s allowed.
    motion = point_to_point(rotor(effort=100.0), [0.0], [DISTANCE], 4.0, intervals=20, cost="time")
    assert motion.duration < 0.2
