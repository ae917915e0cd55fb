"""What an MJCF file states beside its bodies, against MuJoCo: its gravity (<option gravity>,
<flag gravity="disable"/>), its actuators (effort limits, the actuated set), its equality
constraints (records), and what the dynamics leaves out reported in one line a kind."""

from __future__ import annotations

import pickle
import warnings

import numpy as np
import pinocchio as pin
import pytest

import robodyn
from robodyn.dynamics.loading import rebuild
from robodyn.exceptions import RobodynWarning, URDFError
from robodyn.reference import load as load_reference
from robodyn.urdf.sources import lint_source
from tests.conftest import ROOT
from tests.urdf.mujoco_compare import largest_differences, mujoco_effort_limits, mujoco_state, rigid_model

mujoco = pytest.importorskip("mujoco")

DATA = ROOT / "tests" / "data" / "mjcf"
FILES = [
    "included.xml",
    "no_gravity.xml",
    "floating_ref.xml",
    "planar_walker.xml",
    "arm.xml",
    "floating.xml",
    "geoms.xml",
    "extras.xml",
]


def quiet_load(path, **options) -> robodyn.Robot:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RobodynWarning)
        return robodyn.load(path, **options)


@pytest.mark.parametrize("name", FILES)
def test_every_test_file_equals_mujoco_with_the_files_own_gravity(name):
    robot = quiet_load(DATA / name)
    assert max(largest_differences(robot, rigid_model(DATA / name))) < 1e-12


@pytest.mark.parametrize("name", FILES)
def test_effort_limits_equal_mujocos_actuator_limits(name):
    robot = quiet_load(DATA / name)
    limits = mujoco_effort_limits(mujoco.MjModel.from_xml_path(str(DATA / name)))
    for dof in robot.dofs:
        if not dof.is_base:
            assert dof.effort_limit == pytest.approx(limits[dof.name], abs=1e-12)


def test_a_tilted_option_gravity_is_the_robots_and_survives_rebuild_and_pickle():
    robot = quiet_load(DATA / "included.xml")
    assert tuple(robot.gravity_vector) == (0.8, -0.5, -9.7)
    assert robot.options.gravity == (0.8, -0.5, -9.7)
    for copy in (rebuild(robot), pickle.loads(pickle.dumps(robot))):
        assert tuple(copy.gravity_vector) == (0.8, -0.5, -9.7)


def test_the_reference_takes_the_files_gravity_too():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RobodynWarning)
        reference = load_reference(DATA / "included.xml")
    assert tuple(reference.gravity_vector) == (0.8, -0.5, -9.7)


def test_gravity_given_overrides_the_files():
    assert tuple(quiet_load(DATA / "included.xml", gravity=(0, 0, -3)).gravity_vector) == (0, 0, -3)


def test_a_disabled_gravity_flag_gives_zero_gravity_as_in_mujoco():
    robot = quiet_load(DATA / "no_gravity.xml")
    model = mujoco.MjModel.from_xml_path(str(DATA / "no_gravity.xml"))
    data = mujoco.MjData(model)
    q = robot.random_configuration(np.random.default_rng(1))
    data.qpos[:] = mujoco_state(robot, model, q, np.zeros(robot.nv), np.zeros(robot.nv))[0]
    mujoco.mj_forward(model, data)
    assert np.abs(data.qfrc_bias).max() == 0 and np.abs(robot.gravity(q)).max() == 0
    assert tuple(robot.gravity_vector) == (0, 0, 0)


def test_a_disabled_damper_flag_leaves_the_joints_undamped_as_in_mujoco():
    robot = quiet_load(DATA / "no_gravity.xml")
    model = mujoco.MjModel.from_xml_path(str(DATA / "no_gravity.xml"))
    assert model.dof_damping.max() > 0 and model.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_DAMPER
    model.opt.density, model.opt.viscosity = 0.0, 0.0  # the fluid forces (reported) out of the way
    data = mujoco.MjData(model)
    data.qvel[:] = 1.0
    mujoco.mj_forward(model, data)
    assert np.abs(data.qfrc_passive).max() == 0  # MuJoCo applies no damping
    assert robot.joint_damping.max() == 0
    assert quiet_load((DATA / "no_gravity.xml").read_text().replace(' damper="disable"', "")).joint_damping.max() == 0.5


def test_a_file_without_option_keeps_the_standard_gravity():
    assert tuple(quiet_load(DATA / "arm.xml").gravity_vector) == (0, 0, -9.81)


def test_fluid_forces_and_flags_are_one_warning_line_each():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        robodyn.load(DATA / "no_gravity.xml")
    lines = [str(item.message) for item in caught if issubclass(item.category, RobodynWarning)]
    assert len(lines) == 2 and all("\n" not in line for line in lines)
    assert any("fluid forces" in line and "density=1000" in line and "viscosity=0.001" in line for line in lines)
    assert any("<flag>" in line and "(limit=disable)" in line for line in lines)  # contact: nothing robodyn models
    with pytest.raises(URDFError, match="strict=True refuses"):
        robodyn.load(DATA / "no_gravity.xml", strict=True)


def test_the_actuated_set_is_the_joints_the_actuators_drive():
    robot = quiet_load(DATA / "included.xml")
    assert {dof.name: dof.actuated for dof in robot.dofs} == {
        "yaw": True,
        "shoulder": True,
        "shoulder_slide": True,
        "elbow": True,
        "passive": False,
    }
    floating = robodyn.load(DATA / "floating_ref.xml", strict=True)  # motors only: nothing to report
    assert [dof.name for dof in floating.dofs if dof.actuated] == ["hip_a", "hip_b"]
    assert all(dof.actuated for dof in quiet_load(DATA / "arm.xml").dofs)  # no <actuator>: every joint
    walker = robodyn.load(DATA / "planar_walker.xml", strict=True)  # the planar root is not actuated
    assert [dof.name for dof in walker.dofs if not dof.actuated] == ["rootx", "rootz", "rooty"]


def test_an_actuator_of_a_joint_the_model_does_not_have_is_refused():
    text = (DATA / "extras.xml").read_text().replace('joint="swing" gear="10"', 'joint="nowhere" gear="10"')
    with pytest.raises(ValueError):
        mujoco.MjModel.from_xml_string(text)
    with pytest.raises(URDFError, match="'nowhere'"):
        quiet_load(text)


def world_pose(robot, data, frame: str) -> pin.SE3:
    return data.oMf[robot.frame_id(frame)]


def test_equality_records_anchor_the_points_mujoco_anchors():
    robot = quiet_load(DATA / "included.xml")
    model = mujoco.MjModel.from_xml_path(str(DATA / "included.xml"))
    data = mujoco.MjData(model)
    q = robot.random_configuration(np.random.default_rng(6))
    data.qpos[:] = mujoco_state(robot, model, q, np.zeros(robot.nv), np.zeros(robot.nv))[0]
    mujoco.mj_kinematics(model, data)
    ours = robot.model.createData()
    pin.framesForwardKinematics(robot.model, ours, q)
    records = {record.name: record for record in robot.source.equalities}
    assert set(records) == {"loop", "grip"}
    loop = records["loop"]
    index = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "hand")
    theirs = data.xpos[index] + data.xmat[index].reshape(3, 3) @ model.eq_data[0, :3]
    assert np.abs(world_pose(robot, ours, loop.body1).act(np.array(loop.anchor)) - theirs).max() < 1e-12
    grip = records["grip"]  # body1's pose implied by the weld, in the world: robodyn's link against MuJoCo's body
    body1, body2 = (mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name) for name in ("tip", "upper"))
    pose = lambda position, wxyz: pin.SE3(pin.Quaternion(*wxyz).normalized().matrix(), np.array(position))  # noqa: E731
    mujoco_body1 = pin.SE3(data.xmat[body1].reshape(3, 3), data.xpos[body1])
    link_in_body = mujoco_body1.inverse() * world_pose(robot, ours, "tip")
    theirs_implied = (
        pin.SE3(data.xmat[body2].reshape(3, 3), data.xpos[body2])
        * pose(model.eq_data[1, 3:6], model.eq_data[1, 6:10])
        * link_in_body
    )
    ours_implied = world_pose(robot, ours, grip.body2) * pose(grip.relpose[:3], grip.relpose[3:])
    assert np.abs(ours_implied.homogeneous - theirs_implied.homogeneous).max() < 1e-12


def test_lint_reports_what_the_import_reported():
    problems = lint_source(str(DATA / "no_gravity.xml"))
    warned = [problem for problem in problems if problem.severity == "warning"]
    assert any("fluid forces" in problem.rule for problem in warned)
    assert any("limit=disable" in problem.rule for problem in warned)


MOTOR = """<mujoco><compiler angle="radian"/><worldbody><body name="b"><joint name="j" {joint}/>
<geom size="0.1"/></body></worldbody><actuator><motor joint="j" {motor}/></actuator></mujoco>"""


@pytest.mark.parametrize(
    ("joint", "motor", "words"),
    [
        ("", 'gear="abc" ctrlrange="-1 1"', "gear: 'abc' is not a finite number"),
        ("", 'ctrllimited="True" ctrlrange="-1 1"', "ctrllimited='True'"),
        ("", 'ctrlrange="1"', "must be 2 numbers"),
        ("", 'ctrlrange="1 -1"', "lower > upper"),
        ("", 'gear="1e308" ctrlrange="-1e308 1e308"', "overflows"),
        ('actuatorfrcrange="a b"', "", "actuatorfrcrange: 'a' is not a finite number"),
    ],
)
def test_a_hostile_actuator_is_one_sentence(joint, motor, words):
    with pytest.raises(URDFError) as raised:
        robodyn.load(MOTOR.format(joint=joint, motor=motor))
    assert words in str(raised.value) and "\n" not in str(raised.value)


@pytest.mark.parametrize("name", ["included.xml", "planar_walker.xml", "floating_ref.xml"])
def test_effort_limits_are_the_largest_force_mujocos_actuators_apply(name):
    """MuJoCo's own clamping, observed: every corner of the control ranges, qfrc_actuator."""
    robot = quiet_load(DATA / name)
    model = mujoco.MjModel.from_xml_path(str(DATA / name))
    data = mujoco.MjData(model)
    largest = np.zeros(model.nv)
    for corner in np.ndindex(*(2,) * model.nu):
        data.ctrl[:] = [model.actuator_ctrlrange[i, side] for i, side in enumerate(corner)]
        mujoco.mj_forward(model, data)
        largest = np.maximum(largest, np.abs(data.qfrc_actuator))
    for joint in range(model.njnt):
        if model.jnt_type[joint] == mujoco.mjtJoint.mjJNT_FREE:
            continue
        dof = next(d for d in robot.dofs if d.name == mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, joint))
        driven = any(model.actuator_trnid[i, 0] == joint for i in range(model.nu))
        assert dof.effort_limit == (pytest.approx(largest[model.jnt_dofadr[joint]], abs=1e-12) if driven else np.inf)


def test_an_integrated_control_is_not_bounded_by_its_control_range():
    """MuJoCo integrates the control into the activation: ctrlrange does not bound the force."""
    text = MOTOR.format(joint="", motor='gear="2"').replace("<motor", '<general dyntype="integrator" ctrlrange="-1 1"')
    model = mujoco.MjModel.from_xml_string(text)
    data = mujoco.MjData(model)
    data.ctrl[:] = 1
    for _ in range(1500):  # 3 s: the activation reaches 3
        mujoco.mj_step(model, data)
    assert abs(data.qfrc_actuator[0]) > 2  # past gear × ctrlrange
    with pytest.warns(RobodynWarning, match="servos"):
        robot = robodyn.load(text)
    assert robot.dofs[0].effort_limit == np.inf
