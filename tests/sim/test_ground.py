"""The ground plane and the contact points read from a robot's collision geometry or frames."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import robodyn
from robodyn.exceptions import FrameError, InputError, StaticFrameError
from robodyn.sim.contact import contact_kinematics
from robodyn.sim.contact_run import simulate_contact
from robodyn.sim.ground import ContactPoint, Ground, contact_points

DATA = Path(__file__).parents[1] / "data" / "contact"


def test_a_tilted_ground_has_a_unit_normal_and_orthonormal_contact_axes():
    ground = Ground.tilted(0.3, friction=0.2, height=0.1)
    axes = ground.frame()
    assert np.allclose(axes @ axes.T, np.eye(3), atol=1e-15)
    assert np.allclose(axes[2], (math.sin(0.3), 0, math.cos(0.3)))
    assert ground.gap(np.array([0.0, 0.0, 0.1])) == pytest.approx(0.0)
    assert Ground(normal=(0, 0, 5)).normal == (0.0, 0.0, 1.0)


@pytest.mark.parametrize(
    "arguments", [{"friction": -0.1}, {"friction": math.nan}, {"normal": (0, 0, 0)}, {"height": math.inf}, {"normal": (1, 2)}]
)
def test_a_ground_with_impossible_numbers_is_refused_by_name(arguments):
    with pytest.raises(InputError) as error:
        Ground(**arguments)
    assert next(iter(arguments)) in str(error.value)


def test_a_box_collision_gives_its_eight_corners_at_the_right_heights():
    box = robodyn.load(DATA / "box.urdf", floating_base=True)
    points = contact_points(box, "collision").points
    assert len(points) == 8
    q = box.neutral_configuration()
    q[2] = 1.0
    gaps, jacobian = contact_kinematics(box, q, Ground(), points)
    assert sorted(np.round(gaps, 12)) == [0.95] * 4 + [1.05] * 4
    assert jacobian.shape == (24, 6)


def test_a_sphere_touches_the_plane_at_its_centre_minus_its_radius_even_tilted():
    ball = robodyn.load(DATA / "ball.urdf", floating_base=True)
    (point,) = contact_points(ball, "collision").points
    assert point.radius == 0.1
    ground = Ground.tilted(0.4)
    q = ball.neutral_configuration()
    q[:3] = 0.5 * np.array(ground.normal)
    gaps, jacobian = contact_kinematics(ball, q, ground, (point,))
    assert gaps[0] == pytest.approx(0.4, abs=1e-14)
    # a pure spin about the normal does not move the contact point; a spin about a tangent rolls it
    spin = np.zeros(6)
    spin[3:] = np.array(ground.normal) @ np.eye(3)
    assert np.abs(jacobian @ spin).max() < 1e-14


def test_a_ball_thrown_sliding_ends_rolling_without_slipping():
    ball = robodyn.load(DATA / "ball.urdf", floating_base=True)
    q0 = ball.neutral_configuration()
    q0[2] = 0.1
    v0 = np.zeros(6)
    v0[0] = 2.0  # sliding, not spinning
    run = simulate_contact(ball, ground=Ground(friction=0.3), duration=0.5, dt=1e-4, q0=q0, v0=v0)
    rolling = int(np.argmax(run.slip[:, 0] < 1e-9))  # the first step that ends rolling
    assert rolling * 1e-4 == pytest.approx(2 * 2.0 / (7 * 0.3 * 9.81), abs=2e-4)  # slip lasts 2 v₀ / (7 μ g)
    for k in (rolling + 1, len(run.trajectory.t) - 1):
        # the base's velocity is in its frame, the step's contact velocity at the step's start
        rotation = pin.Quaternion(run.trajectory.q[k - 1, 3:7]).toRotationMatrix()
        v, omega = (rotation @ run.trajectory.v[k, :3])[0], (rotation @ run.trajectory.v[k, 3:])[1]
        assert abs(v - omega * 0.1) < 1e-9  # v = ω r
    speed = (pin.Quaternion(run.trajectory.q[rolling, 3:7]).toRotationMatrix() @ run.trajectory.v[rolling + 1, :3])[0]
    assert speed == pytest.approx(2.0 * 5 / 7, rel=1e-3)  # a solid sphere keeps 5/7 of its speed
    assert run.slip[-1, 0] < 1e-9


def test_unknown_contact_frames_and_robots_without_simple_collisions_are_refused():
    solo = robodyn.load("solo12")
    with pytest.raises(FrameError, match="FL_FOOTX"):
        contact_points(solo, ["FL_FOOTX"])
    found = contact_points(solo, ["FL_FOOT", ContactPoint("heel", "HL_FOOT", (0.0, 0.0, -0.01), 0.01)])
    assert found.names == ["FL_FOOT", "heel"]
    with pytest.raises(InputError, match="twice"):
        contact_points(solo, ["FL_FOOT", "FL_FOOT"])


@pytest.mark.parametrize(
    ("arguments", "named"),
    [
        ({"radius": -0.01}, "radius"),
        ({"radius": math.nan}, "radius"),
        ({"position": (0.0, math.inf, 0.0)}, "position"),
        ({"position": (0.0, 0.0)}, "position"),
        ({"link": ""}, "link"),
    ],
)
def test_an_impossible_contact_point_is_refused_by_name(arguments, named):
    with pytest.raises(InputError, match=named):
        ContactPoint(**({"name": "heel", "link": "HL_FOOT"} | arguments))


def test_a_fixed_robots_world_fixed_links_are_no_contacts():
    arm = robodyn.load(DATA.parent / "mimic_arm.urdf")
    with pytest.raises(StaticFrameError, match="contact point"):
        contact_points(arm, ["base"])
    assert contact_points(arm, ["tip"]).names == ["tip"]


def test_collision_geometry_fixed_to_the_world_is_left_out_and_said():
    urdf = """<robot name="post">
      <link name="base"><collision><geometry><box size="1 1 0.1"/></geometry></collision></link>
      <link name="arm"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
        <collision><origin xyz="0.5 0 0"/><geometry><sphere radius="0.05"/></geometry></collision></link>
      <joint name="hinge" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/>
        <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
    </robot>"""
    found = contact_points(robodyn.load(urdf), "collision")
    assert found.names == ["arm.sphere0"]
    assert found.skipped == ("link 'base' is fixed to the world: its collision geometry is not a contact",)


def test_without_a_collision_sphere_or_box_the_links_named_foot_are_the_contacts_and_said():
    found = contact_points(robodyn.load("solo12"), "collision")
    assert found.names == ["FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"]
    assert found.skipped[-1] == "contacts: the links named *foot (4), the collision geometry has no sphere or box"


def test_a_robot_with_no_simple_collision_geometry_and_no_feet_is_refused_naming_contacts():
    urdf = """<robot name="rod">
      <link name="base"/>
      <link name="arm"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
        <collision><geometry><cylinder radius="0.05" length="0.5"/></geometry></collision></link>
      <joint name="hinge" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/>
        <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
    </robot>"""
    with pytest.raises(InputError, match=r"contacts.*no collision sphere or box"):
        contact_points(robodyn.load(urdf), "collision")


def test_an_empty_contact_frame_name_is_refused_naming_the_contacts():
    with pytest.raises(InputError, match=r"^contacts must be frame names, none empty") as caught:
        contact_points(robodyn.load("rp_arm"), ["end_effector", ""])  # `--contact end_effector,` on the command line
    assert caught.value.argument == "contacts"
