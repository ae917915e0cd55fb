"""The numeric boundary: bad state vectors raise InputError naming the argument.

Also here:

- Family 6 of issue #14 (the library part): every remaining traceback becomes one error.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import robodyn
from robodyn.common.inputs import as_state
from robodyn.exceptions import InputError, RobodynWarning
from tests.conftest import ROOT, random_state


@pytest.fixture(scope="module")
def robot():
    return robodyn.load("rp_arm")


@pytest.mark.parametrize(
    ("call", "argument", "fragment"),
    [
        (lambda r: r.inverse_dynamics([0.1], [0, 0], [0, 0]), "q", "2 values, got 1 value."),
        (lambda r: r.inverse_dynamics([0.1, 0.2], [0, 0, 0], [0, 0]), "v", "2 values, got 3"),
        (lambda r: r.inverse_dynamics([0.1, 0.2], [0, 0], [np.nan, 0]), "a", "finite, got nan at index 0"),
        (lambda r: r.forward_dynamics([0.1, 0.2], [0, 0], [0, np.inf]), "tau", "finite, got inf at index 1"),
        (lambda r: r.mass_matrix([[[0.1, 0.2]]]), "q", "3-D shape"),
        (lambda r: r.mass_matrix("zero"), "q", "an array of 2 real numbers"),
        (lambda r: r.gravity(["a", "b"]), "q", "an array of 2 real numbers"),
        (lambda r: r.coriolis_matrix([[0.1, 0.2]] * 3, [[0, 0]] * 2), "v", "3 rows like q"),
        (lambda r: r.nonlinear_effects([0.1, 0.2], [[0, 0]]), "v", "1-D like q"),
        (lambda r: r.gravity(np.full((4, 2), np.nan)), "q", "finite, got nan at index (0, 0)"),
    ],
)
def test_bad_input_names_the_argument(robot, call, argument, fragment):
    with pytest.raises(InputError) as raised:
        call(robot)
    assert raised.value.argument == argument
    assert str(raised.value).startswith(f"{argument} must be ")
    assert fragment in str(raised.value)
    assert len(str(raised.value)) < 160


def test_input_error_is_a_value_error(robot):
    with pytest.raises(ValueError):
        robot.gravity([1.0])


def test_unknown_frame_is_a_frame_error(robot):
    with pytest.raises(robodyn.FrameError, match="has no frame named 'tool'"):
        robot.frame_position([0, 0], "tool")


def test_integer_and_list_inputs_are_converted(robot):
    np.testing.assert_allclose(robot.gravity([0, 0]), robot.gravity(np.array([0.0, 0.0])))


def test_inputs_are_not_modified(robot):
    q = np.array([0.3, 0.1])
    before = q.copy()
    robot.inverse_dynamics(q, q, q)
    np.testing.assert_array_equal(q, before)


NON_FINITE_ROBOTS = ["rp_arm", "panda", "solo12", "double_pendulum_continuous", str(ROOT / "tests" / "data" / "gantry.urdf")]
CALLS = {
    "inverse_dynamics": (lambda r, q, v, a: r.inverse_dynamics(q, v, a), ("q", "v", "a")),
    "forward_dynamics": (lambda r, q, v, a: r.forward_dynamics(q, v, a), ("q", "v", "tau")),
    "mass_matrix": (lambda r, q, v, a: r.mass_matrix(q), ("q",)),
    "coriolis_matrix": (lambda r, q, v, a: r.coriolis_matrix(q, v), ("q", "v")),
    "gravity": (lambda r, q, v, a: r.gravity(q), ("q",)),
    "nonlinear_effects": (lambda r, q, v, a: r.nonlinear_effects(q, v), ("q", "v")),
    "kinetic_energy": (lambda r, q, v, a: r.kinetic_energy(q, v), ("q", "v")),
    "potential_energy": (lambda r, q, v, a: r.potential_energy(q), ("q",)),
}


@pytest.mark.parametrize("source", NON_FINITE_ROBOTS, ids=lambda s: Path(s).stem)
@pytest.mark.parametrize("method", CALLS)
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_a_non_finite_entry_anywhere_is_refused(source, method, bad, rng):
    """Every entry of every argument, one at a time: never a silent non-finite result."""
    robot = robodyn.load(source)
    call, names = CALLS[method]
    q, v, a = random_state(robot, rng)
    for position, name in enumerate(names):
        for index in range(robot.nq if name == "q" else robot.nv):
            arguments = [q.copy(), v.copy(), a.copy()]
            arguments[position][index] = bad
            with pytest.raises(InputError) as raised:
                call(robot, *arguments)
            assert raised.value.argument.startswith(name)


def test_floating_base_quaternion_must_be_unit(rng):
    robot = robodyn.load("solo12")
    q, v, a = random_state(robot, rng)
    q[3:7] *= 1.01
    with pytest.raises(InputError, match=r"q\[3:7\] must be a unit quaternion"):
        robot.inverse_dynamics(q, v, a)
    with pytest.raises(InputError, match=r"norm 1\.01"):
        robot.mass_matrix(np.stack([q, q]))


def test_consecutive_results_are_independent_arrays(robot):
    first = robot.inverse_dynamics([0.1, 0.1], [0, 0], [0, 0])
    kept = first.copy()
    robot.inverse_dynamics([1.0, 0.2], [1, 1], [1, 1])
    np.testing.assert_array_equal(first, kept)


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
