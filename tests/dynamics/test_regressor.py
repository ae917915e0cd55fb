"""The regressor: Y π = tau, against Pinocchio's RNEA column by column, and the reference's Y."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import HealthCheck, given, settings

import robodyn
import robodyn.reference as reference
from robodyn.dynamics.regressor import body_links, inertial_parameters, parameter_names, regressor
from robodyn.reference.regressor import reference_body_links, reference_parameters, reference_regressor
from robodyn.urdf.zoo import zoo_names
from tests.conftest import FAST_ZOO, NONDEGENERATE, random_state, random_states
from tests.random_robots import random_urdfs

#: A chain with a mimic joint (multiplier ≠ 1, an offset), non-unit axes and a welded link.
MIMIC_URDF = """<?xml version="1.0"?>
<robot name="mimic_chain">
  <link name="base"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.1" rpy="0.1 0.2 0"/><axis xyz="0 0.3 1.2"/><limit lower="-2" upper="2" effort="10" velocity="2"/></joint>
  <link name="l1"><inertial><origin xyz="0.1 0.02 0" rpy="0.3 0 0.1"/><mass value="1.3"/>
    <inertia ixx="0.02" ixy="0.001" ixz="0" iyy="0.03" iyz="0.002" izz="0.025"/></inertial></link>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/>
    <origin xyz="0.3 0 0" rpy="0 0.4 0"/><axis xyz="2 0 0.5"/><limit lower="-0.2" upper="0.3" effort="10" velocity="1"/></joint>
  <link name="l2"><inertial><origin xyz="0 0.05 0.01" rpy="0 0 0"/><mass value="0.8"/>
    <inertia ixx="0.004" ixy="0" ixz="0.0005" iyy="0.006" iyz="0" izz="0.005"/></inertial></link>
  <joint name="j3" type="revolute"><parent link="l1"/><child link="l3"/>
    <origin xyz="0 0.2 0" rpy="0 0 0.5"/><axis xyz="1 1 0"/><limit lower="-3" upper="3" effort="10" velocity="2"/>
    <mimic joint="j2" multiplier="-0.7" offset="0.2"/></joint>
  <link name="l3"><inertial><origin xyz="0.05 0 0.02" rpy="0 0 0"/><mass value="0.5"/>
    <inertia ixx="0.002" ixy="0" ixz="0" iyy="0.003" iyz="0" izz="0.0025"/></inertial></link>
  <joint name="tool" type="fixed"><parent link="l3"/><child link="l4"/><origin xyz="0.1 0 0" rpy="0.2 0 0"/></joint>
  <link name="l4"><inertial><origin xyz="0.02 0.01 0" rpy="0 0 0"/><mass value="0.3"/>
    <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial></link>
</robot>
"""


def assert_regressor_reproduces_tau(robot, rng, count=6):
    q, v, a = random_state(robot, rng, count)
    Y = regressor(robot, q, v, a)
    tau = robot.inverse_dynamics(q, v, a)
    scale = max(1.0, float(np.abs(tau).max()))
    assert Y.shape == (count, robot.nv, 10 * len(body_links(robot)))
    np.testing.assert_allclose(Y @ inertial_parameters(robot), tau, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(regressor(robot, q[0], v[0], a[0]), Y[0], rtol=0, atol=1e-12 * np.abs(Y[0]).max())


def rnea_columns(robot, q, v, a):
    """Each column as Pinocchio's RNEA (mimic-aware) of a model whose only non-zero
    parameter is that one: the map Y ↔ RNEA, independent of the regressor algorithm."""
    model = robot.model.copy()
    unit = np.eye(10)

    def tau_with(joint, parameters):  # Pinocchio stores m, c, I_c: a first moment needs a mass
        for other in range(model.njoints):
            model.inertias[other] = pin.Inertia.Zero()
        model.inertias[joint] = pin.Inertia.FromDynamicParameters(parameters)
        return pin.rnea(model, model.createData(), q, v, a)

    columns = []
    for joint in range(1, model.njoints):
        mass_only = tau_with(joint, unit[0])
        columns += [mass_only] + [tau_with(joint, unit[0] + unit[k]) - mass_only for k in range(1, 10)]
    return np.array(columns).T


@pytest.mark.parametrize("name", ["rp_arm", *FAST_ZOO])
def test_y_pi_is_tau_on_zoo_robots(name, rng):
    assert_regressor_reproduces_tau(robodyn.load(name), rng)


def test_y_pi_is_tau_with_mimic_locked_and_floating(rng):
    assert_regressor_reproduces_tau(robodyn.load(MIMIC_URDF), rng)
    assert_regressor_reproduces_tau(robodyn.load("panda", lock={"panda_finger_joint1": 0.013}), rng)
    assert_regressor_reproduces_tau(robodyn.load(MIMIC_URDF, floating_base=True), rng)


def test_without_mimic_joints_y_is_pinocchios_regressor(rng):
    robot = robodyn.load("ur5")
    q, v, a = random_state(robot, rng)
    expected = pin.computeJointTorqueRegressor(robot.model, robot.model.createData(), q, v, a)
    np.testing.assert_array_equal(regressor(robot, q, v, a), expected)


@pytest.mark.parametrize("source", ["ur5", MIMIC_URDF, "panda"])
def test_columns_are_pinocchio_rnea_of_one_parameter(source, rng):
    # Y's column k (Pinocchio's computeJointTorqueRegressor, through Sᵀ for mimic joints)
    # equals RNEA of the model with parameter k alone, in toDynamicParameters' order.
    robot = robodyn.load(source)
    q, v, a = random_state(robot, rng)
    expected = rnea_columns(robot, q, v, a)
    np.testing.assert_allclose(regressor(robot, q, v, a), expected, rtol=0, atol=1e-11 * np.abs(expected).max())


def test_parameter_names_and_friction_columns(rng):
    robot = robodyn.load("rp_arm")
    names = parameter_names(robot, friction=True)
    assert names[:4] == ["m[link1]", "mx[link1]", "my[link1]", "mz[link1]"] and names[9] == "Izz[link1]"
    assert names[-4:] == ["fv[joint1]", "fv[joint2]", "fc[joint1]", "fc[joint2]"]
    q, v, a = random_state(robot, rng)
    Y = regressor(robot, q, v, a, friction=True)
    np.testing.assert_array_equal(Y[:, 20:22], np.diag(v))
    np.testing.assert_array_equal(Y[:, 22:], np.diag(np.sign(v)))
    assert np.all(inertial_parameters(robot, friction=True)[20:] == 0)


def test_input_errors():
    robot = robodyn.load("rp_arm")
    with pytest.raises(robodyn.InputError, match="v"):
        regressor(robot, [0, 0], [0, np.nan], [0, 0])
    with pytest.raises(robodyn.InputError, match="a"):
        regressor(robot, [0, 0], [0, 0], [0, 0, 0])


def test_negative_control_a_wrong_parameter_fails(rng):
    robot = robodyn.load("ur5")
    q, v, a = random_state(robot, rng, 4)
    wrong = inertial_parameters(robot)
    wrong[10 * 2] *= 1.01  # one mass off by 1 %
    tau = robot.inverse_dynamics(q, v, a)
    assert np.abs(regressor(robot, q, v, a) @ wrong - tau).max() > 1e-6 * np.abs(tau).max()


def assert_reference_agrees(source, rng, **options):
    robot = robodyn.load(source, **options)
    ref = reference.load(source, **options)
    q, v, a = random_state(robot, rng, 3)
    order = [robot.joint_names.index(name) for name in ref.joint_names]
    Y = regressor(robot, q, v, a)[:, order]
    links = body_links(robot)
    columns = np.concatenate([10 * links.index(link) + np.arange(10) for link in reference_body_links(ref)])
    Y_ref = reference_regressor(ref, q[:, order], v[:, order], a[:, order])
    assert sorted(reference_body_links(ref)) == sorted(links)
    np.testing.assert_allclose(Y_ref, Y[..., columns], rtol=0, atol=1e-9 * max(1.0, np.abs(Y).max()))
    np.testing.assert_allclose(reference_parameters(ref), inertial_parameters(robot)[columns], rtol=0, atol=1e-12)
    return Y[..., columns], Y_ref


@pytest.mark.parametrize("source", ["rp_arm", "ur5", MIMIC_URDF])
def test_reference_regressor_agrees(source, rng):
    assert_reference_agrees(source, rng)


def test_reference_regressor_agrees_locked(rng):
    assert_reference_agrees("panda", rng, lock={"panda_finger_joint1": 0.013})


def test_negative_control_reference_detects_swapped_columns(rng):
    Y, Y_ref = assert_reference_agrees("rp_arm", rng)
    swapped = Y.copy()
    swapped[..., [4, 6]] = swapped[..., [6, 4]]  # Ixx and Iyy of link1
    assert np.abs(swapped - Y_ref).max() > 1e-3 * np.abs(Y).max()


@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(random_urdfs)
def test_random_trees(urdf):
    rng = np.random.default_rng(0)
    assert_regressor_reproduces_tau(robodyn.load(urdf), rng)
    assert_reference_agrees(urdf, rng)


@pytest.mark.slow
@pytest.mark.parametrize("name", zoo_names())
def test_every_fixed_base_zoo_robot(name, rng):
    try:
        robot = robodyn.load(name, floating_base=False)
    except robodyn.RobodynError:
        return  # refused models are covered by the zoo tests
    assert_regressor_reproduces_tau(robot, rng, count=3)


def test_the_friction_columns_are_the_joints_damping_and_friction_and_armature_a_known_torque(rng):
    """oblique (``<dynamics damping friction>`` on j_twist), floating, with armature: the
    robot's own friction parameters are its b and f, and ``Y π + armature ⊙ a`` is the
    inverse dynamics with the joints' friction (7 states, one with j_twist at rest)."""
    robot = robodyn.load(NONDEGENERATE / "oblique.urdf", floating_base=True, armature={"j_twist": 0.05, "j_extend": 0.3})
    parameters = inertial_parameters(robot, friction=True)
    nv = robot.nv
    np.testing.assert_array_equal(parameters[-2 * nv :], np.concatenate([robot.joint_damping, robot.joint_friction]))
    assert robot.joint_friction.any()
    q, v, a = random_states(robot, rng, 7)
    v[0, robot.joint_names.index("j_twist") + 5] = 0.0
    Y = regressor(robot, q, v, a, friction=True)
    expected = robot.inverse_dynamics(q, v, a, joint_friction=True)
    np.testing.assert_allclose(Y @ parameters + robot.joint_armature * a, expected, atol=1e-10 * np.abs(expected).max())
    assert np.abs(Y @ parameters - expected).max() > 1e-3  # negative control: the armature matters
