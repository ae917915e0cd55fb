"""The whole-body controller's attitude task is a law in world axes: where the centre of
mass and attitude tasks are reachable together (four sticking feet leave a floating
robot six motions), the QP's base angular acceleration is ``kp log(R_d Rᵀ) − kd ω``, with
the base's world angular velocity ``ω`` and acceleration as Pinocchio gives them
(``LOCAL_WORLD_ALIGNED``), not the body-axes ones (the control: the same law with the
body-axes ``ω`` misses by ``kd (R − I) ω_b``)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

import robodyn
from robodyn.constraints import PointContact
from robodyn.sim.whole_body import Stand

FEET = ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")
LEGS = np.array([0.0, 0.8, -1.6, 0.0, 0.8, -1.6, 0.0, -0.8, 1.6, 0.0, -0.8, 1.6])
KP, KD = 10.0, 20.0


def test_the_base_turns_back_by_kp_log_minus_kd_times_its_world_angular_velocity():
    robot = robodyn.load("solo12")
    level = robot.floating_configuration([0.0, 0.0, 0.3], [0.0, 0.0, 0.0], LEGS)
    height = np.mean([robot.frame_position(level, foot)[2] for foot in FEET])
    level = robot.floating_configuration([0.0, 0.0, 0.3 - height], [0.0, 0.0, 0.0], LEGS)
    turned = robot.floating_configuration([0.0, 0.0, 0.3 - height], [0.0, 0.0, 0.4], LEGS)  # yawed 0.4 rad
    feet = tuple(PointContact(foot, friction=0.8, plane_point=(0, 0, 0)) for foot in FEET)
    control = Stand(robot, feet, robot.center_of_mass(level), np.eye(3), level, kp=KP, kd=KD)
    jacobian = robot.constraint_jacobian(turned, feet)
    null = np.linalg.svd(jacobian)[2][np.linalg.matrix_rank(jacobian) :].T
    kick = np.zeros(robot.nv)
    kick[:6] = [0.02, -0.01, 0.01, 0.15, 0.1, -0.05]
    v = null @ (null.T @ kick)  # a motion the stuck feet allow, rolling and pitching the base
    a, _, _ = control.solve(turned, v)
    model, data, base = robot.model, robot.model.createData(), robot.model.getFrameId("base_link")
    pin.forwardKinematics(model, data, turned, v, a)
    pin.updateFramePlacements(model, data)
    world = pin.LOCAL_WORLD_ALIGNED
    omega = pin.getFrameVelocity(model, data, base, world).angular
    alpha = pin.getFrameClassicalAcceleration(model, data, base, world).angular
    rotation = data.oMf[base].rotation
    law = KP * pin.log3(rotation.T) - KD * omega
    body = KP * pin.log3(rotation.T) - KD * v[3:6]  # the control: ω in the base's own axes
    assert np.linalg.norm(law - body) > 0.03 * np.linalg.norm(law)
    np.testing.assert_allclose(alpha, law, atol=1e-4 * np.linalg.norm(law))
