"""The numeric boundary: bad state vectors raise InputError naming the argument."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import robodyn
from robodyn import InputError
from tests.conftest import ROOT, random_state


@pytest.fixture(scope="module")
def robot():
    return robodyn.load("rp_arm")


@pytest.mark.parametrize(
    ("call", "argument", "fragment"),
    [
        (lambda r: r.inverse_dynamics([0.1], [0, 0], [0, 0]), "q", "2 values, got 1 values"),
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
