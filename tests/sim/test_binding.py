"""Simulation's limits, friction and thresholds where they bind, beside where they are slack.

A rotor (one revolute joint about the vertical: no gravity torque, inertia I = 0.5 kg m²)
under a constant or ramped torque has closed-form motions, which RK4 integrates exactly
(polynomials of degree ≤ 4 in t):

- ``limits="enforce"``: a command of 3 E against the effort limit E moves it as E would
  (``q = E t² / 2I``), a command of E / 2 as itself; a stop at 0.5 rad holds it there with
  no velocity into it, and lets it leave;
- stiction: a torque ramp ``τ = k t`` against Coulomb friction f leaves the joint exactly
  at rest until ``k t = f``, then ``q = k (t − t₀)³ / 6I``;
- the momentum observer's threshold: an external step torque of 2 N m is detected for a
  threshold of 1.9 (at the time the first-order lag crosses it) and not for 2.1.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import robodyn
from robodyn import exceptions
from robodyn.sim.observer import detect_collision, estimate_external_torques
from robodyn.trajectory import Trajectory
from tests.conftest import ROOT

INERTIA = 0.5


def rotor(*, effort: float = 0.0, upper: float = 10.0, friction: float = 0.0, lower: float = -10.0) -> robodyn.Robot:
    dynamics = f'<dynamics friction="{friction}"/>' if friction else ""
    return robodyn.load(
        f"""<robot name="rotor"><link name="base"/><link name="disc"><inertial><mass value="1"/>
        <inertia ixx="0.3" iyy="0.3" izz="{INERTIA}" ixy="0" ixz="0" iyz="0"/></inertial></link>
        <joint name="spin" type="revolute"><parent link="base"/><child link="disc"/><axis xyz="0 0 1"/>
        <limit lower="{lower}" upper="{upper}" velocity="0" effort="{effort}"/>{dynamics}</joint></robot>"""
    )


def constant(torque: float):
    return lambda t, q, v: np.array([torque])


@pytest.mark.parametrize(("command", "applied"), [(3.0, 1.0), (-3.0, -1.0), (0.5, 0.5)], ids=["binds", "binds-below", "slack"])
def test_enforce_saturates_the_torque_at_the_effort_limit_and_only_there(command, applied):
    robot = rotor(effort=1.0)
    run = robodyn.simulate(robot, np.zeros(1), np.zeros(1), 1.0, 1e-2, controller=constant(command), limits="enforce")
    assert np.all(run.tau[:, 0] == applied)
    assert np.abs(run.q[:, 0] - applied * run.t**2 / (2 * INERTIA)).max() < 1e-12
    # "warn" does not saturate: the command acts whole (and the effort limit is reported).
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", exceptions.JointLimitWarning)
        free = robodyn.simulate(robot, np.zeros(1), np.zeros(1), 1.0, 1e-2, controller=constant(command))
    assert np.abs(free.q[-1, 0] - command / (2 * INERTIA)) < 1e-12


def test_enforce_holds_the_joint_on_its_stop_and_lets_it_leave():
    robot = rotor(upper=0.5)

    def push_then_pull(t, q, v):
        return np.array([1.0 if t < 1.5 else -1.0])

    run = robodyn.simulate(robot, np.zeros(1), np.zeros(1), 2.0, 1e-3, controller=push_then_pull, limits="enforce", hold=True)
    q, v, t = run.q[:, 0], run.v[:, 0], run.t
    assert q.max() == 0.5  # on the stop, never past it
    on_stop = (t > 0.75) & (t < 1.5)  # q = t² reaches 0.5 at t = 0.707 s
    assert np.all(q[on_stop] == 0.5) and np.all(v[on_stop] == 0.0)
    leaving = t > 1.6
    assert np.all(q[leaving] < 0.5) and np.all(v[leaving] < 0.0)  # the velocity away from it is kept
    assert np.abs(q[leaving] - (0.5 - (t[leaving] - 1.5) ** 2)).max() < 1e-9
    # Slack: a stop the motion never reaches changes nothing.
    far = robodyn.simulate(
        rotor(upper=5.0), np.zeros(1), np.zeros(1), 2.0, 1e-3, controller=push_then_pull, limits="enforce", hold=True
    )
    assert far.q[:, 0].max() > 0.5 and np.abs(far.q[t < 1.5, 0] - t[t < 1.5] ** 2).max() < 1e-9


@pytest.mark.parametrize("integrator", ["rk4", "semi-implicit-euler"])
def test_a_joint_sticks_until_the_torque_reaches_its_friction_then_breaks_away(integrator):
    ramp, friction = 2.0, 1.0013  # breakaway at t0 = f / k = 0.50065 s, inside a step
    breakaway = friction / ramp
    robot = rotor(friction=friction)
    run = robodyn.simulate(
        robot, np.zeros(1), np.zeros(1), 1.0, 1e-3, controller=lambda t, q, v: np.array([ramp * t]), integrator=integrator
    )
    t, q = run.t, run.q[:, 0]
    before = t < breakaway
    assert np.all(q[before] == 0.0) and np.all(run.v[before, 0] == 0.0)  # exactly stuck: no creep
    after = t > breakaway
    expected = ramp * (t[after] - breakaway) ** 3 / (6 * INERTIA)
    tolerance = 1e-10 if integrator == "rk4" else 2e-3 * expected.max()
    assert np.all(q[after] > 0) and np.abs(q[after] - expected).max() < tolerance
    # Slack: without friction it moves from the first step.
    free = robodyn.simulate(rotor(), np.zeros(1), np.zeros(1), 0.2, 1e-3, controller=lambda t, q, v: np.array([ramp * t]))
    assert free.q[-1, 0] > 0


def pushed_pendulum(push: float = 2.0, at: float = 0.2) -> tuple[robodyn.Robot, Trajectory]:
    """The test double pendulum (no damping) held by its gravity torques, pushed at the
    shoulder by ``push`` N m from ``at`` s: the recorded torques are the commanded ones only."""
    robot = robodyn.load(ROOT / "tests" / "data" / "robots" / "double_pendulum.urdf")
    q0 = np.array([0.3, -0.5])

    def command(t, q, v):
        return robot.gravity(q)

    def plant(t, q, v):
        return command(t, q, v) + np.array([push if t >= at else 0.0, 0.0])

    run = robodyn.simulate(robot, q0, np.zeros(2), 0.6, 1e-3, controller=plant, hold=True, limits="ignore")
    tau = np.array([command(t, q, v) for t, q, v in zip(run.t, run.q, run.v, strict=True)])
    recorded = Trajectory(run.t, run.q, run.v, run.a, tau, joint_names=list(robot.joint_names), robot=robot.name)
    return robot, recorded


def test_the_observer_detects_a_push_just_above_its_threshold_and_not_just_below():
    robot, recorded = pushed_pendulum()
    gain = 50.0
    residual = estimate_external_torques(robot, recorded, gain=gain)
    assert abs(residual[-1, 0] - 2.0) < 1e-3 and abs(residual[-1, 1]) < 1e-3
    hit = detect_collision(robot, recorded.t, residual, 1.9)
    assert hit is not None and hit.index == 0 and hit.dof == robot.dofs[0].name
    crossing = 0.2 + np.log(2.0 / 0.1) / gain  # 2 (1 − e^{−K (t − 0.2)}) = 1.9
    assert abs(hit.time - crossing) < 3e-3
    assert detect_collision(robot, recorded.t, residual, 2.1) is None  # just above the push: nothing
    # Thresholds per joint: the shoulder's slack, the elbow's low: no joint crosses its own.
    assert detect_collision(robot, recorded.t, residual, np.array([2.1, 0.05])) is None


def two_rotors() -> robodyn.Robot:
    """Two rotors on one base, about parallel vertical axes: independent motions (diagonal
    M, no gravity torque); the first has a stop at 0.5 rad, the second stops far away."""
    disc = '<inertial><mass value="1"/><inertia ixx="0.3" iyy="0.3" izz="0.5" ixy="0" ixz="0" iyz="0"/></inertial>'
    return robodyn.load(
        f"""<robot name="two_rotors"><link name="base"/><link name="a">{disc}</link><link name="b">{disc}</link>
        <joint name="first" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/>
        <limit lower="-10" upper="0.5" velocity="0" effort="0"/></joint>
        <joint name="second" type="revolute"><parent link="base"/><child link="b"/><origin xyz="1 0 0"/><axis xyz="0 0 1"/>
        <limit lower="-10" upper="10" velocity="0" effort="0"/></joint></robot>"""
    )


@pytest.mark.parametrize("pull", [-1.0, 1.0], ids=["second-moving-away", "second-moving-along"])
def test_a_stop_holds_its_own_joint_only(pull):
    """The first rotor rests on its stop, pushed into it; the second moves freely either way:
    its velocity is never touched by the other joint's stop."""
    robot = two_rotors()
    run = robodyn.simulate(
        robot, np.zeros(2), np.zeros(2), 1.5, 1e-3, controller=constant_pair(1.0, pull), limits="enforce", hold=True
    )
    assert run.q[:, 0].max() == 0.5 and np.all(run.v[run.t > 0.75, 0] == 0.0)
    np.testing.assert_allclose(run.q[:, 1], pull * run.t**2 / (2 * INERTIA), rtol=0, atol=1e-12)
    np.testing.assert_allclose(run.v[:, 1], pull * run.t / INERTIA, rtol=0, atol=1e-12)


def constant_pair(first: float, second: float):
    return lambda t, q, v: np.array([first, second])


@pytest.mark.parametrize("side", [1.0, -1.0], ids=["upper", "lower"])
def test_a_joint_started_beyond_its_stop_keeps_its_speed_back_into_the_range(side):
    """Put back on the stop after the first step, the velocity away from it is kept."""
    robot = rotor(upper=0.5, lower=-0.5)
    with pytest.warns(exceptions.JointLimitWarning, match="spin position"):  # the start itself is beyond
        run = robodyn.simulate(robot, np.array([0.52 * side]), np.array([-0.4 * side]), 0.5, 1e-3, limits="enforce")
    assert run.q[1, 0] == 0.5 * side and run.v[1, 0] == -0.4 * side  # back on the stop, the speed away kept
    np.testing.assert_allclose(run.q[2:, 0], side * (0.5 - 0.4 * (run.t[2:] - run.t[1])), atol=1e-12)
