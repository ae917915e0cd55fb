"""The shape rule: 1-D in gives one result, 2-D in (one state a row) gives a stack."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from tests.conftest import random_state


@pytest.fixture(scope="module", params=["panda", "rp_arm", "solo12"])
def robot(request):
    return robodyn.load(request.param)


METHODS = {
    "inverse_dynamics": lambda r, q, v, a: r.inverse_dynamics(q, v, a),
    "forward_dynamics": lambda r, q, v, a: r.forward_dynamics(q, v, a),
    "mass_matrix": lambda r, q, v, a: r.mass_matrix(q),
    "coriolis_matrix": lambda r, q, v, a: r.coriolis_matrix(q, v),
    "gravity": lambda r, q, v, a: r.gravity(q),
    "nonlinear_effects": lambda r, q, v, a: r.nonlinear_effects(q, v),
    "kinetic_energy": lambda r, q, v, a: r.kinetic_energy(q, v),
    "potential_energy": lambda r, q, v, a: r.potential_energy(q),
    "frame_position": lambda r, q, v, a: r.frame_position(q, r.spec.root),
    "frame_jacobian": lambda r, q, v, a: r.frame_jacobian(q, r.spec.root),
}


@pytest.mark.parametrize("method", METHODS)
def test_batch_equals_row_by_row(robot, method, rng):
    call = METHODS[method]
    q, v, a = random_state(robot, rng, 7)
    stacked = call(robot, q, v, a)
    rows = np.stack([np.asarray(call(robot, q[i], v[i], a[i])) for i in range(7)])
    assert np.shape(stacked) == rows.shape
    np.testing.assert_allclose(stacked, rows, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("method", METHODS)
def test_one_row_gives_a_stack_of_one(robot, method, rng):
    call = METHODS[method]
    q, v, a = random_state(robot, rng, 1)
    single = np.asarray(call(robot, q[0], v[0], a[0]))
    assert np.shape(call(robot, q, v, a)) == (1, *single.shape)


@pytest.mark.parametrize("method", METHODS)
def test_zero_rows_give_an_empty_stack(robot, method, rng):
    call = METHODS[method]
    q, v, a = random_state(robot, rng, 1)
    single = np.asarray(call(robot, q[0], v[0], a[0]))
    assert np.shape(call(robot, q[:0], v[:0], a[:0])) == (0, *single.shape)


def test_batch_accepts_non_contiguous_views(robot, rng):
    q, v, a = random_state(robot, rng, 6)
    expected = robot.inverse_dynamics(q[::2], v[::2], a[::2])
    np.testing.assert_allclose(expected, np.stack([robot.inverse_dynamics(q[i], v[i], a[i]) for i in (0, 2, 4)]), atol=1e-12)
