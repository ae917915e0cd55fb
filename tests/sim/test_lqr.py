"""LQR (robodyn.sim.control.LQR): balances an upright double pendulum (both joints
actuated, tilted gravity) and an acrobot (the elbow alone) within their effort limits,
continuous and discrete designs; the gain of the wrong equilibrium does not balance."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn.sim.control import LQR

EFFORT = 20.0  # [N m], both joints of the double pendulum
ELBOW = 10.0  # [N m], the acrobot's one motor


def two_link_urdf(name: str, masses, lengths, centres, inertias, efforts) -> str:
    """A planar two-link pendulum hanging along −z at q = 0, joints about y (continuous)."""
    links, joints = [], []
    parent = "base"
    for k in range(2):
        link = f"link{k + 1}"
        i = inertias[k]
        links.append(
            f'<link name="{link}"><inertial><origin xyz="0 0 {-centres[k]}"/><mass value="{masses[k]}"/>'
            f'<inertia ixx="{i}" iyy="{i}" izz="{i / 10}" ixy="0" ixz="0" iyz="0"/></inertial></link>'
        )
        origin = 0.0 if k == 0 else -lengths[0]
        joints.append(
            f'<joint name="joint{k + 1}" type="continuous"><parent link="{parent}"/><child link="{link}"/>'
            f'<origin xyz="0 0 {origin}"/><axis xyz="0 1 0"/><limit effort="{efforts[k]}" velocity="30"/></joint>'
        )
        parent = link
    return f'<robot name="{name}"><link name="base"/>{"".join(links)}{"".join(joints)}</robot>'


DOUBLE = two_link_urdf("double", [1.0, 0.8], [0.5, 0.5], [0.25, 0.25], [0.02, 0.017], [EFFORT, EFFORT])
ACROBOT = two_link_urdf("acrobot", [1.0, 1.0], [1.0, 1.0], [0.5, 0.5], [0.083, 0.083], [1.0, ELBOW])
UP = np.array([np.pi, 0.0])
Q_WEIGHT, R_WEIGHT = np.diag([10.0, 10.0, 1.0, 1.0]), 64.0 * np.eye(2) / EFFORT**2


def balance(robot, controller, q0, *, duration=4.0, dt=1e-3, hold=False):
    run = robodyn.simulate(robot, q0, np.zeros(2), duration, dt, controller=controller, limits="ignore", hold=hold)
    return float(np.abs(run.q[-1] - UP).max()), np.abs(run.tau).max(axis=0)


@pytest.fixture(scope="module")
def double():
    return robodyn.load(DOUBLE, gravity=[1.5, 0.0, -9.6])  # tilted: the upright needs torque


def test_lqr_balances_an_upright_double_pendulum_from_a_tilt_within_its_effort_limits(double):
    lqr = LQR(double, UP, np.zeros(2), Q_WEIGHT, R_WEIGHT)
    np.testing.assert_allclose(lqr.actuation @ lqr.u_eq, double.gravity(UP), atol=1e-12)
    assert np.abs(lqr.u_eq).max() > 0.1  # tilted gravity: holding the upright takes torque
    error, peak = balance(double, lqr, UP + np.array([0.15, 0.0]))
    assert error < 1e-5, error
    assert (peak <= EFFORT).all(), peak


def test_the_gain_of_the_wrong_equilibrium_does_not_balance(double):
    right = LQR(double, UP, np.zeros(2), Q_WEIGHT, R_WEIGHT)
    wrong = LQR(double, np.zeros(2), np.zeros(2), Q_WEIGHT, R_WEIGHT)  # designed hanging down

    def law(t, q, v):
        return right.u_eq - wrong.gain @ (np.concatenate([q, v]) - right.x_eq)

    error, _ = balance(double, law, UP + np.array([0.15, 0.0]))
    assert error > 0.5, error


def test_a_discrete_design_balances_at_a_coarse_held_step(double):
    """The discrete Riccati gain of one 20 ms RK4 step, run with the torque held over each
    step: stable where the continuous gain, sampled the same way, is designed on another system."""
    dt = 0.02
    lqr = LQR(double, UP, np.zeros(2), Q_WEIGHT, R_WEIGHT, dt=dt)
    A, B = robodyn.linearize(double, UP, np.zeros(2), dt=dt)
    assert np.abs(np.linalg.eigvals(A - B @ lqr.gain)).max() < 1.0
    error, peak = balance(double, lqr, UP + np.array([0.15, 0.0]), duration=4.0, dt=dt, hold=True)
    assert error < 1e-5 and (peak <= EFFORT).all(), (error, peak)
    continuous = LQR(double, UP, np.zeros(2), Q_WEIGHT, R_WEIGHT)  # negative control: designed on another system
    try:
        error, _ = balance(double, continuous, UP + np.array([0.15, 0.0]), duration=4.0, dt=dt, hold=True)
    except robodyn.SimulationError:
        error = np.inf
    assert error > 0.5, error


def test_lqr_balances_an_acrobot_by_its_elbow_alone():
    robot = robodyn.load(ACROBOT)
    weights = np.diag([100.0, 10.0, 10.0, 1.0]), 1.0
    lqr = LQR(robot, UP, np.zeros(2), *weights, actuated=["joint2"])
    assert lqr.actuation.shape == (2, 1) and lqr.gain.shape == (1, 4)
    tilt = UP + np.array([0.02, 0.0])  # the acrobot's linear basin is small: its elbow swings 0.6 rad to right it
    run = robodyn.simulate(robot, tilt, np.zeros(2), 6.0, 1e-3, controller=lqr, limits="ignore")
    assert np.all(run.tau[:, 0] == 0.0)  # the shoulder is never driven
    assert np.abs(run.q[-1] - UP).max() < 1e-5
    assert np.abs(run.tau[:, 1]).max() <= ELBOW
    wrong = LQR(robot, np.zeros(2), np.zeros(2), *weights, actuated=["joint2"])  # negative control

    def law(t, q, v):
        return lqr.actuation @ (lqr.u_eq - wrong.gain @ (np.concatenate([q, v]) - lqr.x_eq))

    try:
        fallen = robodyn.simulate(robot, tilt, np.zeros(2), 6.0, 1e-3, controller=law, limits="ignore")
        assert np.abs(fallen.q[-1] - UP).max() > 0.5
    except robodyn.SimulationError:
        pass  # it diverged: not balanced either


def test_an_equilibrium_the_actuated_joints_cannot_hold_is_refused():
    robot = robodyn.load(ACROBOT)
    with pytest.raises(robodyn.InputError) as error:
        LQR(robot, UP + np.array([0.3, 0.0]), np.zeros(2), 1.0, 1.0, actuated=["joint2"])
    assert error.value.argument == "q_eq"


@pytest.mark.parametrize(
    ("arguments", "argument"),
    [
        ({"Q": -1.0}, "Q"),
        ({"R": np.zeros((2, 2))}, "R"),
        ({"Q": np.ones(3)}, "Q"),
        ({"Q": "heavy"}, "Q"),
        ({"R": 1.0 + 2.0j}, "R"),
        ({"v_eq": np.ones(2)}, "v_eq"),
        ({"actuated": ["elbow"]}, "actuated"),
    ],
)
def test_bad_weights_and_arguments_are_refused(double, arguments, argument):
    settings = {"q_eq": UP, "v_eq": np.zeros(2), "Q": 1.0, "R": 1.0, **arguments}
    with pytest.raises(robodyn.InputError) as error:
        LQR(double, **settings)
    assert error.value.argument == argument


def test_a_floating_base_is_refused():
    robot = robodyn.load("solo12")
    with pytest.raises(robodyn.InputError, match="floating"):
        LQR(robot, robot.neutral_configuration(), np.zeros(robot.nv), 1.0, 1.0)
