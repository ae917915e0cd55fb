"""Issues 38 (item 12) and 42, the whole-body QP on a plant whose joints are damped: solo12
with viscous damping written into a copy of its URDF (0.02 to 0.06 N m s/rad, a different
value a joint), its feet bilateral contacts, the plant's joint torque ``τ − b v``. Laws, as
on the rigid plant: with ``compensate_damping`` the accelerations and foot forces the plant
realises are the QP's at a moving state and at rest the feet carry ``m g``; a 2 cm shift of
the centre of mass follows ``ë + Kd ė + Kp e = 0`` (its exact solution). Negative control:
the rigid-body QP on the same plant leaves both."""

from __future__ import annotations

import re
from functools import cache
from itertools import count

import numpy as np
import pytest

import robodyn
from robodyn.dynamics.loading import rebuild
from robodyn.sim.constrained import simulate_constrained
from robodyn.sim.whole_body import Stand
from tests.sim.test_whole_body import GRAVITY, kicked, standing

SHIFT = np.array([0.0, 0.02, 0.0])


@cache
def damped_solo() -> robodyn.Robot:
    """solo12 with ``<dynamics damping>`` 0.02 … 0.06 on its twelve revolute joints."""
    rigid = standing()[0]
    values = count()

    def damped(match: re.Match) -> str:
        return f'{match.group(1)}<dynamics damping="{0.02 + 0.04 * next(values) / 11:.6f}" friction="0.0"/>'

    revolute = r'(<joint name="\w+" type="revolute">(?:(?!</joint>).)*?)<dynamics damping="0.0" friction="0.0"/>'
    robot = rebuild(rigid, urdf=re.sub(revolute, damped, rigid.source.text, flags=re.S), label="solo12_damped")
    assert robot.joint_damping[6:].min() >= 0.02 and not robot.joint_damping[:6].any()
    return robot


def moving(robot: robodyn.Robot, q: np.ndarray, feet) -> np.ndarray:
    """The kick's velocity projected onto the feet's constraints (the joints then move)."""
    jacobian = np.vstack([robot.frame_jacobian(q, foot.frame)[:3] for foot in feet])
    v = kicked(robot)
    return v - np.linalg.pinv(jacobian) @ (jacobian @ v)


@pytest.mark.parametrize("compensate", [True, False], ids=["compensated", "negative_control_rigid_law"])
def test_on_the_damped_plant_the_robot_does_what_the_qp_planned_only_when_it_compensates(compensate):
    robot = damped_solo()
    _, q, feet = standing()
    law = Stand(robot, feet, robot.center_of_mass(q), np.eye(3), q, compensate_damping=compensate)
    weight = robot.total_mass * GRAVITY
    for v in (np.zeros(robot.nv), moving(robot, q, feet)):
        planned, _, forces = law.solve(q, v)
        tau = law(0.0, q, v) - robot.joint_damping * v  # what the damped joints pass on
        felt, multipliers = robot.constrained_forward_dynamics(q, v, tau, feet)
        gap = max(np.abs(felt - planned).max(), np.abs(multipliers - forces).max() / weight)
        if not v.any():  # at rest the damping does nothing: the feet carry m g either way
            assert gap <= 1e-6 and abs(multipliers.reshape(4, 3)[:, 2].sum() - weight) <= 1e-6 * weight
        else:
            assert np.abs(robot.joint_damping * v).max() > 1e-3  # the damping acts [N m]
            assert (gap <= 1e-6) == compensate, gap


def on_damped_joints(robot: robodyn.Robot, q: np.ndarray, feet, law: Stand):
    """0.3 s from rest at 2 ms, the joints' torque ``τ − b v``."""
    return simulate_constrained(
        robot, q, constraints=feet, duration=0.3, dt=2e-3, tau=lambda t, qi, vi: law(t, qi, vi) - robot.joint_damping * vi
    )


@pytest.mark.slow  # two 0.3 s runs of 600 QPs, about 6 s
def test_a_centre_of_mass_shift_on_the_damped_plant_follows_the_rigid_plants_closed_loop_law():
    """``e = c_d − c`` from rest: ``e(t) = e₀ (1 + ω t) e^(−ω t)`` (Kp = ω², Kd = 2 ω, ω = 10);
    the posture task's weight moves it by about 1e-4 of the shift, on the rigid plant too."""
    robot = damped_solo()
    _, q, feet = standing()
    target = robot.center_of_mass(q) + SHIFT
    deviations = {}
    for compensate in (True, False):
        law = Stand(robot, feet, target, np.eye(3), q, compensate_damping=compensate)
        plant = on_damped_joints(robot, q, feet, law)
        t = plant.trajectory.t
        exact = np.outer((1 + 10 * t) * np.exp(-10 * t), SHIFT)
        error = target - np.atleast_2d(robot.center_of_mass(plant.trajectory.q))
        deviations[compensate] = np.abs(error - exact).max() / np.linalg.norm(SHIFT)
    assert deviations[True] <= 5e-4, deviations
    assert deviations[False] > 1e-2, deviations  # negative control: the rigid-body QP
