"""Default PD gains that carry a legged robot's weight (robodyn.sim.gains.load_gains): the
load each joint carries at the target, standing on its contacts. The laws: the contact
forces the rule finds hold the robot up (their sum is m g, their moments cancel gravity's
on the base), each joint's load moment bounds the torque it must hold; solo12 under the
default PD stands at its target height (the inertia-only gains fold it: negative control)."""

from __future__ import annotations

import json

import numpy as np
import pytest

import robodyn
from robodyn.cli.app import main
from robodyn.sim.contact import contact_kinematics
from robodyn.sim.contact_checks import start_above
from robodyn.sim.gains import LOAD_GIVE, joint_inertia, joint_loads, load_gains, pd_gains
from robodyn.sim.ground import Ground, contact_points

FEET = ["FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"]
BENT = [0.1, 0.8, -1.6, -0.1, 0.8, -1.6, 0.1, -0.8, 1.6, -0.1, -0.8, 1.6]


def _standing(robot: robodyn.Robot, joints: list[float]) -> tuple[np.ndarray, np.ndarray]:
    q = robot.default_configuration()
    q[7:] = joints
    q = start_above(robot, q, Ground(), FEET, clearance=0.0)[0]
    return q, contact_kinematics(robot, q, Ground(), contact_points(robot, FEET).points)[1]


def test_the_load_rule_finds_forces_that_hold_the_robot_and_moments_that_bound_its_joint_torques():
    solo = robodyn.load("solo12", gravity=(0.3, -0.2, -8.7))
    q, jacobian = _standing(solo, BENT)
    moment, carried = joint_loads(solo, q, jacobian)
    gravity = solo.gravity(q)
    forces = np.linalg.lstsq(jacobian[:, :6].T, gravity[:6], rcond=None)[0]
    assert np.allclose(jacobian[:, :6].T @ forces, gravity[:6], atol=1e-12)  # the base's rows: it is held
    holding = gravity[6:] - jacobian[:, 6:].T @ forces  # what each joint's motor holds
    assert (np.abs(holding) <= moment + 1e-12).all() and (carried > 0).all()
    assert np.linalg.norm(forces.reshape(-1, 3), axis=1).sum() >= solo.total_mass * np.linalg.norm((0.3, -0.2, -8.7)) - 1e-9
    kp, kd = load_gains(solo, q, jacobian)
    inertia = joint_inertia(solo, q)
    assert np.allclose(kp, 100 * inertia + moment / LOAD_GIVE) and np.allclose(kd, 2 * np.sqrt(kp * inertia))


def test_solo12_stands_at_its_height_under_the_default_pd_hold(capsys):
    status = main(["simulate", "solo12", "--ground", "--controller", "pd", "--duration", "2", "--json"])
    summary = json.loads(capsys.readouterr().out)
    solo = robodyn.load("solo12")
    target, _ = _standing(solo, [0.0] * 12)  # the neutral pose on its feet
    assert status == 0 and abs(summary["final_q"][2] - target[2]) < 1e-3  # [m]
    assert summary["final_joint_error"] < 1e-3


@pytest.mark.slow
def test_the_inertia_only_gains_let_solo12_fold_onto_the_floor(capsys):
    solo = robodyn.load("solo12")
    kp = pd_gains(solo, _standing(solo, [0.0] * 12)[0])[0]  # the rule without the load (kd: critical, the same)
    flags = ["--ground", "--controller", "pd", "--kp", ",".join(f"{k:.17g}" for k in kp), "--duration", "2"]
    status = main(["simulate", "solo12", *flags])
    text = capsys.readouterr().out
    assert status == 0 and "that are no contact points went under the ground" in text
