"""Family 6 of issue #14 (the library part): every remaining traceback becomes one error."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import robodyn
from robodyn.common.inputs import as_state
from robodyn.exceptions import InputError, RobodynWarning


@pytest.fixture(scope="module")
def arm():
    return robodyn.load("rp_arm")


@pytest.mark.parametrize(
    "lock",
    [{"joint2": "0.1"}, {"joint2": None}, {"joint2": True}, {"joint2": [0.1]}, {"joint2": 0.1 + 0j}, {3: 0.1}, {"joint9": 0.1}],
)
def test_lock_values_that_are_not_numbers_are_input_errors(lock):
    with pytest.raises(InputError) as raised:
        robodyn.load("rp_arm", lock=lock)
    assert "\n" not in str(raised.value)


def test_lock_accepts_numpy_numbers_and_suggests_names():
    assert robodyn.load("rp_arm", lock={"joint2": np.float32(0.125)}).nv == 1
    with pytest.raises(InputError, match="did you mean 'joint2'"):
        robodyn.load("rp_arm", lock={"joint_2": 0.1})


@pytest.mark.parametrize(
    "q", [[0.1 + 0j, 0.2], np.array([0.1, 0.2], dtype=complex), ["0.1", "0.2"], [True, False], [[0.1], [0.2, 0.3]]]
)
def test_complex_strings_and_booleans_are_refused_not_converted(arm, q):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no numpy warning is printed on the way
        with pytest.raises(InputError, match="real numbers"):
            arm.inverse_dynamics(q, [0, 0], [0, 0])


def test_numbers_that_overflow_float64_are_refused_without_a_warning():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(InputError):
            as_state([10**400, 1], "q", 2)
        with pytest.raises(InputError, match="finite"):
            as_state([1e308 * 10, 1], "q", 2)


def test_real_number_types_still_work(arm):
    from fractions import Fraction

    expected = arm.inverse_dynamics([0.1, 0.2], [0, 0], [0, 0])
    for q in ([Fraction(1, 10), 0.2], np.array([0.1, 0.2], dtype=np.float32).astype(float), (0.1, 0.2)):
        np.testing.assert_allclose(arm.inverse_dynamics(q, [0, 0], [0, 0]), expected, rtol=1e-7)


def test_integrate_refuses_a_zero_quaternion():
    robot = robodyn.load("rp_arm", floating_base=True)
    q = np.array(robot.neutral_configuration(), dtype=float)
    v = np.zeros(robot.nv)
    np.testing.assert_allclose(robot.integrate(q, v), q)
    q[3:7] = 0.0
    with pytest.raises(InputError, match="unit quaternion"):
        robot.integrate(q, v)
    with pytest.raises(InputError):
        robot.integrate(np.full(robot.nq, np.nan), v)


def test_integrate_of_a_fixed_base_checks_sizes(arm):
    np.testing.assert_allclose(arm.integrate([0.1, 0.2], [0.5, -0.1]), [0.6, 0.1])
    with pytest.raises(InputError):
        arm.integrate([0.1, 0.2, 0.3], [0, 0])


def test_strict_load_turns_warnings_into_errors_and_default_shows_them():
    text = robodyn.rp_arm_urdf().replace(
        '<inertia ixx="0.00041666666666666675" ixy="0" ixz="0" iyy="0.013541666666666669" iyz="0" izz="0.013541666666666669"/>',
        '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.03"/>',
    )
    with pytest.warns(RobodynWarning, match='link "link2"'):
        robodyn.load(text)
    with pytest.raises(robodyn.URDFError, match="triangle inequality"):
        robodyn.load(text, strict=True)
    with warnings.catch_warnings():  # check_inertia=False: the user asked, no warning
        warnings.simplefilter("error", RobodynWarning)
        robodyn.load(text, check_inertia=False)


def test_negative_mass_non_psd_and_nan_stay_errors_with_check_inertia():
    good = robodyn.rp_arm_urdf()
    for old, new in (
        ('<mass value="1.0"/>', '<mass value="-1.0"/>'),
        ('ixy="0" ixz="0" iyy="0.013541666666666669"', 'ixy="0.5" ixz="0" iyy="0.013541666666666669"'),
        ('<mass value="1.0"/>', '<mass value="nan"/>'),
    ):
        with pytest.raises(robodyn.URDFError):
            robodyn.load(good.replace(old, new, 1))
