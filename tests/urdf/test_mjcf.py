"""robodyn's MJCF reader against MuJoCo (mj_inverse, mj_fullM) and Pinocchio's MJCF reader.

The hand-written files in tests/data/mjcf cover every element the reader takes: degree
and radian angles, euler sequences about moving and fixed axes, quat (w first),
axisangle, xyaxes, zaxis, nested default classes with childclass, several joints in one
body, welded bodies, hinge / slide / free joints, diaginertia and fullinertia, armature,
damping, frictionloss, range, limited, sites.
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import mujoco
import numpy as np
import pinocchio as pin
import pytest

import robodyn
from robodyn.exceptions import RobodynWarning, URDFError
from tests.conftest import ROOT

DATA = ROOT / "tests" / "data" / "mjcf"
FILES = ["arm.xml", "floating.xml", "geoms.xml"]


def mujoco_model(text: str) -> mujoco.MjModel:
    """MuJoCo's model with what robodyn's rigid-body dynamics leaves out switched off
    (constraints, joint damping, springs); armature kept."""
    model = mujoco.MjModel.from_xml_string(text)
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT
    model.dof_damping[:] = 0
    model.jnt_stiffness[:] = 0
    return model


def with_armature(robot: robodyn.Robot) -> pin.Model:
    """Pinocchio's model of the robot with the armature robodyn read from the file."""
    model = pin.Model(robot.model)
    for index in range(1, model.njoints):
        joint = robot.spec.joints.get(model.names[index])
        if joint is not None:
            model.armature[model.joints[index].idx_v] = joint.armature
    return model


def velocity_map(robot: robodyn.Robot, model: mujoco.MjModel, q: np.ndarray) -> np.ndarray:
    """T with MuJoCo's qvel = T v: joints matched by name; a free joint's linear velocity
    is in the world frame in MuJoCo, in the body frame in Pinocchio."""
    names = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(model.njnt)]
    transform = np.zeros((model.nv, robot.nv))
    for index in range(1, robot.model.njoints):
        joint = robot.model.joints[index]
        if joint.nv == 6:
            free = int(np.flatnonzero(model.jnt_type == mujoco.mjtJoint.mjJNT_FREE)[0])
            start = model.jnt_dofadr[free]
            transform[start : start + 3, :3] = pin.Quaternion(q[6], *q[3:6]).normalized().matrix()
            transform[start + 3 : start + 6, 3:6] = np.eye(3)
        else:
            transform[model.jnt_dofadr[names.index(robot.model.names[index])], joint.idx_v] = 1
    return transform


def mujoco_state(robot, model, q, v, a):
    """MuJoCo's qpos, qvel, qacc of Pinocchio's (q, v, a)."""
    names = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(model.njnt)]
    transform = velocity_map(robot, model, q)
    qpos, qacc = np.zeros(model.nq), transform @ a
    for index in range(1, robot.model.njoints):
        joint = robot.model.joints[index]
        if joint.nq == 7:
            free = int(np.flatnonzero(model.jnt_type == mujoco.mjtJoint.mjJNT_FREE)[0])
            start = model.jnt_qposadr[free]
            qpos[start : start + 7] = np.concatenate([q[:3], q[6:7], q[3:6]])  # MuJoCo: w first
            qacc[model.jnt_dofadr[free] : model.jnt_dofadr[free] + 3] += transform[:3, :3] @ np.cross(v[3:6], v[:3])
        else:
            qpos[model.jnt_qposadr[names.index(robot.model.names[index])]] = q[joint.idx_q]
    return qpos, transform @ v, qacc, transform


def largest_differences(robot: robodyn.Robot, text: str, samples: int = 7, seed: int = 5) -> tuple[float, float, float]:
    """Largest |τ|, |M| and |G| differences between robodyn (with the file's armature) and
    MuJoCo, over random states."""
    model = mujoco_model(text)
    model.opt.gravity[:] = robot.gravity_vector
    data = mujoco.MjData(model)
    pinocchio_model = with_armature(robot)
    pinocchio_data = pinocchio_model.createData()
    rng = np.random.default_rng(seed)
    worst = np.zeros(3)
    for q in robot.random_configuration(rng, samples):
        v, a = rng.normal(size=robot.nv), rng.normal(size=robot.nv)
        data.qpos[:], data.qvel[:], data.qacc[:], transform = mujoco_state(robot, model, q, v, a)
        mujoco.mj_inverse(model, data)
        tau = pin.rnea(pinocchio_model, pinocchio_data, q, v, a)
        full = np.zeros((model.nv, model.nv))
        mujoco.mj_fullM(model, full, data.qM) if hasattr(data, "qM") else mujoco.mj_fullM(model, data, full)
        mass = pin.crba(pinocchio_model, pinocchio_data, q)
        mass = np.triu(mass) + np.triu(mass, 1).T
        data.qvel[:] = 0
        mujoco.mj_forward(model, data)
        gravity = pin.computeGeneralizedGravity(pinocchio_model, pinocchio_data, q)
        worst = np.maximum(
            worst,
            [
                np.abs(transform.T @ data.qfrc_inverse - tau).max(),
                np.abs(transform.T @ full @ transform - mass).max(),
                np.abs(transform.T @ data.qfrc_bias - gravity).max(),
            ],
        )
    return tuple(worst)


@pytest.mark.parametrize("name", FILES)
def test_tau_mass_matrix_and_gravity_of_an_mjcf_file_equal_mujocos(name):
    path = DATA / name
    robot = robodyn.load(path, gravity=(0.3, -0.2, -9.5))
    assert max(largest_differences(robot, path.read_text())) < 1e-10


def test_the_arm_reads_every_joint_and_its_armature_damping_and_friction_as_mujoco_does():
    path = DATA / "arm.xml"
    robot = robodyn.load(path)
    model = mujoco.MjModel.from_xml_path(str(path))
    for index in range(model.njnt):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, index)
        joint = robot.spec.joints[name]
        dof = model.jnt_dofadr[index]
        assert (joint.armature, joint.damping, joint.friction) == pytest.approx(
            (model.dof_armature[dof], model.dof_damping[dof], model.dof_frictionloss[dof]), abs=1e-15
        )
        if model.jnt_limited[index]:
            assert (joint.lower, joint.upper) == pytest.approx(tuple(model.jnt_range[index]), abs=1e-12)
        else:
            assert np.isinf(joint.lower) and np.isinf(joint.upper)
    assert sorted(robot.joint_names) == sorted(mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(model.njnt))


def test_sites_are_frames_where_mujoco_puts_them():
    path = DATA / "arm.xml"
    robot = robodyn.load(path)
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    q = robot.random_configuration(np.random.default_rng(11))
    data.qpos[:] = mujoco_state(robot, mujoco_model(path.read_text()), q, np.zeros(robot.nv), np.zeros(robot.nv))[0]
    mujoco.mj_kinematics(model, data)
    pin_data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, pin_data, q)
    for site in ("tool", "fingertip"):
        pose = pin_data.oMf[robot.frame_id(site)]
        index = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, site)
        assert np.abs(pose.translation - data.site_xpos[index]).max() < 1e-12
        assert np.abs(pose.rotation - data.site_xmat[index].reshape(3, 3)).max() < 1e-12


#: The arm's axisangle as the same rotation written as a quaternion: Pinocchio's MJCF reader
#: (4.x) reads an axisangle's angle as radians even under <compiler angle="degree"> (MuJoCo
#: reads degrees, as robodyn does: see the test above), so Pinocchio is given the quaternion.
AXISANGLE = ('axisangle="1 1 0 30"', 'quat="0.9659258262890683 0.1830127018922193 0.1830127018922193 0"')


def test_pinocchios_own_mjcf_reader_gives_the_same_mass_matrix(tmp_path):
    name = "arm.xml"  # the floating one: Pinocchio's reader puts the free joint in the tree
    path = DATA / name
    robot = robodyn.load(path)
    (tmp_path / name).write_text(path.read_text().replace(*AXISANGLE))
    theirs = pin.buildModelFromMJCF(str(tmp_path / name))
    assert theirs.nv == robot.nv  # a body's several joints are one composite joint there: same order of dofs
    ours = with_armature(robot)
    assert np.abs(theirs.armature - ours.armature).max() < 1e-15
    for q in robot.random_configuration(np.random.default_rng(2), 7):
        mass = pin.crba(ours, ours.createData(), q)
        their_mass = pin.crba(theirs, theirs.createData(), q)
        assert np.abs(np.triu(mass) - np.triu(their_mass)).max() < 1e-10


def test_a_changed_armature_is_caught():
    path = DATA / "arm.xml"
    text = path.read_text().replace('armature="0.004"', 'armature="0.04"')
    changed = robodyn.load(text)
    assert largest_differences(changed, path.read_text())[1] > 1e-3


def test_a_quaternion_written_w_last_is_caught():
    path = DATA / "arm.xml"
    text = path.read_text().replace('quat="0.9659258 0 0 0.2588190"', 'quat="0 0 0.2588190 0.9659258"')
    assert text != path.read_text()
    assert max(largest_differences(robodyn.load(text), path.read_text())) > 1e-3


def test_settotalmass_scales_masses_and_inertias_as_mujoco_does():
    text = (DATA / "geoms.xml").read_text().replace('<compiler angle="radian"/>', '<compiler angle="radian" settotalmass="7.5"/>')
    robot = robodyn.load(text)
    assert robot.total_mass == pytest.approx(7.5, abs=1e-12)
    assert max(largest_differences(robot, text)) < 1e-10


def test_a_geom_class_left_out_is_caught():
    path = DATA / "geoms.xml"
    text = path.read_text().replace('size="0.06" class="light"', 'size="0.06"')
    assert largest_differences(robodyn.load(text), path.read_text())[1] > 1e-6  # far above the 1e-10 tolerance


def test_degrees_read_as_radians_are_caught():
    path = DATA / "arm.xml"
    text = path.read_text().replace('angle="degree"', 'angle="radian"')
    assert max(largest_differences(robodyn.load(text, check_inertia=False), path.read_text())) > 1e-3


def test_elements_the_dynamics_does_not_take_are_one_warning_line_per_kind_and_strict_refuses():
    path = DATA / "extras.xml"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        robodyn.load(path)
    lines = [str(w.message) for w in caught if issubclass(w.category, RobodynWarning)]
    assert len(lines) == 3 and all("\n" not in line for line in lines)
    assert any("tendons" in line and "cable" in line for line in lines)
    # the motor "drive" is read (an effort limit, the actuated set); the position servo's gains are reported
    assert any("servos" in line and "(servo)" in line for line in lines)
    assert any("stiffness" in line and "swing" in line for line in lines)
    with pytest.raises(URDFError, match="strict=True refuses"):
        robodyn.load(path, strict=True)


MINIMAL = """<mujoco model="m"><compiler angle="radian"/><worldbody>
<body name="b"><joint name="j" {joint}/>{inside}</body></worldbody></mujoco>"""
INERTIAL = '<inertial pos="0 0 -0.1" mass="1" diaginertia="0.01 0.01 0.01"/>'


@pytest.mark.parametrize(
    ("joint", "inside", "message"),
    [
        ('type="ball"', INERTIAL, 'joint "j": ball joints are not read'),
        ("", '<geom type="mesh" mesh="m"/>', 'body "b" has no <inertial> and a mesh geom'),
        ("", '<geom type="box" fromto="0 0 0 0 0 1" size="0.1 0.1"/>', "fromto on a box"),
        ('axis="0 0 0"', INERTIAL, "must not be zero"),
        ('range="0.5 0.1"', INERTIAL, "lower < upper"),
        ("", INERTIAL + '<body name="c"><freejoint/>' + INERTIAL + "</body>", "only read on the top body"),
        ("", '<frame pos="0 0 1"/>' + INERTIAL, "MJCF <frame> is not read"),
        ("", '<inertial mass="1" fullinertia="1 1 1 0 0 0" quat="1 0 0 0"/>', "fullinertia cannot have"),
    ],
)
def test_what_the_reader_cannot_take_is_refused_in_one_line(joint, inside, message):
    with pytest.raises(URDFError) as raised:
        robodyn.load(MINIMAL.format(joint=joint, inside=inside))
    assert message in str(raised.value) and "\n" not in str(raised.value)


def test_an_sdf_file_is_refused_with_how_to_convert_it(tmp_path):
    path = tmp_path / "model.sdf"
    path.write_text('<?xml version="1.0"?>\n<sdf version="1.7"><model name="m"/></sdf>\n')
    with pytest.raises(URDFError, match=re.escape("gz sdf -p model.sdf > model.urdf")):
        robodyn.load(path)


def test_the_reference_and_check_read_the_mjcf_robot():
    report = robodyn.check_robot(str(DATA / "arm.xml"), samples=7)
    assert report.passed
    reference = robodyn.reference.load(DATA / "arm.xml")
    assert reference.joint_names == robodyn.load(DATA / "arm.xml").joint_names


def test_mujocos_own_test_models_are_refused_in_one_line_where_out_of_scope():
    folder = Path(mujoco.__file__).parent / "testdata"
    for path in sorted(folder.glob("*.xml")):
        try:
            robodyn.load(path)
        except URDFError as error:
            assert "\n" not in str(error)


def test_a_joint_without_range_loads_unlimited_without_a_warning_about_the_file():
    """MuJoCo's joints are unlimited unless limited: nothing in the file to warn about."""
    text = (
        '<mujoco model="free_slide"><worldbody><body name="a" pos="0 0 0.1">'
        '<joint name="slide" type="slide" axis="1 1 0"/><joint name="turn" type="hinge" axis="0 0 1"/>'
        '<inertial pos="0 0 0" mass="1.2" diaginertia="0.01 0.02 0.03"/></body></worldbody></mujoco>'
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        robot = robodyn.load(text)
    assert [dof.joint_type for dof in robot.dofs] == ["prismatic", "continuous"]
    assert all(dof.lower == -np.inf and dof.upper == np.inf for dof in robot.dofs)
