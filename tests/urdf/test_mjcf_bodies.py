"""MJCF bodies, joints and sites: separate namespaces for bodies and sites, and a joint's
``ref`` carried as a constant offset (robodyn's q = MuJoCo's qpos − ref), against MuJoCo."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import robodyn
from tests.conftest import ROOT
from tests.urdf.mujoco_compare import largest_differences, mujoco_state, rigid_model

mujoco = pytest.importorskip("mujoco")

DATA = ROOT / "tests" / "data" / "mjcf"


def placements(robot: robodyn.Robot, q: np.ndarray) -> pin.Data:
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, q)
    return data


def test_a_site_named_as_a_body_becomes_the_frame_site_colon_name_where_mujoco_puts_it():
    robot = robodyn.load(DATA / "included.xml")
    model = mujoco.MjModel.from_xml_path(str(DATA / "included.xml"))
    data = mujoco.MjData(model)
    q = robot.random_configuration(np.random.default_rng(3))
    data.qpos[:] = mujoco_state(robot, model, q, np.zeros(robot.nv), np.zeros(robot.nv))[0]
    mujoco.mj_kinematics(model, data)
    ours = placements(robot, q)
    for site, frame in (("torso", "site:torso"), ("tip", "site:tip")):
        index = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, site)
        pose = ours.oMf[robot.frame_id(frame)]
        assert np.abs(pose.translation - data.site_xpos[index]).max() < 1e-12
        assert np.abs(pose.rotation - data.site_xmat[index].reshape(3, 3)).max() < 1e-12
    for body in ("torso", "tip"):  # the bodies keep their names
        index = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, body)
        assert np.abs(ours.oMf[robot.frame_id(body)].rotation - data.xmat[index].reshape(3, 3)).max() < 1e-12


def test_at_q_zero_each_body_is_where_mujoco_puts_it_at_qpos0():
    """MuJoCo's qpos0 is each joint's ref: the modelled pose."""
    robot = robodyn.load(DATA / "included.xml")
    model = mujoco.MjModel.from_xml_path(str(DATA / "included.xml"))
    data = mujoco.MjData(model)
    assert np.abs(model.qpos0).max() > 0.1  # the file has refs
    mujoco.mj_kinematics(model, data)
    ours = placements(robot, np.zeros(robot.nq))
    for body in ("torso", "upper", "tip", "hand"):
        index = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, body)
        assert np.abs(ours.oMf[robot.frame_id(body)].rotation - data.xmat[index].reshape(3, 3)).max() < 1e-12


def test_limits_are_mujocos_range_minus_ref():
    robot = robodyn.load(DATA / "included.xml")
    model = mujoco.MjModel.from_xml_path(str(DATA / "included.xml"))
    for joint in range(model.njnt):
        if not model.jnt_limited[joint]:
            continue
        dof = next(d for d in robot.dofs if d.name == mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, joint))
        ref = model.qpos0[model.jnt_qposadr[joint]]
        assert (dof.lower, dof.upper) == pytest.approx(tuple(model.jnt_range[joint] - ref), abs=1e-15)
        assert dict(robot.source.joint_offsets).get(dof.name, 0.0) == pytest.approx(ref, abs=1e-15)


def test_a_ref_ignored_is_caught():
    """The negative control: robodyn's q taken as MuJoCo's qpos (the ref offset left out)
    gives other torques."""
    robot = robodyn.load(DATA / "floating_ref.xml")
    model = rigid_model(DATA / "floating_ref.xml")
    assert max(largest_differences(robot, model)) < 1e-12
    assert max(largest_differences(robot, model, refs=False)) > 1e-3
