"""robodyn.load: every kind of source, and clear errors for bad ones."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import robodyn
from robodyn import UnknownRobotError, URDFError
from tests.conftest import ROOT

RP_PATH = ROOT / "urdf" / "rp_arm.urdf"


def test_every_source_kind_gives_the_same_robot():
    robots = [robodyn.load("rp_arm"), robodyn.load(str(RP_PATH)), robodyn.load(RP_PATH), robodyn.load(RP_PATH.read_text())]
    q = [0.4, 0.1]
    for robot in robots:
        assert robot.joint_names == ["joint1", "joint2"]
        np.testing.assert_allclose(robot.mass_matrix(q), robots[0].mass_matrix(q))


def test_generated_robot_keeps_its_urdf_text():
    assert robodyn.load("rp_arm").urdf == robodyn.rp_arm_urdf()


def test_zoo_robot_resolves_package_paths():
    robot = robodyn.load("panda")
    assert robot.nq == robot.nv == 8  # seven arm joints and one finger; the other finger mimics it
    assert robot.package_dirs and all(Path(d).is_dir() for d in robot.package_dirs)
    mesh = robot.spec.xml.find(".//mesh").get("filename")
    assert mesh.startswith("package://")
    relative = mesh.removeprefix("package://")
    assert any((Path(d) / relative).is_file() for d in robot.package_dirs)


def test_continuous_joints_take_one_angle_each():
    robot = robodyn.load("double_pendulum_continuous")
    assert [joint.type for joint in robot.joints] == ["continuous", "continuous"]
    assert robot.nq == robot.nv == 2
    # An angle and the same angle plus a full turn are the same configuration.
    q = np.array([0.3, -1.1])
    np.testing.assert_allclose(robot.mass_matrix(q), robot.mass_matrix(q + 2 * np.pi), atol=1e-12)


def test_mimic_joint_follows_its_source():
    robot = robodyn.load("panda")
    assert "panda_finger_joint2" not in robot.joint_names
    q = robot.neutral_configuration()
    q[-1] = 0.03
    left = robot.frame_position(q, "panda_leftfinger")
    right = robot.frame_position(q, "panda_rightfinger")
    assert np.linalg.norm(left - right) == pytest.approx(0.06, abs=1e-9)


def test_joints_are_ordered_by_name_not_by_position_in_the_file():
    text = RP_PATH.read_text()
    joint2 = text[text.index('  <joint name="joint2"') : text.index("  </joint>", text.index('<joint name="joint2"')) + 11]
    reordered = text.replace(joint2, "").replace("</robot>", joint2 + "</robot>")
    robot = robodyn.load(reordered)
    assert robot.joint_names == ["joint1", "joint2"]
    np.testing.assert_allclose(robot.gravity([0.2, 0.1]), robodyn.load("rp_arm").gravity([0.2, 0.1]))


def test_floating_base_from_the_zoo():
    robot = robodyn.load("solo12")
    assert robot.floating_base and robot.nq == robot.nv + 1 == 19
    assert robodyn.load("solo12", floating_base=False).nq == 12


def test_gravity_option():
    robot = robodyn.load("rp_arm", gravity=[0, 0, -1.62])
    assert robot.gravity([0.0, 0.0])[0] == pytest.approx(robodyn.load("rp_arm").gravity([0.0, 0.0])[0] * 1.62 / 9.81)


def test_unknown_name_suggests_close_names():
    with pytest.raises(UnknownRobotError, match="did you mean panda"):
        robodyn.load("pandaa")


def test_missing_file_is_a_urdf_error(tmp_path):
    with pytest.raises(URDFError, match="no such file"):
        robodyn.load(tmp_path / "missing.urdf")


def test_malformed_xml_is_a_urdf_error():
    with pytest.raises(URDFError, match="not well-formed XML"):
        robodyn.load("<robot name='x'><link name='a'></robot>")


def test_negative_mass_names_the_link():
    text = robodyn.rp_arm_urdf().replace('<mass value="1.0"/>', '<mass value="-1.0"/>')
    with pytest.raises(URDFError, match=re.escape('link "link2": mass -1.0 kg must not be negative')):
        robodyn.load(text)


def test_robot_names_list_generated_and_zoo():
    names = robodyn.robot_names()
    assert names[:2] == ["pendulum", "rp_arm"]
    assert {"panda", "ur5", "double_pendulum", "solo12"} <= set(names)


def _branch(name: str, child: str, extra: str = "", parent: str = "base") -> str:
    return (
        f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="0.1 0.2 0" rpy="0 0.3 0"/><axis xyz="0 0.6 0.8"/>'
        f'<limit lower="-2" upper="2" effort="5" velocity="1"/>{extra}</joint>'
        f'<link name="{child}"><inertial><origin xyz="0.3 0 0"/><mass value="0.7"/>'
        f'<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.025"/></inertial></link>'
    )


def test_a_mimic_met_before_its_source_loads_and_matches_the_reference():
    """Pinocchio refuses a mimic joint whose subtree it meets before its source's (romeo,
    talos_full): robodyn orders the source's subtree first and keeps every name."""
    from robodyn import reference

    text = (
        '<robot name="gripper"><link name="base"/>'
        + _branch("a_finger", "finger", '<mimic joint="z_motor" multiplier="-0.7" offset="0.1"/>')
        + _branch("m_wrist", "wrist")
        + _branch("z_motor", "motor", parent="wrist")
        + '<link name="j0000000"/><joint name="tip" type="fixed"><parent link="finger"/><child link="j0000000"/></joint>'
        + "</robot>"
    )
    import pinocchio as pin

    with pytest.raises((RuntimeError, ValueError)):  # negative control: Pinocchio alone refuses it
        pin.buildModelFromXML(text, mimic=True)
    robot = robodyn.load(text)
    assert sorted(robot.joint_names) == ["m_wrist", "z_motor"]
    assert "j0000000" in robot.frame_names and "tip" in robot.frame_names and "a_finger" in robot.frame_names
    twin = reference.load(text)
    rng = np.random.default_rng(3)
    q, v, a = rng.uniform(-1, 1, (3, 2))
    assert sorted(twin.joint_names) == sorted(robot.joint_names)
    order = [robot.joint_names.index(name) for name in twin.joint_names]
    np.testing.assert_allclose(
        robot.inverse_dynamics(q, v, a)[order], twin.inverse_dynamics(q[order], v[order], a[order]), rtol=1e-10, atol=1e-12
    )
    # the mimic relation holds: the finger frame follows -0.7 q_motor + 0.1
    finger = robot.frame_position(q, "finger")
    unlocked = robodyn.load(text.replace('<mimic joint="z_motor" multiplier="-0.7" offset="0.1"/>', ""))
    q_full = np.zeros(3)
    names = unlocked.joint_names
    q_full[names.index("m_wrist")] = q[robot.joint_names.index("m_wrist")]
    q_full[names.index("z_motor")] = q[robot.joint_names.index("z_motor")]
    q_full[names.index("a_finger")] = -0.7 * q[robot.joint_names.index("z_motor")] + 0.1
    np.testing.assert_allclose(unlocked.frame_position(q_full, "finger"), finger, atol=1e-14)


@st.composite
def trees_with_a_mimic(draw):
    """A random tree of revolute joints in which one joint mimics another that is not
    below it; joint names are random, so Pinocchio's name order is any order."""
    count = draw(st.integers(3, 6))
    names = draw(st.lists(st.text("abcdefgxyz", min_size=1, max_size=3), min_size=count, max_size=count, unique=True))
    parents = [draw(st.integers(0, i)) for i in range(count)]  # joint i hangs below link parents[i]
    below = {i: {i} for i in range(count)}
    for i in reversed(range(count)):
        if parents[i] > 0:
            below[parents[i] - 1] |= below[i]
    mimic = draw(st.sampled_from([i for i in range(count) if len(below[i]) < count]))
    source = draw(st.sampled_from([i for i in range(count) if i not in below[mimic]]))
    multiplier = draw(st.sampled_from([-0.7, 0.5, 1.3]))
    parts = ['<robot name="tree"><link name="l0"/>']
    for i in range(count):
        extra = f'<mimic joint="{names[source]}" multiplier="{multiplier}" offset="0.05"/>' if i == mimic else ""
        parts.append(_branch(names[i], f"l{i + 1}", extra, parent=f"l{parents[i]}"))
    return "".join([*parts, "</robot>"])


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(trees_with_a_mimic())
def test_any_mimic_order_loads_and_matches_the_reference(text):
    from robodyn import reference

    robot = robodyn.load(text)
    twin = reference.load(text)
    order = [robot.joint_names.index(name) for name in twin.joint_names]
    q, v, a = np.random.default_rng(0).uniform(-1, 1, (3, robot.nv))
    np.testing.assert_allclose(
        robot.inverse_dynamics(q, v, a)[order], twin.inverse_dynamics(q[order], v[order], a[order]), rtol=1e-9, atol=1e-12
    )
