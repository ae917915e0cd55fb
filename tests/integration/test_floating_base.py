"""Floating bases: the reference agrees with Pinocchio, and laws that hold only when floating."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import HealthCheck, given, settings

import robodyn
from robodyn.sim.simulation import simulate
from robodyn.verify.check import check_robot
from tests.random_robots import random_urdfs


@pytest.mark.parametrize("name", ["solo12", "hector", "talos_arm"])
def test_pinocchio_agrees_with_the_reference(name):
    robot = robodyn.load(name, floating_base=True)
    report = check_robot(robot, samples=20, seed=2)
    assert report.passed, {k: c.max_rel for k, c in report.comparisons.items()}
    assert set(report.comparisons) == {"tau", "M", "Cv", "G"}


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(random_urdfs)
def test_random_floating_trees_agree(urdf):
    report = check_robot(robodyn.load(urdf, floating_base=True), samples=3)
    assert report.passed, {k: c.max_rel for k, c in report.comparisons.items()}


def test_base_rows_of_gravity_are_the_weight_in_the_base_frame(rng):
    robot = robodyn.load("solo12")
    for _ in range(5):
        q = robot.random_configuration(rng)
        rotation = pin.Quaternion(q[3:7]).toRotationMatrix()
        weight = robot.total_mass * np.array([0.0, 0.0, -9.81])
        G = robot.gravity(q)
        np.testing.assert_allclose(G[:3], -rotation.T @ weight, atol=1e-10)
        # and the base torque is the weight's moment about the base origin
        com = pin.centerOfMass(robot.model, robot.model.createData(), q)
        np.testing.assert_allclose(G[3:6], -rotation.T @ np.cross(com - q[:3], weight), atol=1e-10)


def test_momentum_is_conserved_without_gravity_or_torque(rng):
    robot = robodyn.load("solo12", gravity=[0, 0, 0])
    q0 = robot.floating_configuration([0, 0, 0.3], [0.2, -0.1, 0.5], rng.uniform(-1, 1, 12))
    v0 = rng.normal(size=robot.nv)
    trajectory = simulate(robot, q0, v0, 1.0, 1e-3)
    data = robot.model.createData()
    momenta = np.array(
        [
            pin.computeCentroidalMomentum(robot.model, data, q, v).vector.copy()
            for q, v in zip(trajectory.q[::50], trajectory.v[::50], strict=True)
        ]
    )
    drift = np.abs(momenta - momenta[0]).max() / np.abs(momenta[0]).max()
    assert drift < 1e-6, drift  # the integration error (3e-7 at 1 kHz, falling with dt²), not a modelling one
    assert np.ptp(trajectory.q[:, 7:], axis=0).max() > 0.1  # the legs really moved
    # The quaternion stays unit (integration on SE(3)).
    np.testing.assert_allclose(np.linalg.norm(trajectory.q[:, 3:7], axis=1), 1.0, atol=1e-12)


def test_floating_configuration_helper():
    robot = robodyn.load("solo12")
    q = robot.floating_configuration([1, 2, 3], [0, 0, np.pi / 2])
    np.testing.assert_allclose(q[:3], [1, 2, 3])
    np.testing.assert_allclose(q[3:7], [0, 0, np.sqrt(0.5), np.sqrt(0.5)], atol=1e-12)
    assert q.shape == (robot.nq,)
    with pytest.raises(robodyn.InputError, match="floating-base robot"):
        robodyn.load("ur5").floating_configuration([0, 0, 0], [0, 0, 0])
