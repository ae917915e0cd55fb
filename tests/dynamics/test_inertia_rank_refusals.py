"""Forward dynamics called directly at a configuration where joints together move no inertia
(a point mass turned about the line through it) is refused naming those joints, one state or
a batch's row, unconstrained or constrained; a regular robot's results are left as they were."""

from __future__ import annotations

import warnings

import numpy as np
import pinocchio as pin
import pytest

import robodyn
from robodyn.dynamics import inertia_rank
from robodyn.exceptions import RobodynWarning, SingularMassMatrixError

# two revolute axes through one point (x, then y) and a point mass behind them on the line
# (1, 1, 0) while pitch = 0: the combined rotation about that line moves nothing
NECK = """<robot name="neck"><link name="base"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0"
iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
<joint name="nod" type="revolute"><parent link="base"/><child link="ring"/><axis xyz="1 0 0"/>
<limit lower="-1" upper="1" effort="10" velocity="5"/></joint>
<link name="ring"><inertial><mass value="0.2"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>
<joint name="pitch" type="revolute"><parent link="ring"/><child link="head"/><axis xyz="0 1 0"/>
<limit lower="-1" upper="1" effort="10" velocity="5"/></joint>
<link name="head"><inertial><origin xyz="0.2 0.2 0"/><mass value="1.7"/>
<inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link></robot>"""

TAU = np.array([0.7, 0.2])


@pytest.fixture(scope="module")
def neck() -> robodyn.Robot:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RobodynWarning)  # the load's own warning names them too
        return robodyn.load(NECK, gravity=(0.4, -0.3, -9.6))


def test_pinocchios_own_crba_is_singular_where_the_refusals_are_expected():
    model = pin.buildModelFromXML(NECK)
    for q in ([0.0, 0.0], [0.5, 0.0]):
        assert np.linalg.matrix_rank(pin.crba(model, model.createData(), np.array(q)), tol=1e-12) == 1
    assert np.linalg.matrix_rank(pin.crba(model, model.createData(), np.array([0.5, 0.3])), tol=1e-12) == 2


def test_one_state_is_refused_naming_the_joints(neck):
    with pytest.raises(SingularMassMatrixError) as raised:
        neck.forward_dynamics(np.zeros(2), np.array([0.3, -0.1]), TAU)
    assert raised.value.joints == ["nod", "pitch"] and raised.value.row is None
    assert "'nod', 'pitch' together move no inertia" in str(raised.value)


def test_a_batch_is_refused_naming_the_joints_and_the_first_singular_row(neck):
    q = np.array([[0.5, 0.3], [-0.2, 0.4], [0.5, 0.0], [0.0, 0.0], [0.1, -0.2]])
    with pytest.raises(SingularMassMatrixError) as raised:
        neck.forward_dynamics(q, np.zeros((5, 2)), np.tile(TAU, (5, 1)))
    assert raised.value.joints == ["nod", "pitch"] and raised.value.row == 2
    assert "at row 2 of the batch" in str(raised.value)


def test_constrained_forward_dynamics_is_refused_naming_the_joints_one_state_and_a_batch(neck):
    with pytest.raises(SingularMassMatrixError) as raised:
        neck.constrained_forward_dynamics(np.zeros(2), np.zeros(2), TAU, constraints=[])
    assert raised.value.joints == ["nod", "pitch"] and raised.value.row is None
    with pytest.raises(SingularMassMatrixError) as raised:
        neck.constrained_forward_dynamics(np.array([[0.5, 0.3], [0.4, 0.0]]), np.zeros((2, 2)), np.tile(TAU, (2, 1)), [])
    assert raised.value.joints == ["nod", "pitch"] and raised.value.row == 1


def test_forward_dynamics_derivatives_are_refused_naming_the_joints_one_state_and_a_batch(neck):
    with pytest.raises(SingularMassMatrixError) as raised:
        neck.forward_dynamics_derivatives(np.zeros(2), np.zeros(2), TAU)
    assert raised.value.joints == ["nod", "pitch"] and raised.value.row is None
    with pytest.raises(SingularMassMatrixError) as raised:
        neck.forward_dynamics_derivatives(np.array([[0.5, 0.3], [0.1, 0.2], [-0.3, 0.0]]), np.zeros((3, 2)), np.zeros((3, 2)))
    assert raised.value.joints == ["nod", "pitch"] and raised.value.row == 2


def test_away_from_the_singular_set_the_neck_solves_m_a_equals_the_net_torque(neck):
    q, v = np.array([0.5, 0.3]), np.array([0.3, -0.1])
    a = neck.forward_dynamics(q, v, TAU)
    np.testing.assert_allclose(neck.mass_matrix(q) @ a, TAU - neck.nonlinear_effects(q, v), rtol=1e-10, atol=1e-12)


def test_a_regular_robot_with_large_accelerations_gets_the_unchecked_numbers_bit_for_bit(monkeypatch):
    # a light point mass off the line, a large torque: accelerations where M's rank is looked at
    robot = robodyn.load(NECK.replace('xyz="0.2 0.2 0"/><mass value="1.7"', 'xyz="0.2 0.2 0.1"/><mass value="1e-10"'))
    rng = np.random.default_rng(4)
    q, v, tau = rng.uniform(-1, 1, (7, 2)), rng.normal(size=(7, 2)), 1e6 * rng.normal(size=(7, 2))
    looked = []  # the states whose M's rank was looked at: this control reaches that check
    monkeypatch.setattr(inertia_rank, "inertialess_joints", lambda *state: looked.append(state) or [])
    data = robot.model.createData()
    expected = np.array([pin.aba(robot.model, data, *state) for state in zip(q, v, tau, strict=True)])
    assert np.abs(expected).max() > 1e12  # the negative control reaches the looked-at range
    batch = robot.forward_dynamics(q, v, tau)
    assert np.array_equal(batch, robot.handle.calls.a(q, v, tau))  # the path before the check, unchanged
    np.testing.assert_allclose(batch, expected, rtol=1e-9)
    assert np.array_equal(robot.forward_dynamics(q[3], v[3], tau[3]), expected[3])
    inverse = robot.forward_dynamics_derivatives(q, v, tau)[2]
    assert np.abs(inverse).max() > 1e12  # M⁻¹ of the light link, regular: returned
    np.testing.assert_allclose(inverse[3] @ robot.mass_matrix(q[3]), np.eye(2), atol=1e-6)
    assert len(looked) >= 3
