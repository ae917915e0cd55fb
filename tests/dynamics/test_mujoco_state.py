"""Robot.to_mujoco / from_mujoco against MuJoCo's own model of the file: joint order by name,
ref offsets, the free joint's w-first quaternion and world-frame linear velocity."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn.exceptions import InputError
from tests.conftest import ROOT

mujoco = pytest.importorskip("mujoco")

PATH = ROOT / "tests" / "data" / "mjcf" / "floating_ref.xml"


def mujoco_model() -> mujoco.MjModel:
    model = mujoco.MjModel.from_xml_path(str(PATH))
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT
    model.dof_damping[:] = 0
    return model


def random_mujoco_state(model, rng):
    qpos = model.qpos0 + np.concatenate([rng.normal(size=3), np.zeros(4), rng.normal(scale=0.5, size=model.nq - 7)])
    qpos[3:7] = rng.normal(size=4)
    qpos[3:7] /= np.linalg.norm(qpos[3:7])
    return qpos, rng.normal(size=model.nv), rng.normal(size=model.nv)


def base_rotation(qpos) -> np.ndarray:
    matrix = np.zeros(9)
    mujoco.mju_quat2Mat(matrix, qpos[3:7])
    return matrix.reshape(3, 3)


def robodyn_acceleration_and_torque_map(robot, model, qpos, qvel, qacc, v):
    """robodyn's a of MuJoCo's qacc, and the map of MuJoCo's generalized forces to
    robodyn's, written from MuJoCo's conventions (not robodyn's conversion)."""
    rotation = base_rotation(qpos)
    a, forces = np.zeros(robot.nv), np.zeros((robot.nv, model.nv))
    a[:3] = rotation.T @ qacc[:3] - np.cross(v[3:6], v[:3])
    a[3:6] = qacc[3:6]
    forces[:3, :3], forces[3:6, 3:6] = rotation.T, np.eye(3)
    for joint in range(1, model.njnt):
        index = next(dof.index for dof in robot.dofs if dof.name == mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, joint))
        a[index] = qacc[model.jnt_dofadr[joint]]
        forces[index, model.jnt_dofadr[joint]] = 1
    return a, forces


def test_tau_at_the_converted_state_equals_mj_inverse():
    robot = robodyn.load(PATH)
    model = mujoco_model()
    data = mujoco.MjData(model)
    rng = np.random.default_rng(8)
    mujoco_order = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(1, model.njnt)]
    assert robot.joint_names[1:] != mujoco_order  # the orders differ: matching by name matters
    for _ in range(5):
        data.qpos[:], data.qvel[:], data.qacc[:] = random_mujoco_state(model, rng)
        mujoco.mj_inverse(model, data)
        q, v = robot.from_mujoco(data.qpos, data.qvel)
        a, forces = robodyn_acceleration_and_torque_map(robot, model, data.qpos, data.qvel, data.qacc, v)
        assert np.abs(robot.inverse_dynamics(q, v, a) - forces @ data.qfrc_inverse).max() < 1e-12


def test_gravity_at_mujocos_qpos0_is_mujocos():
    """The trap: qpos0 passed as q (w-first quaternion read as x-first, joints out of order)."""
    robot = robodyn.load(PATH)
    model = mujoco_model()
    data = mujoco.MjData(model)
    data.qpos[:] = model.qpos0
    mujoco.mj_forward(model, data)
    q, _ = robot.from_mujoco(model.qpos0)
    _, forces = robodyn_acceleration_and_torque_map(robot, model, data.qpos, data.qvel, data.qacc, np.zeros(robot.nv))
    assert np.abs(robot.gravity(q) - forces @ data.qfrc_bias).max() < 1e-12
    with pytest.raises(InputError):
        robot.gravity(model.qpos0[:-1])
    wrong = np.abs(robot.gravity(_as_q(model.qpos0)) - forces @ data.qfrc_bias).max()
    assert wrong > 1e-3  # the negative control: MuJoCo's qpos read as robodyn's q


def _as_q(qpos: np.ndarray) -> np.ndarray:
    """MuJoCo's qpos taken as it is, its quaternion normalised as if it were x, y, z, w."""
    q = qpos.copy()
    q[3:7] /= np.linalg.norm(q[3:7])
    return q


def test_kinetic_energy_is_the_same_in_both_coordinates():
    robot = robodyn.load(PATH)
    model = mujoco_model()
    model.opt.enableflags |= mujoco.mjtEnableBit.mjENBL_ENERGY
    data = mujoco.MjData(model)
    rng = np.random.default_rng(2)
    for _ in range(3):
        data.qpos[:], data.qvel[:], _ = random_mujoco_state(model, rng)
        mujoco.mj_forward(model, data)
        q, v = robot.from_mujoco(data.qpos, data.qvel)
        assert robot.kinetic_energy(q, v) == pytest.approx(data.energy[1], abs=1e-12)


def test_to_mujoco_inverts_from_mujoco_row_by_row():
    robot = robodyn.load(PATH)
    model = mujoco_model()
    rng = np.random.default_rng(4)
    states = [random_mujoco_state(model, rng) for _ in range(5)]
    qpos, qvel = np.array([state[0] for state in states]), np.array([state[1] for state in states])
    q, v = robot.from_mujoco(qpos, qvel)
    assert q.shape == (5, robot.nq) and v.shape == (5, robot.nv)
    back_qpos, back_qvel = robot.to_mujoco(q, v)
    assert np.abs(back_qpos - qpos).max() < 1e-14 and np.abs(back_qvel - qvel).max() < 1e-13
    one_q, one_v = robot.from_mujoco(qpos[2], qvel[2])
    assert np.array_equal(one_q, q[2]) and np.abs(one_v - v[2]).max() < 1e-15


def test_a_robot_not_read_from_mjcf_needs_mujocos_joint_order():
    robot = robodyn.load("rp_arm")
    with pytest.raises(InputError, match="joint_names"):
        robot.to_mujoco(np.zeros(robot.nq))
    order = list(reversed(robot.joint_names))
    qpos, _ = robot.to_mujoco(np.arange(robot.nq, dtype=float), joint_names=order)
    assert list(qpos) == list(reversed(range(robot.nq)))
    with pytest.raises(InputError, match="joint_names"):
        robot.to_mujoco(np.zeros(robot.nq), joint_names=order[:1])


def test_a_robot_with_locked_joints_needs_the_order_given():
    robot = robodyn.load(PATH, lock={"knee_b": 0.1})
    with pytest.raises(InputError, match="locked"):
        robot.from_mujoco(np.zeros(robot.nq))
