"""A Robot used from several threads at once gives each thread its own, right answers."""

from __future__ import annotations

import threading
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import robodyn
from robodyn.dynamics.loading import rebuild
from robodyn.exceptions import InputError


@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_concurrent_calls_equal_serial_calls(name):
    robot = robodyn.load(name)
    rng = np.random.default_rng(3)
    q = robot.random_configuration(rng, 64)
    v = rng.normal(size=(64, robot.nv))
    a = rng.normal(size=(64, robot.nv))
    serial = [
        (robot.inverse_dynamics(*s), robot.mass_matrix(s[0]), robot.frame_jacobian(s[0], robot.frame_names[-1]))
        for s in zip(q, v, a, strict=True)
    ]

    def work(index: int):
        results = []
        for _ in range(20):
            i = (index * 7 + _) % 64
            results.append(
                (
                    i,
                    robot.inverse_dynamics(q[i], v[i], a[i]),
                    robot.mass_matrix(q[i]),
                    robot.frame_jacobian(q[i], robot.frame_names[-1]),
                )
            )
        return results

    with ThreadPoolExecutor(max_workers=4) as pool:
        for results in pool.map(work, range(16)):
            for i, tau, mass, jacobian in results:
                np.testing.assert_array_equal(tau, serial[i][0])
                np.testing.assert_array_equal(mass, serial[i][1])
                np.testing.assert_array_equal(jacobian, serial[i][2])


def test_each_thread_has_its_own_data():
    robot = robodyn.load("rp_arm")
    barrier = threading.Barrier(2)

    def data_id(_):
        data = robot.data
        barrier.wait()  # both threads alive at once: their data objects coexist
        return id(data), data

    with ThreadPoolExecutor(max_workers=2) as pool:
        results = list(pool.map(data_id, range(2)))
    assert len({identity for identity, _ in results}) == 2
    assert all(data is not robot.data for _, data in results)


def test_threads_option_and_batch_results():
    robot = robodyn.load("ur5", threads=1)
    assert robot.threads == 1
    rng = np.random.default_rng(0)
    q = robot.random_configuration(rng, 10)
    v = rng.normal(size=(10, robot.nv))
    batch = robot.inverse_dynamics(q, v, v)
    np.testing.assert_allclose(batch, [robot.inverse_dynamics(*s) for s in zip(q, v, v, strict=True)], rtol=1e-12, atol=1e-12)
    with pytest.raises(robodyn.InputError, match="threads"):
        robodyn.load("ur5", threads=0)


def test_rebuild_is_an_independent_copy_with_the_same_options():
    robot = robodyn.load("ur5", gravity=(1.0, 0.0, -3.0), threads=1)
    copy = rebuild(robot)
    assert copy is not robot and copy.model is not robot.model
    assert copy.options == robot.options
    q = robot.random_configuration(np.random.default_rng(1))
    np.testing.assert_array_equal(copy.gravity(q), robot.gravity(q))


@pytest.mark.parametrize(("norms", "named"), [((1.0, 0.3, 1.2), "0.3"), ((1.0, 0.8, 1.5), "1.5")])
def test_a_batch_of_floating_states_names_the_quaternion_farthest_from_unit(norms, named):
    """The refusal quotes the row whose quaternion norm is farthest from 1 (not the largest
    norm, not the smallest): found by mutation testing, where only one-state refusals were checked."""
    robot = robodyn.load("solo12")
    q = np.tile(robot.neutral_configuration(), (len(norms), 1))
    q[:, 3:7] *= np.asarray(norms)[:, None]
    with pytest.raises(InputError) as raised:
        robot.gravity(q)
    assert raised.value.argument == "q[3:7]" and f"norm {named}" in str(raised.value), str(raised.value)
