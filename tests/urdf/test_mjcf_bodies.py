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


def test_a_floating_robot_beside_a_free_ball_is_refused_naming_the_ball(tmp_path):
    """dm_control's quadruped and dog carry a free ball beside the free torso: MuJoCo loads
    it as two bodies; robodyn reads one robot and says which bodies are the second one."""
    path = tmp_path / "robot_and_ball.xml"
    path.write_text(
        """<mujoco><worldbody>
        <body name="torso" pos="0 0 1"><freejoint name="root"/><geom type="sphere" size="0.2" mass="3"/></body>
        <body name="ball" pos="1 0 0.1"><freejoint name="ball_root"/><geom type="sphere" size="0.1" mass="0.2"/></body>
        </worldbody></mujoco>"""
    )
    assert mujoco.MjModel.from_xml_path(str(path)).nv == 12
    with pytest.raises(robodyn.URDFError, match=r"'torso' has other bodies beside it .*\('ball'\).*one robot") as refused:
        robodyn.load(path)
    assert "\n" not in str(refused.value)


SITES = """<mujoco><compiler angle="radian"/><worldbody>
<site name="target" pos="0.3 -0.2 0.4" euler="0.3 0.2 0.1"/>
<body name="upper" pos="0 0 0.5"><joint name="shoulder" axis="0 1 0"/><geom type="capsule" fromto="0 0 0 0.4 0 0" size="0.04"/>
  <site name="ray" type="capsule" size="0.005" fromto="0.41 -0.02 0.11 0.34 0 0.115"/>
  <site name="down" type="box" size="0.01 0.01 0.01" fromto="0.1 0 0.3 0.1 0 0.1"/>
  <body name="lower" pos="0.4 0 0"><joint name="elbow" axis="0.2 1 0.1"/><geom type="cylinder" fromto="0 0 0 0 0.1 -0.3" size="0.03"/>
    <site name="upper" pos="0 0.1 -0.3" zaxis="1 1 0"/>
  </body>
</body></worldbody></mujoco>"""


def test_sites_given_by_fromto_and_the_worlds_sites_are_frames_where_mujoco_puts_them(tmp_path):
    """A site's ``fromto`` is its pose (centre, z from its second point to its first, as
    MuJoCo turns it; dm_control's quadruped has twenty such rangefinder sites), and a fixed
    base's world sites are frames on the world (acrobot's and finger's ``target``); both were
    read at the body's origin, or not at all. Checked against MuJoCo at random states."""
    path = tmp_path / "sites.xml"
    path.write_text(SITES)
    robot = robodyn.load(path)
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    for q in robot.random_configuration(np.random.default_rng(8), 3):
        data.qpos[:] = robot.to_mujoco(q)[0]
        mujoco.mj_kinematics(model, data)
        ours = placements(robot, q)
        for site, frame in (("target", "target"), ("ray", "ray"), ("down", "down"), ("upper", "site:upper")):
            index = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, site)
            pose = ours.oMf[robot.frame_id(frame)]
            assert np.abs(pose.translation - data.site_xpos[index]).max() < 1e-12, site
            assert np.abs(pose.rotation - data.site_xmat[index].reshape(3, 3)).max() < 1e-12, site


def test_a_sphere_site_with_fromto_is_refused_as_mujoco_refuses_it_and_a_floating_robots_world_site_is_reported(tmp_path):
    sphere = tmp_path / "sphere.xml"
    sphere.write_text(SITES.replace('type="capsule" size="0.005"', 'type="sphere" size="0.005"'))
    with pytest.raises(ValueError):
        mujoco.MjModel.from_xml_path(str(sphere))
    with pytest.raises(robodyn.URDFError, match="fromto requires a capsule, cylinder, box or ellipsoid site, not a sphere"):
        robodyn.load(sphere)
    floating = tmp_path / "floating.xml"
    floating.write_text(
        """<mujoco><worldbody><site name="goal" pos="1 0 0"/>
        <body name="box"><freejoint/><geom type="box" size="0.1 0.1 0.1"/></body></worldbody></mujoco>"""
    )
    with pytest.warns(robodyn.RobodynWarning, match=r"<worldbody> sites beside a floating robot .*\(goal\)"):
        robodyn.load(floating)
