"""Issue 13, item 8 (reference and sampling): floating robots in the reference's forward
dynamics and kinetic energy; placeholder limits sampled in a physical range.

Reproductions: ``reference.forward_dynamics`` / ``kinetic_energy`` sized ``q`` by ``nv``
and refused every floating robot; ``random_configuration`` drew ridgeback-style ±999 999
limits as real positions, so ``check`` failed a correct model; ``random_configuration(rng,
-1)`` was not an InputError.
"""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
import robodyn.reference as reference
from robodyn.exceptions import InputError
from robodyn.verify.check import check_robot


def reference_order(robot, model):
    joints = robot.joint_names[1:]
    others = model.joint_names[1:]
    v_order = list(range(6)) + [6 + others.index(name) for name in joints]
    q_order = list(range(7)) + [7 + others.index(name) for name in joints]
    return q_order, v_order


def to_reference(x, order):
    out = np.empty_like(x)
    out[:, order] = x
    return out


def test_reference_forward_dynamics_and_kinetic_energy_take_floating_robots():
    robot = robodyn.load("solo12")
    model = reference.load("solo12", floating_base=True)
    q_order, v_order = reference_order(robot, model)
    rng = np.random.default_rng(5)
    q, v, tau = robot.random_configuration(rng, 6), rng.normal(size=(6, 18)), rng.normal(size=(6, 18))
    mine = robot.forward_dynamics(q, v, tau)
    theirs = model.forward_dynamics(to_reference(q, q_order), to_reference(v, v_order), to_reference(tau, v_order))[:, v_order]
    np.testing.assert_allclose(theirs, mine, rtol=1e-9, atol=1e-9 * np.abs(mine).max())
    energy = model.kinetic_energy(to_reference(q, q_order), to_reference(v, v_order))
    np.testing.assert_allclose(energy, robot.kinetic_energy(q, v), rtol=1e-12)
    single = model.kinetic_energy(to_reference(q, q_order)[0], to_reference(v, v_order)[0])
    assert single == pytest.approx(energy[0], rel=1e-14)
    # Negative control: a wrong torque gives other accelerations.
    wrong = model.forward_dynamics(to_reference(q, q_order), to_reference(v, v_order), to_reference(tau + 0.1, v_order))
    assert np.abs(wrong[:, v_order] - mine).max() > 1e-3


PLACEHOLDER = """<robot name="placeholder_base">
  <link name="world"/>
  <joint name="rail" type="prismatic"><parent link="world"/><child link="cart"/><axis xyz="0.6 0.8 0"/>
    <limit lower="-999999" upper="999999" effort="100" velocity="1"/></joint>
  <link name="cart"><inertial><origin xyz="0.05 0 0.1"/><mass value="3"/>
    <inertia ixx="0.1" ixy="0.01" ixz="0" iyy="0.2" iyz="0" izz="0.15"/></inertial></link>
  <joint name="turn" type="revolute"><parent link="cart"/><child link="arm"/><origin xyz="0 0 0.2"/><axis xyz="0 0 1"/>
    <limit lower="-1e4" upper="1e4" effort="100" velocity="1"/></joint>
  <link name="arm"><inertial><origin xyz="0.3 0 0"/><mass value="1.2"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.04" iyz="0" izz="0.04"/></inertial></link>
  <joint name="lift" type="revolute"><parent link="arm"/><child link="hand"/><origin xyz="0.6 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="999999" effort="20" velocity="1"/></joint>
  <link name="hand"><inertial><origin xyz="0.1 0 0"/><mass value="0.4"/>
    <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.002"/></inertial></link>
</robot>"""


def test_placeholder_limits_are_sampled_in_a_physical_range():
    robot = robodyn.load(PLACEHOLDER)
    q = robot.random_configuration(np.random.default_rng(0), 2000)
    assert np.abs(q[:, :2]).max() <= np.pi  # no limit: [-π, π]
    assert q[:, 2].min() >= -2 and q[:, 2].max() <= -2 + 2 * np.pi  # one limit: 2π on its side
    assert np.ptp(q[:, 0]) > 5  # and really spread over it
    lower, upper = robot.physical_limits()
    assert np.isinf(lower[:2]).all() and lower[2] == -2 and np.isinf(upper).all()


def test_check_passes_a_correct_model_with_placeholder_limits():
    robot = robodyn.load(PLACEHOLDER)
    assert check_robot(robot, samples=20, seed=1).passed


@pytest.mark.parametrize("count", [-1, 2.5, "3", True])
def test_random_configuration_refuses_a_bad_count(count):
    with pytest.raises(InputError, match="count"):
        robodyn.load("ur5").random_configuration(np.random.default_rng(0), count)


def test_random_configuration_of_zero_states_is_empty():
    assert robodyn.load("ur5").random_configuration(np.random.default_rng(0), 0).shape == (0, 6)


def test_empty_limit_ranges_are_no_limits():
    """The zoo's double pendulum writes lower = upper = 0 on joints that swing freely: its
    states must not all be q = 0, and a swing is not a limit violation."""
    import warnings

    from robodyn.sim.simulation import simulate

    robot = robodyn.load("double_pendulum")
    assert np.ptp(robot.random_configuration(np.random.default_rng(0), 100), axis=0).min() > 3
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        trajectory = simulate(robot, np.array([1.0, 0.5]), np.zeros(2), 0.5, 1e-3)
    assert np.ptp(trajectory.q[:, 0]) > 0.1
