"""The numeric boundary: bad state vectors raise InputError naming the argument."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn import InputError


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
        (lambda r: r.mass_matrix("zero"), "q", "an array of 2 numbers"),
        (lambda r: r.gravity(["a", "b"]), "q", "an array of 2 numbers"),
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
