"""MJCF bodies, joints and sites: separate namespaces for bodies and sites, and a joint's
``ref`` carried as a constant offset (robodyn's q = MuJoCo's qpos − ref), against MuJoCo."""

from __future__ import annotations

import contextlib
import pickle

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


START = """<mujoco><compiler angle="radian"/><worldbody><geom type="plane" size="5 5 0.1"/>
<body name="torso" pos="0.3 -0.2 1.1" ORIENTATION><freejoint name="root"/><geom type="box" size="0.2 0.1 0.05"/>
  <body name="arm" pos="0.2 0 0"><joint name="hinge" axis="0 1 0" ref="0.4" range="-1 1.5"/><geom type="sphere" size="0.05"/>
    <body name="slider" pos="0 0 -0.1"><joint name="slide" type="slide" axis="1 0 0" ref="-0.03" range="-0.1 0.1"/>
      <geom type="sphere" size="0.03"/></body>
  </body>
</body></worldbody></mujoco>"""


@pytest.mark.parametrize("orientation", ['quat="0.8 0.1 -0.3 0.5"', 'euler="0.4 -1.2 2.9"'])
def test_the_default_configuration_is_mujocos_qpos0_the_free_body_where_the_file_puts_it(tmp_path, orientation):
    """A free MJCF body starts at its ``<body pos quat>`` (Gymnasium's humanoid at 1.4 m), not
    at the origin in the floor; its joints at their ``ref`` (robodyn's zero)."""
    path = tmp_path / "start.xml"
    path.write_text(START.replace("ORIENTATION", orientation))
    robot = robodyn.load(path)
    model = mujoco.MjModel.from_xml_path(str(path))
    qpos = robot.to_mujoco(robot.default_configuration())[0]
    sign = np.sign(qpos[3] * model.qpos0[3])  # q and -q are one rotation (MuJoCo's euler may give either)
    assert np.abs(np.concatenate([qpos[:3], sign * qpos[3:7], qpos[7:]]) - model.qpos0).max() < 1e-15
    assert np.abs(model.qpos0[3:7] - [1, 0, 0, 0]).max() > 0.1 and abs(model.qpos0[2]) > 1
    neutral = robot.to_mujoco(robot.neutral_configuration())[0]  # the negative control: Pinocchio's neutral
    assert np.abs(neutral[:7] - model.qpos0[:7]).max() > 1
    for copy in (pickle.loads(pickle.dumps(robot)), robodyn.load(path, floating_base=True)):
        np.testing.assert_array_equal(copy.default_configuration(), robot.default_configuration())
    assert robodyn.load(path, floating_base=False).default_configuration().shape == (2,)


def test_a_free_body_on_the_files_plane_starts_above_it_in_a_contact_run(tmp_path):
    """The trap: the default start put the box 5 cm into the floor and the run was refused."""
    path = tmp_path / "start.xml"
    path.write_text(START.replace("ORIENTATION", ""))
    robot = robodyn.load(path)
    trajectory = robodyn.simulate(robot, robot.default_configuration(), np.zeros(robot.nv), 0.002, 1e-3, ground="file")
    assert trajectory.q[0][2] == pytest.approx(1.1)
    with pytest.raises(robodyn.InputError, match="below"):
        robodyn.simulate(robot, robot.neutral_configuration(), np.zeros(robot.nv), 0.002, 1e-3, ground="file")


UNNAMED = """<mujoco><worldbody><site pos="0 0 0.1"/>
<body pos="0 0 1">ROOT<geom type="sphere" size="0.1"/><site pos="0.1 0 0"/>
  <body name="named" pos="0.3 0 0"><joint axis="1 0 0"/><joint name="twist" axis="0 0 1"/><geom type="sphere" size="0.1"/>
    <body pos="0 0.2 0"><joint type="slide" axis="0 1 0"/><geom type="sphere" size="0.1"/><site pos="0 0 0.3"/></body>
  </body>
  <body pos="-0.3 0 0.1"><geom type="sphere" size="0.1"/><site name="tip" pos="0.2 0 0"/><site pos="0 0.2 0"/></body>
</body>
OTHER</worldbody></mujoco>"""


@pytest.mark.parametrize("floating", [False, True])
def test_unnamed_bodies_joints_and_sites_are_named_after_mujocos_ids(tmp_path, floating):
    """``bodyN``, ``jointN``, ``siteN``: N is MuJoCo's id (the world body 0; a free joint
    counts, and so do a floating robot's world sites), each where MuJoCo puts it."""
    other = '<body pos="1 0 0"><joint axis="0 0 1"/><geom type="sphere" size="0.1"/></body>'
    text = UNNAMED.replace("ROOT", "<freejoint/>" if floating else '<joint axis="0 1 0"/>')
    text = text.replace("OTHER", "" if floating else other)
    path = tmp_path / "unnamed.xml"
    path.write_text(text)
    with pytest.warns(robodyn.RobodynWarning) if floating else contextlib.nullcontext():
        robot = robodyn.load(path)
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    q = robot.random_configuration(np.random.default_rng(2))
    data.qpos[:] = robot.to_mujoco(q)[0]
    mujoco.mj_kinematics(model, data)
    ours = placements(robot, q)
    names = {"body": 0, "site": 0, "joint": 0}
    for kind, count, where in (("body", model.nbody, data.xpos), ("site", model.nsite, data.site_xpos)):
        for index in range(1 if kind == "body" else 0, count):
            name = mujoco.mj_id2name(model, getattr(mujoco.mjtObj, f"mjOBJ_{kind.upper()}"), index) or f"{kind}{index}"
            if name == "site0" and floating:
                continue  # a floating robot's world site is reported, not a frame
            names[kind] += name == f"{kind}{index}"
            assert np.abs(ours.oMf[robot.frame_id(name)].translation - where[index]).max() < 1e-12, name
    for index in range(1 if floating else 0, model.njnt):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, index) or f"joint{index}"
        names["joint"] += name == f"joint{index}"
        joint = robot.model.getJointId(name)  # its anchor before it moves, as MuJoCo's xanchor
        anchor = ours.oMi[robot.model.parents[joint]] * robot.model.jointPlacements[joint]
        assert np.abs(anchor.translation - data.xanchor[index]).max() < 1e-12, name
    assert min(names.values()) >= 2  # the file has unnamed ones of each kind


KEYS = """<keyframe><key name="crouch" qpos="0.1 0.2 0.5 0.6 0 0.8 0 0.9 -0.05"/><key time="1"/>
<key name="short" qpos="0.6 0 0.8 0 0.9 -0.05"/></keyframe></mujoco>"""


def test_keyframes_are_reported_in_one_line_and_each_is_a_start_on_request(tmp_path):
    path = tmp_path / "keys.xml"
    path.write_text(START.replace("ORIENTATION", "").replace("</mujoco>", KEYS))
    """A short ``qpos`` is completed as MuJoCo completes it (its ``qpos0``, the quaternion normalised)."""
    with pytest.warns(robodyn.RobodynWarning, match=r"keyframes are not the start, MuJoCo's qpos0 is \(crouch, key1, short\)"):
        robot = robodyn.load(path)
    model = mujoco.MjModel.from_xml_path(str(path))
    for key in range(model.nkey):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_KEY, key) or f"key{key}"
        qpos = robot.to_mujoco(robot.default_configuration(keyframe=name))[0]
        assert np.abs(qpos - model.key_qpos[key]).max() < 1e-15, name
    assert np.abs(model.key_qpos[0] - model.qpos0).max() > 0.5  # the named key is not the start
    with pytest.raises(
        robodyn.InputError, match=r"keyframe must be one of the file's MJCF keyframes \('crouch', 'key1', 'short'\)"
    ):
        robot.default_configuration(keyframe="stand")
    path.write_text(START.replace("ORIENTATION", "").replace("</mujoco>", KEYS.replace(" -0.05", " -0.05 3", 1)))
    with pytest.raises(ValueError):
        mujoco.MjModel.from_xml_path(str(path))
    with pytest.raises(robodyn.URDFError, match=r"keyframe 'crouch': qpos has 10 numbers, more than the model's 9"):
        robodyn.load(path)


def test_a_joint_whose_ref_is_outside_its_range_starts_at_the_nearest_limit_said_in_one_line(tmp_path):
    """Gymnasium's ant: MuJoCo starts its ankles at 0, outside their 30°–70°; robodyn's start
    is MuJoCo's qpos0 clipped into the ranges (a start inside the limits it enforces)."""
    path = tmp_path / "outside.xml"
    path.write_text(START.replace("ORIENTATION", "").replace('ref="0.4" range="-1 1.5"', 'ref="0.4" range="0.6 1.5"'))
    with pytest.warns(robodyn.RobodynWarning, match=r"qpos0 \(ref\) is outside their range start at the nearest limit \(hinge\)"):
        robot = robodyn.load(path)
    model = mujoco.MjModel.from_xml_path(str(path))
    qpos = robot.to_mujoco(robot.default_configuration())[0]
    hinge = model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "hinge")]
    assert model.qpos0[hinge] == pytest.approx(0.4) and qpos[hinge] == pytest.approx(0.6, abs=1e-15)
    qpos[hinge] = model.qpos0[hinge]
    assert np.abs(qpos - model.qpos0).max() < 1e-15
