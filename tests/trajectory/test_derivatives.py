"""robodyn.trajectory.derivatives: velocities of a floating base with a prismatic joint from positions."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn.exceptions import InputError
from robodyn.trajectory.derivatives import derive_velocities
from tests.conftest import ROOT


@pytest.fixture(scope="module")
def arm():
    return robodyn.load(ROOT / "tests" / "data" / "rrp_arm.urdf", floating_base=True)


def constant_twist(robot, steps: int, h: float):
    """Positions of a constant body-frame velocity (``integrate`` of ``v t``) and that velocity."""
    v = np.array([0.3, -0.2, 0.1, 0.7, -0.4, 1.1, 0.5, -0.8, 0.05])
    t = np.arange(steps) * h
    q = np.array([robot.integrate(robot.neutral_configuration(), v * s) for s in t])
    return t, q, v


def test_a_constant_body_velocity_is_found_exactly_enough(arm):
    t, q, v = constant_twist(arm, 200, 1e-3)
    derived = derive_velocities(t, q, floating_base=True)
    assert derived.shape == (len(t), arm.nv)
    np.testing.assert_allclose(derived, np.tile(v, (len(t), 1)), atol=1e-6)


def test_quaternion_sign_flips_between_samples_change_nothing(arm):
    t, q, _ = constant_twist(arm, 50, 1e-2)
    flipped = q.copy()
    flipped[1::2, 3:7] *= -1.0  # q and -q are one orientation
    np.testing.assert_allclose(
        derive_velocities(t, flipped, floating_base=True), derive_velocities(t, q, floating_base=True), atol=1e-12
    )


def test_the_error_falls_by_four_when_the_step_halves(arm):
    """Second order: a motion with curvature, sampled at h and h/2."""
    errors = []
    for h in (2e-2, 1e-2):
        t = np.arange(0.0, 1.0, h)
        q = np.column_stack([np.sin(2.0 * t), t**3])  # a revolute and a prismatic joint, fixed base
        exact = np.column_stack([2.0 * np.cos(2.0 * t), 3.0 * t**2])
        errors.append(np.abs(derive_velocities(t, q, floating_base=False) - exact)[1:-1].max())
    assert 3.5 < errors[0] / errors[1] < 4.5


def test_fewer_than_three_samples_are_refused():
    with pytest.raises(InputError, match="at least 3 samples"):
        derive_velocities(np.array([0.0, 0.1]), np.zeros((2, 1)), floating_base=False)
