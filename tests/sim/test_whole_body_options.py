"""Issue 39, the whole-body controller crossed with a gravity that is not along −z and with
armature: solo12 on its four feet under gravity tilted 10°, its joints given rotor inertia.
At rest the QP's forces carry ``−m g`` (the tangential part too) inside the cones and its
torques, applied to the robot, give those forces and no motion. The support polygon is the
feet seen along gravity: a centre of mass over the feet seen from above but outside them
seen along a gravity tilted 30° is refused, and inside when the tilt is the other way.
Negative controls: the default gravity's weight is not what the feet carry; the same
target is accepted under the default gravity."""

from __future__ import annotations

import math

import numpy as np
import pytest

import robodyn
from robodyn.constraints import PointContact
from robodyn.exceptions import InputError
from robodyn.sim.whole_body import Stand, friction_cone_margin, support_margin

FEET = ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")
LEGS = np.array([0.0, 0.8, -1.6, 0.0, 0.8, -1.6, 0.0, -0.8, 1.6, 0.0, -0.8, 1.6])
JOINTS = [f"{leg}_{part}" for leg in ("FL", "FR", "HL", "HR") for part in ("HAA", "HFE", "KFE")]


def gravity_towards(theta: float, azimuth: float) -> np.ndarray:
    return 9.81 * np.array([math.sin(theta) * math.cos(azimuth), math.sin(theta) * math.sin(azimuth), -math.cos(theta)])


def standing(gravity: np.ndarray, **options) -> tuple[robodyn.Robot, np.ndarray, tuple[PointContact, ...]]:
    """solo12 with its feet on the ground ``z = 0``, base level, at rest."""
    robot = robodyn.load("solo12", gravity=gravity, **options)
    q = robot.floating_configuration([0.0, 0.0, 0.3], [0.0, 0.0, 0.0], LEGS)
    height = np.mean([robot.frame_position(q, foot)[2] for foot in FEET])
    q = robot.floating_configuration([0.0, 0.0, 0.3 - height], [0.0, 0.0, 0.0], LEGS)
    return robot, q, tuple(PointContact(foot, friction=0.7, plane_point=(0, 0, 0)) for foot in FEET)


def test_at_rest_under_tilted_gravity_with_armature_the_feet_carry_minus_m_g_inside_the_cones():
    gravity = gravity_towards(math.radians(10.0), math.radians(40.0))
    robot, q, feet = standing(gravity, armature={joint: 0.02 for joint in JOINTS})
    control = Stand(robot, feet, robot.center_of_mass(q), np.eye(3), q)
    zero = np.zeros(robot.nv)
    acceleration, _, forces = control.solve(q, zero)
    weight = robot.total_mass * 9.81
    total = forces.reshape(4, 3).sum(axis=0)
    np.testing.assert_allclose(total, -robot.total_mass * gravity, rtol=0, atol=1e-6 * weight)
    assert np.abs(total - robot.total_mass * np.array([0.0, 0.0, 9.81])).max() > 0.1 * weight  # not the default weight
    assert (friction_cone_margin(feet, forces) > 0).all()
    assert np.abs(acceleration).max() <= 1e-6
    felt, multipliers = robot.constrained_forward_dynamics(q, zero, control(0.0, q, zero), feet)
    np.testing.assert_allclose(multipliers, forces, atol=1e-6 * weight)
    assert np.abs(felt).max() <= 1e-6


@pytest.mark.parametrize("azimuth", [0.0, math.pi])
def test_the_support_polygon_is_seen_along_gravity(azimuth):
    robot, q, feet = standing(gravity_towards(0.0, 0.0))
    feet_x = np.array([robot.frame_position(q, foot)[0] for foot in FEET])
    centre = robot.center_of_mass(q)
    target = centre + np.array([0.6 * feet_x.max() - 0.4 * centre[0], 0.0, 0.0])  # over the feet, seen from above
    assert support_margin(robot, q, feet, target) > 0
    Stand(robot, feet, target, np.eye(3), q)  # accepted under the default gravity
    tilted, q_tilted, _ = standing(gravity_towards(math.radians(30.0), azimuth))
    height = target[2] - np.mean([tilted.frame_position(q_tilted, foot)[2] for foot in FEET])
    shift = height * math.tan(math.radians(30.0)) * math.cos(azimuth)  # where gravity carries the target on the ground
    seen = target[0] + shift
    inside = feet_x.min() < seen < feet_x.max()
    assert inside == (azimuth != 0.0)
    if inside:
        assert support_margin(tilted, q_tilted, feet, target) > 0
        Stand(tilted, feet, target, np.eye(3), q_tilted)
    else:
        assert support_margin(tilted, q_tilted, feet, target) < 0
        with pytest.raises(InputError, match="outside"):
            Stand(tilted, feet, target, np.eye(3), q_tilted)
