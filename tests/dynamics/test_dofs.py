"""Robot.dofs: one record per degree of freedom, its units and limits, for every robot kind."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from tests.conftest import ROOT


def test_a_fixed_base_robot_has_one_dof_per_velocity_entry_with_its_joint_limits():
    robot = robodyn.load("rp_arm")
    assert [dof.name for dof in robot.dofs] == robot.joint_names
    assert [dof.index for dof in robot.dofs] == list(range(robot.nv))
    np.testing.assert_array_equal([dof.lower for dof in robot.dofs], robot.lower_limits)
    np.testing.assert_array_equal([dof.upper for dof in robot.dofs], robot.upper_limits)
    assert [dof.effort_limit for dof in robot.dofs] == [joint.effort for joint in robot.joints]


def test_a_prismatic_joint_is_linear_and_a_revolute_one_angular_with_their_units():
    revolute, prismatic = robodyn.load("rp_arm").dofs
    assert (revolute.kind, revolute.position_unit, revolute.velocity_unit, revolute.effort_unit) == (
        "angular",
        "rad",
        "rad/s",
        "N m",
    )
    assert (prismatic.kind, prismatic.position_unit, prismatic.velocity_unit, prismatic.effort_unit) == (
        "linear",
        "m",
        "m/s",
        "N",
    )
    assert prismatic.unit("a") == "m/s²" and revolute.unit("acceleration") == "rad/s²"
    assert (prismatic.effort_word, revolute.effort_word) == ("force", "torque")


def test_a_floating_base_gives_six_base_coordinates_three_linear_then_three_angular():
    robot = robodyn.load(str(ROOT / "urdf" / "rp_arm.urdf"), floating_base=True)
    assert len(robot.dofs) == robot.nv and len(robot.configuration_names) == robot.nq
    base = robot.dofs[:6]
    assert [dof.name for dof in base] == ["base.x", "base.y", "base.z", "base.rx", "base.ry", "base.rz"]
    assert [dof.kind for dof in base] == ["linear"] * 3 + ["angular"] * 3
    assert all(dof.is_base and dof.joint == robot.joint_names[0] for dof in base)
    assert robot.configuration_names[:7] == ["base.x", "base.y", "base.z", "base.qx", "base.qy", "base.qz", "base.qw"]
    assert [dof.name for dof in robot.dofs[6:]] == robot.joint_names[1:] == robot.configuration_names[7:]


@pytest.mark.parametrize("lock", [None, {"joint2": 0.1}])
def test_locked_joints_have_no_dof(lock):
    robot = robodyn.load("rp_arm", lock=lock)
    assert [dof.name for dof in robot.dofs] == robot.joint_names
