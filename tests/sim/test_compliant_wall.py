"""Issue 42, force control against a compliant wall (k = 5000 N/m, d = 20 N s/m): the RP
arm's tip presses the wall ``x = 0.8``. Laws: explicit force control with integral action
reaches the commanded force even with a wrong model of the robot (the proportional law
without the integral does not: the negative control); the sequel's impedance controller in
contact settles where its spring and the wall's carry the same force,
``K (x_target − x) = k (x − c)``: series springs, ``f = K k / (K + k) · (x_target − c)``."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn.exceptions import InputError
from robodyn.sim.compliant_wall import CompliantWall, ExplicitForce, simulate_compliant
from robodyn.sim.operational_space import Impedance

WALL_X, HEIGHT, STIFFNESS, FORCE = 0.8, 0.2, 5000.0, 10.0


def setting():
    robot = robodyn.load("rp_arm")
    q0 = np.array([np.arctan2(HEIGHT, WALL_X), np.hypot(WALL_X, HEIGHT) - 0.9])  # touching, at rest
    wall = CompliantWall(robot, "end_effector", (-1, 0, 0), (WALL_X, 0, 0), stiffness=STIFFNESS, damping=20.0)
    return robot, q0, wall


@pytest.mark.parametrize("integral_gain", [20.0, 0.0])
def test_integral_action_reaches_the_commanded_force_despite_a_wrong_model(integral_gain):
    robot, q0, wall = setting()
    wrong = robodyn.load("rp_arm", gravity=(0.0, 0.0, -9.0))  # the controller's gravity is 8 % off
    control = ExplicitForce(wrong, None, (-1, 0, 0), FORCE, wall.force, (WALL_X, 0, HEIGHT), integral_gain=integral_gain)
    run = simulate_compliant(
        robot, q0, lambda t, q, v, z: control.torques(q, v, z), wall, duration=2.0, dt=1e-3, integral_rate=control.integral_rate
    )
    settled = np.abs(run["force"][-200:] - FORCE).max() / FORCE
    assert run["force"][100:].min() > 0  # the tip never leaves the wall
    if integral_gain:
        assert settled <= 1e-6
    else:
        assert settled > 1e-3  # negative control: the proportional law keeps a steady error


def test_the_impedance_controller_in_contact_settles_where_the_two_springs_balance():
    robot, q0, wall = setting()
    stiffness, target = 500.0, np.array([WALL_X + 0.01, 0.0, HEIGHT])  # the virtual target 1 cm inside
    control = Impedance(robot, None, target, stiffness=[stiffness] * 3, damping=[60.0] * 3)
    run = simulate_compliant(robot, q0, lambda t, q, v, z: control(t, q, v), wall, duration=2.0, dt=1e-3)
    tip = robot.frame_position(run["q"][-1], "end_effector")
    force = run["force"][-1]
    assert force == pytest.approx(stiffness * (target[0] - tip[0]), rel=1e-6)
    series = stiffness * STIFFNESS / (stiffness + STIFFNESS) * (target[0] - WALL_X)
    assert force == pytest.approx(series, rel=1e-6)
    assert force != pytest.approx(stiffness * (target[0] - WALL_X), rel=1e-2)  # not the rigid wall's


def test_a_bad_wall_is_refused():
    robot, _, _ = setting()
    with pytest.raises(InputError, match="stiffness"):
        CompliantWall(robot, "end_effector", (-1, 0, 0), (WALL_X, 0, 0), stiffness=0.0)
    with pytest.raises(InputError, match="normal"):
        CompliantWall(robot, "end_effector", (0, 0, 0), (WALL_X, 0, 0), stiffness=1.0)
