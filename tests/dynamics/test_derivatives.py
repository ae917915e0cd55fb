"""Derivatives of the dynamics (robodyn.dynamics.derivatives): identities, central finite
differences along ``integrate`` (mimic, oblique prismatic, tilted floating bases, non-default
gravity), batches, the input boundary, MuJoCo's finite differences and the reference's."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pytest

import robodyn
from robodyn import reference
from tests.conftest import NONDEGENERATE_CASES, random_states

GRAVITY = [1.3, -2.1, -8.7]
#: Robots checked against finite differences: a mimic gripper (multipliers ≠ ±1, offsets),
#: oblique prismatic axes, tilted floating bases, a mimic tree on a floating base.
FD_CASES = ["gripper", "oblique", "oblique_floating", "mimic_tree", "mimic_tree_floating", "gripper_floating"]
ZOO = {"ur5": {}, "panda": {"lock": {"panda_finger_joint1": 0.0}}, "double_pendulum_continuous": {}}


def load_case(name: str) -> robodyn.Robot:
    if name in ZOO:
        return robodyn.load(name, gravity=GRAVITY, **ZOO[name])
    path, options = NONDEGENERATE_CASES[name]
    return robodyn.load(path, gravity=GRAVITY, **options)


def along(robot, q, j, step):
    """``q ⊕ step e_j`` (Pinocchio's ``integrate``: the tangent-space convention)."""
    direction = np.zeros(robot.nv)
    direction[j] = step
    return robot.integrate(q, direction)


def central(robot, function, q, v, third, eps=1e-6):
    """Central differences of ``function(q, v, third)`` in q (along integrate), v, third: (nv, nv) each."""
    nv = robot.nv
    by_q, by_v, by_third = (np.zeros((nv, nv)) for _ in range(3))
    for j in range(nv):
        unit = np.eye(nv)[j] * eps
        by_q[:, j] = (function(along(robot, q, j, eps), v, third) - function(along(robot, q, j, -eps), v, third)) / (2 * eps)
        by_v[:, j] = (function(q, v + unit, third) - function(q, v - unit, third)) / (2 * eps)
        by_third[:, j] = (function(q, v, third + unit) - function(q, v, third - unit)) / (2 * eps)
    return by_q, by_v, by_third


def relative(a, b):
    return float(np.abs(a - b).max() / max(1.0, np.abs(b).max()))


@pytest.mark.parametrize("name", [*FD_CASES, *ZOO])
def test_derivatives_match_central_differences_along_integrate(name, rng):
    robot = load_case(name)
    q, v, a = random_states(robot, rng, 2)
    for k in range(2):
        tau = robot.inverse_dynamics(q[k], v[k], a[k])
        exact_id = robot.inverse_dynamics_derivatives(q[k], v[k], a[k])
        exact_fd = robot.forward_dynamics_derivatives(q[k], v[k], tau)
        numeric_id = central(robot, robot.inverse_dynamics, q[k], v[k], a[k])
        numeric_fd = central(robot, robot.forward_dynamics, q[k], v[k], tau)
        for exact, numeric in zip((*exact_id, *exact_fd), (*numeric_id, *numeric_fd), strict=True):
            assert exact.shape == (robot.nv, robot.nv)
            assert relative(exact, numeric) < 1e-6, (name, relative(exact, numeric))


def test_a_floating_base_is_differentiated_along_integrate_not_the_quaternion(rng):
    """Negative control of the convention: naive differences of the seven pose numbers
    (renormalised) disagree with ∂τ/∂q's base columns; differences along integrate agree."""
    robot = load_case("oblique_floating")
    q, v, a = (x[0] for x in random_states(robot, rng, 1))
    exact = robot.inverse_dynamics_derivatives(q, v, a)[0]
    eps, column = 1e-6, 4  # the base's rotation about its y axis
    naive = np.zeros(robot.nq)
    naive[3 + 1] = eps  # the quaternion's y entry, in the position coordinates
    plus, minus = q + naive, q - naive
    plus[3:7] /= np.linalg.norm(plus[3:7])
    minus[3:7] /= np.linalg.norm(minus[3:7])
    naive_column = (robot.inverse_dynamics(plus, v, a) - robot.inverse_dynamics(minus, v, a)) / (2 * eps)
    assert relative(exact[:, column], naive_column) > 1e-2
    tangent = (
        robot.inverse_dynamics(along(robot, q, column, eps), v, a) - robot.inverse_dynamics(along(robot, q, column, -eps), v, a)
    ) / (2 * eps)
    assert relative(exact[:, column], tangent) < 1e-6


@pytest.mark.parametrize("name", ["gripper", "mimic_tree_floating", "panda", "oblique_floating"])
def test_the_identities_hold(name, rng):
    """∂τ/∂a = M; ∂q̈/∂τ M = I; ∂q̈/∂(q, v) = −M⁻¹ ∂τ/∂(q, v) at a = q̈ (not at another a)."""
    robot = load_case(name)
    q, v, tau = random_states(robot, rng, 3)
    for k in range(3):
        dqdd_dq, dqdd_dv, inverse = robot.forward_dynamics_derivatives(q[k], v[k], tau[k])
        mass = robot.mass_matrix(q[k])
        acceleration = robot.forward_dynamics(q[k], v[k], tau[k])
        dtau_dq, dtau_dv, dtau_da = robot.inverse_dynamics_derivatives(q[k], v[k], acceleration)
        np.testing.assert_allclose(dtau_da, mass, atol=1e-12 * np.abs(mass).max())
        np.testing.assert_allclose(inverse @ mass, np.eye(robot.nv), atol=1e-9)
        scale = np.abs(dqdd_dq).max()
        np.testing.assert_allclose(dqdd_dq, -inverse @ dtau_dq, atol=1e-9 * scale)
        np.testing.assert_allclose(dqdd_dv, -inverse @ dtau_dv, atol=1e-9 * max(1.0, np.abs(dqdd_dv).max()))
        elsewhere = robot.inverse_dynamics_derivatives(q[k], v[k], acceleration + 1.0)[0]
        assert relative(dqdd_dq, -inverse @ elsewhere) > 1e-6  # negative control: a ≠ q̈


@pytest.mark.parametrize("count", [1, 7, 129])
def test_a_batch_is_the_stack_of_its_states(count, rng):
    robot = load_case("gripper" if count < 100 else "double_pendulum_continuous")
    q, v, a = random_states(robot, rng, count)
    tau = robot.inverse_dynamics(q, v, a)
    for method, third in ((robot.inverse_dynamics_derivatives, a), (robot.forward_dynamics_derivatives, tau)):
        stacks = method(q, v, third)
        assert all(stack.shape == (count, robot.nv, robot.nv) for stack in stacks)
        for k in (0, count // 2, count - 1):
            for stack, single in zip(stacks, method(q[k], v[k], third[k]), strict=True):
                np.testing.assert_array_equal(stack[k], single)


def test_an_empty_batch_gives_empty_stacks():
    robot = load_case("gripper")
    empty = np.zeros((0, robot.nv))
    stacks = robot.inverse_dynamics_derivatives(np.zeros((0, robot.nq)), empty, empty)
    assert all(stack.shape == (0, robot.nv, robot.nv) for stack in stacks)


@pytest.mark.parametrize(
    ("change", "argument"),
    [
        (lambda q, v, a: (q[:-1], v, a), "q"),
        (lambda q, v, a: (q, np.full_like(v, np.nan), a), "v"),
        (lambda q, v, a: (q, v, [1.0, "x"]), "a"),
        (lambda q, v, a: (q.astype(complex), v, a), "q"),
    ],
)
def test_bad_inputs_are_refused_naming_the_argument(change, argument, rng):
    robot = load_case("gripper")
    q, v, a = (x[0] for x in random_states(robot, rng, 1))
    for method in (robot.inverse_dynamics_derivatives, robot.forward_dynamics_derivatives):
        with pytest.raises(robodyn.InputError) as error:
            method(*change(q, v, a))
        assert error.value.argument.startswith(argument) or error.value.argument == "tau"


def test_a_floating_base_quaternion_that_is_not_unit_is_refused(rng):
    robot = load_case("oblique_floating")
    q, v, a = (x[0] for x in random_states(robot, rng, 1))
    q[3:7] *= 1.1
    with pytest.raises(robodyn.InputError, match="quaternion"):
        robot.inverse_dynamics_derivatives(q, v, a)


MASSLESS = """<robot name="massless"><link name="base"/>
<link name="arm"><inertial><mass value="1"/><origin xyz="0 0 -0.5"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
<link name="tip"/>
<joint name="shoulder" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="10" velocity="5"/></joint>
<joint name="wrist" type="revolute"><parent link="arm"/><child link="tip"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="10" velocity="5"/></joint>
</robot>"""


def test_a_singular_mass_matrix_is_refused_in_forward_derivatives():
    robot = robodyn.load(MASSLESS)
    zeros = np.zeros(2)
    assert np.isfinite(robot.inverse_dynamics_derivatives(zeros, zeros, zeros)[0]).all()
    with pytest.raises(robodyn.SingularMassMatrixError, match="wrist"):
        robot.forward_dynamics_derivatives(zeros, zeros, zeros)


@pytest.mark.parametrize("name", ["gripper", "oblique", "mimic_tree", "ur5"])
def test_the_references_central_differences_agree(name, rng):
    """The independent reference (no Pinocchio; its own joint order): central differences of
    its inverse and forward dynamics, all perturbed states in one stacked call."""
    path, options = (name, ZOO[name]) if name in ZOO else NONDEGENERATE_CASES[name]
    model = reference.load(path, gravity=GRAVITY, **options)
    robot = robodyn.load(path, gravity=GRAVITY, **options)
    to_reference = [robot.joint_names.index(joint) for joint in model.joint_names]
    to_robot = [model.joint_names.index(joint) for joint in robot.joint_names]
    q, v, a = (x[0] for x in random_states(robot, rng, 1))
    nv, eps = robot.nv, 1e-6
    steps = np.vstack([np.eye(nv) * eps, -np.eye(nv) * eps])
    zero = np.zeros_like(steps)
    tau = robot.inverse_dynamics(q, v, a)
    for ours, function, third in (
        (robot.inverse_dynamics_derivatives(q, v, a), model.inverse_dynamics, a),
        (robot.forward_dynamics_derivatives(q, v, tau), model.forward_dynamics, tau),
    ):
        for k, (dq, dv, dt) in enumerate(((steps, zero, zero), (zero, steps, zero), (zero, zero, steps))):
            states = ((q + dq)[:, to_reference], (v + dv)[:, to_reference], (third + dt)[:, to_reference])
            values = function(*states)[:, to_robot]
            numeric = (values[:nv] - values[nv:]).T / (2 * eps)
            assert relative(ours[k], numeric) < 1e-6, (name, k, relative(ours[k], numeric))


# --------------------------------------------------------------------------------------
# MuJoCo (loads the same URDF): mjd_inverseFD for ∂τ, central differences of mj_forward for ∂q̈
# --------------------------------------------------------------------------------------
mujoco = pytest.importorskip("mujoco")


def mujoco_model(robot):
    """MuJoCo's model of the robot's URDF: meshes dropped, contacts, limits, damping off."""
    root = ET.fromstring(robot.urdf)
    for element in [*root.iter("link"), *root.iter("joint")]:
        for child in [c for c in element if c.tag in ("visual", "collision", "dynamics", "safety_controller", "calibration")]:
            element.remove(child)
    extension = ET.SubElement(root, "mujoco")
    ET.SubElement(extension, "compiler", {"discardvisual": "true", "fusestatic": "false", "balanceinertia": "false"})
    model = mujoco.MjModel.from_xml_string(ET.tostring(root, encoding="unicode"))
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT | mujoco.mjtDisableBit.mjDSBL_LIMIT
    model.opt.gravity[:] = robot.gravity_vector
    model.dof_damping[:] = model.dof_armature[:] = model.dof_frictionloss[:] = 0.0
    return model


@pytest.mark.parametrize("name", ["ur5", "double_pendulum_continuous"])
def test_derivatives_match_mujocos_finite_differences(name, rng):
    robot = load_case(name)
    model = mujoco_model(robot)
    assert model.nv == robot.nv
    data = mujoco.MjData(model)
    q, v, a = (x[0] for x in random_states(robot, rng, 1))
    data.qpos[:], data.qvel[:], data.qacc[:] = q, v, a
    transposed = [np.zeros((model.nv, model.nv)) for _ in range(3)]
    mujoco.mjd_inverseFD(model, data, 1e-7, 0, *transposed, None, None, None, None)
    for ours, theirs in zip(robot.inverse_dynamics_derivatives(q, v, a), transposed, strict=True):
        assert relative(ours, theirs.T) < 1e-5, relative(ours, theirs.T)

    def acceleration(qi, vi, tau):
        data.qpos[:], data.qvel[:], data.qfrc_applied[:] = qi, vi, tau
        mujoco.mj_forward(model, data)
        return data.qacc.copy()

    tau = robot.inverse_dynamics(q, v, a)
    theirs = central(robot, acceleration, q, v, tau)
    for ours, numeric in zip(robot.forward_dynamics_derivatives(q, v, tau), theirs, strict=True):
        assert relative(ours, numeric) < 1e-5, relative(ours, numeric)
    assert relative(robot.forward_dynamics_derivatives(q, v, tau)[0], theirs[1]) > 1e-2  # negative control
