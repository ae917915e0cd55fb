"""PD gains scaled to each joint's inertia: stable at a millisecond on a light wrist.

The checks are physical: the closed loop of one joint, ``m ë + kd ė + kp e = 0``, is
critically damped at 10 rad/s whatever ``m``; RK4 holds a real pole ``λ`` only while
``|λ| dt ≤ 2.78``, which fixed gains break on the student's wrist (the negative control).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import robodyn
from robodyn.exceptions import InputError
from robodyn.sim.experiment import run_simulation
from robodyn.sim.gains import joint_inertia, pd_gains

STUDENT_ARM = Path(__file__).parents[1] / "data" / "robots" / "student_arm.urdf"
TARGET = [0.5, -0.5, 0.3, 0.05, 0.02]
#: RK4's stability limit on the negative real axis, |λ| dt.
RK4_REAL_LIMIT = 2.785


@pytest.fixture(scope="module")
def arm():
    return robodyn.load(STUDENT_ARM)


def _fastest_pole(inertia: np.ndarray, kp: np.ndarray, kd: np.ndarray) -> float:
    """The largest |λ| of ``m s² + kd s + kp`` over the joints, in [1/s]."""
    return max(float(np.abs(np.roots([m, d, k])).max()) for m, k, d in zip(inertia, kp, kd, strict=True))


def test_the_default_gains_put_every_joint_at_a_critically_damped_ten_radians_per_second(arm):
    q = np.array(TARGET)
    inertia = np.diag(arm.mass_matrix(q))
    kp, kd = pd_gains(arm, q)
    np.testing.assert_allclose(np.sqrt(kp / inertia), 10.0, rtol=1e-12)
    np.testing.assert_allclose(kd / (2 * np.sqrt(kp * inertia)), 1.0, rtol=1e-12)
    assert inertia[-1] == pytest.approx(0.0046, rel=1e-9)  # the light wrist the defaults must hold
    assert _fastest_pole(inertia, kp, kd) * 1e-3 < RK4_REAL_LIMIT
    fixed = np.full(5, 100.0), np.full(5, 20.0)  # negative control: the old fixed gains
    assert _fastest_pole(inertia, *fixed) * 1e-3 > RK4_REAL_LIMIT


def test_the_student_arm_settles_under_default_pd_at_one_millisecond(arm):
    trajectory, summary = run_simulation(arm, controller="pd", target=TARGET, dt=1e-3, joint_friction=False)
    assert summary.final_joint_error < 1e-5 and np.isfinite(trajectory.q).all()


def test_a_given_kp_gets_the_critical_kd_and_a_given_kd_keeps_the_default_kp(arm):
    q = np.array(TARGET)
    inertia = joint_inertia(arm, q)
    kp, kd = pd_gains(arm, q, kp=4.0)
    np.testing.assert_allclose(kd, 2 * np.sqrt(4.0 * inertia), rtol=1e-12)
    kp, kd = pd_gains(arm, q, kd=[1, 2, 3, 4, 5])
    np.testing.assert_allclose(kp, 100 * inertia, rtol=1e-12)
    np.testing.assert_array_equal(kd, [1, 2, 3, 4, 5])


def test_the_inertia_over_several_configurations_is_each_joints_largest(arm):
    start, goal = np.zeros(5), np.array(TARGET)
    both = joint_inertia(arm, np.array([start, goal]))
    np.testing.assert_array_equal(both, np.maximum(np.diag(arm.mass_matrix(start)), np.diag(arm.mass_matrix(goal))))
    assert both[0] > np.diag(arm.mass_matrix(start))[0] * 5  # the base's yaw inertia grows as the arm leans out


def test_a_floating_robots_joint_inertia_is_with_the_base_free():
    robot = robodyn.load("solo12")
    q = robot.neutral_configuration()
    mass = robot.mass_matrix(q)
    held = np.diag(mass)[6:]
    free = joint_inertia(robot, q)
    assert free.shape == (robot.nv - 6,) and (free <= held + 1e-15).all() and (free < held).any()


@pytest.mark.parametrize(
    ("gains", "message"),
    [({"kp": [1.0, 2.0]}, "2 values"), ({"kd": -1.0}, "-1"), ({"kp": float("nan")}, "nan"), ({"kd": "soft"}, "nan")],
)
def test_bad_gains_are_refused_naming_the_gain(arm, gains, message):
    with pytest.raises(InputError, match=f"^{next(iter(gains))} must be.*{message}"):
        pd_gains(arm, np.zeros(5), **gains)


def test_gains_are_refused_with_a_controller_that_does_not_take_them(arm):
    with pytest.raises(InputError, match=r"^kp must be given only with the pd or computed-torque controller"):
        run_simulation(arm, controller="passive", kp=1.0)


def test_one_driven_joint_feels_the_inertia_with_the_others_giving_way(arm):
    """With only the first joint driven its inertia is 1 / (M⁻¹)₀₀ (the others free), the
    undriven ones keep M_jj; the default kp follows the same inertia."""
    q = np.linspace(0.3, -0.4, arm.nq)
    driven = np.zeros(arm.nv, dtype=int)
    driven[0] = 1  # integers, as a user may pass them
    mass = arm.mass_matrix(q)
    expected = np.diag(mass).copy()
    expected[0] = 1.0 / np.linalg.inv(mass)[0, 0]
    assert expected[0] < mass[0, 0] * (1 - 1e-3)  # negative control: the coupling matters here
    assert np.allclose(joint_inertia(arm, list(q), driven), expected, rtol=1e-10)
    kp, _ = pd_gains(arm, q, driven=driven)
    assert np.allclose(kp, 100.0 * expected, rtol=1e-10)


def test_a_zero_or_small_gain_is_accepted(arm):
    q = np.zeros(arm.nq)
    for gain in (0.0, 0.5):
        kp, kd = pd_gains(arm, q, kp=gain, kd=gain)
        assert np.array_equal(kp, np.full(kp.size, gain)) and np.array_equal(kd, np.full(kd.size, gain))
