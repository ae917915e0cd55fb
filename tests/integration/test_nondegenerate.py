"""Robots that are not degenerate where bugs live, run through every independent check.

The robots of ``tests/data/robots`` have mimic joints with multipliers other than ±1 and
non-zero offsets (revolute, prismatic, and a mimic on another branch than its source),
non-unit oblique axes (``axis="0 3 4"``), joint origins with all six values non-zero; they
are also loaded with a floating base (states with non-identity orientations) and with
joints locked at non-zero positions. On each: the reference comparison, locks against the
unlocked robot, and the generated Python code against the Robot; the dynamics identities run
on them in tests/dynamics/test_robot.py, together with the URDFs and zoo robots.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import robodyn
import robodyn.reference
from robodyn.equations.derive import derive_equations, render
from robodyn.exceptions import AmbiguousEndEffectorError, InputError, URDFError
from robodyn.verify.check import check_robot, report_text
from tests.conftest import NONDEGENERATE_CASES, random_states

ROBOTS = Path(__file__).parents[1] / "data" / "robots"
OBLIQUE = ROBOTS / "oblique.urdf"
GRIPPER = ROBOTS / "mimic_gripper.urdf"
MIMIC_TREE = ROBOTS / "mimic_tree.urdf"

CASES = NONDEGENERATE_CASES

#: Pinocchio 4.1's crba (LOCAL convention) accumulates into its data across calls when a
#: mimic joint sits between two independent joints of a chain (mimic_tree's j_elbow);
#: Robot uses the WORLD convention for mimic models, and test_mass_matrix_is_repeatable
#: guards it.


def cases(*, mass: bool):
    """The case names as parameters (``mass``: the test uses M)."""
    return list(CASES)


def load(name: str) -> robodyn.Robot:
    path, options = CASES[name]
    return robodyn.load(path, **options)


def states(robot: robodyn.Robot, seed: int = 7, count: int = 4):
    return random_states(robot, np.random.default_rng(seed), count)


def scale(x: np.ndarray) -> float:
    return float(np.max(np.abs(x))) + 1e-300


# ------------------------------------------------------------------------------------
# Pinocchio against the independent reference
# ------------------------------------------------------------------------------------
QUANTITIES = ("tau", "M", "Cv", "C", "G", "skew_pinocchio", "skew_reference")


def _reference_params():
    for name in CASES:
        for quantity in QUANTITIES:
            if "floating" in name and quantity in ("C", "skew_pinocchio", "skew_reference"):
                continue  # a floating base's C is in other coordinates (see check_robot)
            yield pytest.param(name, quantity, id=f"{name}-{quantity}")


_REPORTS: dict[str, object] = {}


def _report(name: str):
    if name not in _REPORTS:
        _REPORTS[name] = check_robot(load(name), samples=8, seed=3)
    return _REPORTS[name]


@pytest.mark.parametrize(("name", "quantity"), list(_reference_params()))
def test_pinocchio_matches_the_reference(name, quantity):
    report = _report(name)
    assert report.comparisons[quantity].passed, report_text(report)


def test_reference_joint_set_matches_with_locks_and_mimics():
    for name in CASES:
        robot = load(name)
        path, options = CASES[name]
        model = robodyn.reference.load(path, lock=options.get("lock"), floating_base=robot.floating_base)
        assert sorted(model.joint_names) == sorted(robot.joint_names)


# ------------------------------------------------------------------------------------
# Locks against the unlocked robot
# ------------------------------------------------------------------------------------
LOCKS = {
    "oblique_locked": (OBLIQUE, {"j_twist": 0.7, "j_extend": 0.13}),
    "oblique_locked_negative": (OBLIQUE, {"j_extend": -0.08, "j_tool": -1.1}),
    "gripper_locked_sources": (GRIPPER, {"j_rotate": 0.6, "j_left": 0.03}),
    "gripper_locked_prismatic": (GRIPPER, {"j_left": -0.015}),
    "mimic_tree_locked": (MIMIC_TREE, {"j_shoulder": 0.5, "j_slide": 0.07}),
}


@pytest.mark.parametrize("name", list(LOCKS))
@pytest.mark.parametrize("implementation", ["pinocchio", "reference"])
def test_locked_robot_is_the_full_robot_held_at_the_lock(name, implementation):
    """M, C, G and τ of the locked robot equal the full robot's at the locked positions
    (locked velocities and accelerations zero): an independent check of lock_joints."""
    path, lock = LOCKS[name]
    if implementation == "pinocchio":
        locked, full = robodyn.load(path, lock=lock), robodyn.load(path)
        if name == "mimic_tree_locked":  # the full robot has the mid-chain mimic: use fresh data each call
            full = _FreshMass(full)
    else:
        locked, full = robodyn.reference.load(path, lock=lock), robodyn.reference.load(path)
    free = [full.joint_names.index(joint) for joint in locked.joint_names]
    held = [full.joint_names.index(joint) for joint in lock]
    rng = np.random.default_rng(5)
    for _ in range(3):
        q_free, v_free, a_free = rng.uniform(-0.5, 0.5, locked.nv), rng.normal(size=locked.nv), rng.normal(size=locked.nv)
        q, v, a = np.zeros(full.nv), np.zeros(full.nv), np.zeros(full.nv)
        q[free], v[free], a[free] = q_free, v_free, a_free
        q[held] = list(lock.values())
        sub = np.ix_(free, free)
        size = scale(full.mass_matrix(q))
        np.testing.assert_allclose(locked.mass_matrix(q_free), full.mass_matrix(q)[sub], atol=1e-10 * size)
        np.testing.assert_allclose(locked.gravity(q_free), full.gravity(q)[free], atol=1e-10 * scale(full.gravity(q)))
        np.testing.assert_allclose(locked.coriolis_matrix(q_free, v_free), full.coriolis_matrix(q, v)[sub], atol=1e-10 * size)
        tau = full.inverse_dynamics(q, v, a)
        np.testing.assert_allclose(locked.inverse_dynamics(q_free, v_free, a_free), tau[free], atol=1e-10 * scale(tau))


class _FreshMass:
    """A robot whose mass matrix is computed with new Pinocchio data each call (works around
    the accumulation bug so that the lock test tests the lock)."""

    def __init__(self, robot):
        self.robot = robot

    def __getattr__(self, name):
        return getattr(self.robot, name)

    def mass_matrix(self, q):
        import pinocchio as pin

        mass = pin.crba(self.robot.model, self.robot.model.createData(), q)
        return np.triu(mass) + np.triu(mass, 1).T


def test_lock_refuses_positions_outside_the_limits():
    with pytest.raises(InputError, match="j_extend"):
        robodyn.load(OBLIQUE, lock={"j_extend": 0.3})
    with pytest.raises(InputError, match="bogus"):
        robodyn.load(GRIPPER, lock={"bogus": 0.0})


def test_mimic_before_its_source_is_refused_cleanly_or_right():
    """Pinocchio's parser wants a mimic joint after its source in its traversal: a mimic that
    comes first (here by name) is refused with a URDFError, or must be right."""
    text = GRIPPER.read_text().replace("j_wing", "a_wing")
    try:
        robot = robodyn.load(text)
    except URDFError as error:
        assert "mimic" in str(error)
        return
    assert check_robot(robot, samples=4).passed


# ------------------------------------------------------------------------------------
# Generated equations (closed-form Python code from the reference) against the Robot
# ------------------------------------------------------------------------------------
EQUATION_CASES = {
    "oblique": pytest.param("oblique", marks=pytest.mark.slow),
    "oblique_locked": pytest.param("oblique_locked", marks=pytest.mark.slow),
    "oblique_locked_negative": "oblique_locked_negative",
    "gripper_locked_sources": "gripper_locked_sources",
    "mimic_tree_locked": "mimic_tree_locked",
    "gripper": pytest.param("gripper", marks=pytest.mark.slow),  # mimic joints through the linear map
}


@pytest.mark.parametrize("name", list(EQUATION_CASES.values()))
def test_generated_code_matches_the_robot(name):
    path, options = CASES[name]
    robot = load(name)
    namespace: dict = {}
    exec(render(derive_equations(path, form="compact", lock=options.get("lock")), "python"), namespace)
    order = [namespace["JOINT_NAMES"].index(joint) for joint in robot.joint_names]
    q, v, a = states(robot)
    q_gen, v_gen, a_gen = (np.empty_like(x) for x in (q, v, a))
    q_gen[:, order], v_gen[:, order], a_gen[:, order] = q, v, a
    tau = namespace["inverse_dynamics"](q_gen, v_gen, a_gen)[:, order]
    mass = namespace["mass_matrix"](q_gen)[:, order][:, :, order]
    gravity = namespace["gravity"](q_gen)[:, order]
    np.testing.assert_allclose(tau, robot.inverse_dynamics(q, v, a), atol=1e-9 * scale(tau))
    np.testing.assert_allclose(mass, robot.mass_matrix(q), atol=1e-9 * scale(mass))
    np.testing.assert_allclose(gravity, robot.gravity(q), atol=1e-9 * scale(tau))


def test_equations_refuse_a_floating_base_cleanly():
    with pytest.raises(InputError, match="floating"):
        derive_equations(OBLIQUE, floating_base=True)


# ------------------------------------------------------------------------------------
# The unit-quaternion check on every path (single state and stacks)
# ------------------------------------------------------------------------------------
def _calls(robot):
    try:
        frame = robot.end_effector
    except AmbiguousEndEffectorError as error:  # several chains (mimic_gripper): any tip will do
        frame = error.candidates[0]
    return {
        "inverse_dynamics": lambda q, v: robot.inverse_dynamics(q, v, v),
        "forward_dynamics": lambda q, v: robot.forward_dynamics(q, v, v),
        "mass_matrix": lambda q, v: robot.mass_matrix(q),
        "coriolis_matrix": lambda q, v: robot.coriolis_matrix(q, v),
        "gravity": lambda q, v: robot.gravity(q),
        "nonlinear_effects": lambda q, v: robot.nonlinear_effects(q, v),
        "kinetic_energy": lambda q, v: robot.kinetic_energy(q, v),
        "potential_energy": lambda q, v: robot.potential_energy(q),
        "frame_position": lambda q, v: robot.frame_position(q, frame),
        "frame_jacobian": lambda q, v: robot.frame_jacobian(q, frame),
        "frame_bias_acceleration": lambda q, v: robot.frame_bias_acceleration(q, v, frame),
        "wrench_torques": lambda q, v: robot.wrench_torques(q, frame, np.ones(6)),
        "simulate": lambda q, v: robodyn.simulate(robot, q, v, 0.01, 0.005),
    }


METHODS = list(_calls(robodyn.load(OBLIQUE, floating_base=True)))


@pytest.mark.parametrize("robot_name", ["oblique_floating", "gripper_floating"])
@pytest.mark.parametrize("method", METHODS)
def test_a_quaternion_of_norm_1_5_is_refused(robot_name, method):
    robot = load(robot_name)
    q, v, _ = states(robot, count=2)
    call = _calls(robot)[method]
    call(q[0], v[0])  # a unit quaternion is accepted
    bad = q.copy()
    bad[:, 3:7] *= 1.5
    with pytest.raises(InputError, match="quaternion"):
        call(bad[0], v[0])
    if method not in ("frame_bias_acceleration", "wrench_torques", "simulate"):  # single-state methods
        with pytest.raises(InputError, match="quaternion"):
            call(bad, v)


# ------------------------------------------------------------------------------------
# Lock edits at the awkward angles (gimbal lock of the rpy written back)
# ------------------------------------------------------------------------------------
def test_rpy_round_trip_including_gimbal_lock():
    from robodyn.common.rotations import matrix_rpy as _matrix_rpy
    from robodyn.common.rotations import rpy_matrix

    rng = np.random.default_rng(9)
    angles = [rng.uniform(-3, 3, 3) for _ in range(20)]
    angles += [np.array([0.3, np.pi / 2, -0.7]), np.array([-1.2, -np.pi / 2, 0.4]), np.zeros(3), np.array([np.pi, 0.2, -np.pi])]
    for rpy in angles:
        rotation = rpy_matrix(rpy)
        np.testing.assert_allclose(rotation @ rotation.T, np.eye(3), atol=1e-14)
        assert np.linalg.det(rotation) == pytest.approx(1.0)
        np.testing.assert_allclose(rpy_matrix(_matrix_rpy(rotation)), rotation, atol=1e-12)
    roll, pitch, yaw = 0.3, -0.5, 0.8  # rz(yaw) @ ry(pitch) @ rx(roll), column by column
    expected_x = [np.cos(yaw) * np.cos(pitch), np.sin(yaw) * np.cos(pitch), -np.sin(pitch)]
    np.testing.assert_allclose(rpy_matrix(np.array([roll, pitch, yaw]))[:, 0], expected_x, atol=1e-15)
    np.testing.assert_allclose(_matrix_rpy(rpy_matrix(np.array([roll, pitch, yaw]))), [roll, pitch, yaw], atol=1e-14)


GIMBAL = """<robot name="gimbal">
  <link name="base"><inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <joint name="tilt" type="revolute"><parent link="base"/><child link="a"/>
    <origin xyz="0.1 0.2 0.3" rpy="0 0 0.4"/><axis xyz="0 2 0"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <link name="a"><inertial><origin xyz="0.2 0.05 -0.1" rpy="0.2 0.1 0"/><mass value="1.3"/>
    <inertia ixx="0.02" ixy="0.001" ixz="0" iyy="0.03" iyz="0" izz="0.025"/></inertial></link>
  <joint name="spin" type="revolute"><parent link="a"/><child link="b"/>
    <origin xyz="0.3 -0.1 0.05" rpy="0.2 -0.3 0.1"/><axis xyz="1 1 0"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <link name="b"><inertial><origin xyz="0.1 0.02 0.03" rpy="0 0.3 0.2"/><mass value="0.7"/>
    <inertia ixx="0.01" ixy="0" ixz="0.001" iyy="0.012" iyz="0" izz="0.011"/></inertial></link>
</robot>"""


@pytest.mark.parametrize("angle", [np.pi / 2, -np.pi / 2, 1.0])
def test_lock_at_a_gimbal_lock_angle(angle):
    """Locking ``tilt`` at ±π/2 makes the fixed joint's rotation a gimbal lock of rpy."""
    locked, full = robodyn.load(GIMBAL, lock={"tilt": angle}), robodyn.load(GIMBAL)
    rng = np.random.default_rng(1)
    for _ in range(3):
        q, v, a = rng.uniform(-2, 2, 1), rng.normal(size=1), rng.normal(size=1)
        q_full, v_full, a_full = np.array([angle, q[0]]), np.array([0.0, v[0]]), np.array([0.0, a[0]])
        np.testing.assert_allclose(locked.mass_matrix(q), full.mass_matrix(q_full)[1:, 1:], atol=1e-12)
        np.testing.assert_allclose(locked.gravity(q), full.gravity(q_full)[1:], atol=1e-12)
        np.testing.assert_allclose(
            locked.inverse_dynamics(q, v, a), full.inverse_dynamics(q_full, v_full, a_full)[1:], atol=1e-12
        )
        np.testing.assert_allclose(locked.frame_position(q, "b"), full.frame_position(q_full, "b"), atol=1e-12)
        np.testing.assert_allclose(_rotation(locked, q, "b"), _rotation(full, q_full, "b"), atol=1e-12)


def test_lock_refuses_fixed_and_unknown_joints_naming_them():
    for name in ("bracket", "nonexistent"):
        with pytest.raises(InputError, match=rf"^lock must be moving joints of .*, got '{name}'\.$"):
            robodyn.load(OBLIQUE, lock={name: 0.0})
    with pytest.raises(InputError, match=r"^lock must be a position of 'j_extend' within \[-0\.1, 0\.25\], got 0\.3\.$"):
        robodyn.load(OBLIQUE, lock={"j_extend": 0.3})
    with pytest.raises(InputError, match="j_yaw"):
        robodyn.load(OBLIQUE, lock={"j_yaw": float("nan")})


PAYLOAD = (
    '<link name="payload"><inertial><origin xyz="0.02 -0.01 0.03" rpy="0.3 0.1 -0.2"/><mass value="0.9"/>'
    '<inertia ixx="0.004" ixy="0.0003" ixz="0" iyy="0.006" iyz="0.0002" izz="0.005"/></inertial></link>'
)


def test_weld_link_is_the_same_robot_as_the_link_written_by_hand():
    """weld_link against the URDF with the link and its fixed joint written into the text."""
    import xml.etree.ElementTree as ET

    from robodyn.urdf.edit import weld_link
    from robodyn.urdf.validation import parse_urdf

    text = OBLIQUE.read_text()
    spec = parse_urdf(text)
    before = ET.tostring(spec.xml, encoding="unicode")
    welded = weld_link(spec, "ram", ET.fromstring(PAYLOAD), xyz="0.05 0.02 -0.04", rpy="0.4 -0.2 0.3")
    assert ET.tostring(spec.xml, encoding="unicode") == before  # the spec is not changed
    joint = ET.fromstring(welded).find("joint[@name='payload_joint']")
    assert joint is not None and joint.get("type") == "fixed"
    by_hand = text.replace(
        "</robot>",
        PAYLOAD + '<joint name="payload_joint" type="fixed"><parent link="ram"/><child link="payload"/>'
        '<origin xyz="0.05 0.02 -0.04" rpy="0.4 -0.2 0.3"/></joint></robot>',
    )
    robot, expected, plain = robodyn.load(welded), robodyn.load(by_hand), robodyn.load(OBLIQUE)
    q, v, a = states(robot)
    np.testing.assert_allclose(robot.mass_matrix(q), expected.mass_matrix(q), atol=1e-12)
    np.testing.assert_allclose(robot.inverse_dynamics(q, v, a), expected.inverse_dynamics(q, v, a), atol=1e-12)
    assert np.max(np.abs(robot.gravity(q) - plain.gravity(q))) > 1e-3  # the payload matters
    for xyz, rpy in (("0 0 0", "0.4 -0.2 0.3"), ("0.05 0.02 -0.04", "0 0 0")):  # each part of the origin matters
        other = robodyn.load(weld_link(spec, "ram", ET.fromstring(PAYLOAD), xyz=xyz, rpy=rpy))
        assert np.max(np.abs(other.mass_matrix(q) - robot.mass_matrix(q))) > 1e-6


def test_lock_joints_edits_a_copy_and_accepts_the_limits_themselves():
    import xml.etree.ElementTree as ET

    from robodyn.urdf.edit import lock_joints
    from robodyn.urdf.validation import parse_urdf

    spec = parse_urdf(OBLIQUE.read_text())
    before = ET.tostring(spec.xml, encoding="unicode")
    for value in (0.25, -0.1):  # exactly at the upper and lower limits
        locked = ET.fromstring(lock_joints(spec, {"j_extend": value}))
        assert locked.find("joint[@name='j_extend']").get("type") == "fixed"
    assert ET.tostring(spec.xml, encoding="unicode") == before  # the spec is not changed
    for value in (-0.6, 0.25 + 1e-9, -0.1 - 1e-9):
        with pytest.raises(InputError, match="within"):
            lock_joints(spec, {"j_extend": value})
    with pytest.raises(InputError, match=r"^lock must be moving joints of <string>, got 'bracket'\.$"):
        lock_joints(spec, {"bracket": 0.0})


@pytest.mark.parametrize(("path", "lock"), [(OBLIQUE, {"j_twist": 0.7}), (GRIPPER, {"j_rotate": 0.6, "j_left": 0.03})])
def test_locked_joints_keep_nothing_of_their_motion(path, lock):
    """A locked joint is a plain fixed joint: no axis, limit, mimic, dynamics, safety
    controller or calibration left (nothing for lint to warn about)."""
    import xml.etree.ElementTree as ET

    from robodyn.urdf.edit import lock_joints
    from robodyn.urdf.validation import lint_urdf, parse_urdf

    text = lock_joints(parse_urdf(path.read_text()), lock)
    spec, problems = lint_urdf(text)
    assert spec is not None and problems == []
    fixed = {node.get("name"): node for node in ET.fromstring(text).findall("joint") if node.get("type") == "fixed"}
    locked = set(lock) | {j.name for j in parse_urdf(path.read_text()).joints.values() if j.mimic and j.mimic.joint in lock}
    for name in locked:
        assert sorted(child.tag for child in fixed[name]) == ["child", "origin", "parent"]


def _rotation(robot, q, frame):
    """Orientation of a frame in the world frame (through Pinocchio: Robot has no such method)."""
    import pinocchio as pin

    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, q)
    return data.oMf[robot.frame_id(frame)].rotation.copy()
