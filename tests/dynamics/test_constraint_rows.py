"""The constraint rows of one kinematics pass: the inner loops' reuse of the last state's rows
(read-only, recomputed for any other state, each thread its own) against fresh computations,
and the rows against the per-constraint algebra fed with Pinocchio's frame calls."""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pinocchio as pin
import pytest

from robodyn.constraints import FrameAnchor, PointContact
from robodyn.constraints.algebra import EndKinematics, stack, world_end
from robodyn.dynamics import constrained
from tests.constraints.linkages import load_linkage


@pytest.fixture(scope="module")
def linkage():
    robot = load_linkage("four_bar_3d")
    extra = [FrameAnchor("crank", (0.01, 0.02, 0.03, 0.1, 0.2, 0.3)), PointContact("rocker", (0.1, 0.0, 0.0), friction=0.4)]
    return robot, constrained.bound(robot, [*robot.constraints, *extra])


def per_end(robot, bounds, q, v):
    """The rows the way they were computed before one pass a state: each end from its link's
    Pinocchio frame, shifted to its point, then stacked constraint by constraint."""
    model, data = robot.model, pin.Model.createData(robot.model)
    pin.forwardKinematics(model, data, q, v, np.zeros(robot.nv))
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)

    def kinematics(end):
        if end.link is None:
            return world_end(end, robot.nv)
        index = robot.handle.frames[end.link]
        placement, world = data.oMf[index], pin.LOCAL_WORLD_ALIGNED
        lever = placement.rotation @ end.position
        jacobian = pin.getFrameJacobian(model, data, index, world)
        acceleration = pin.getFrameClassicalAcceleration(model, data, index, world)
        omega, alpha = jacobian[3:] @ v, acceleration.angular
        return EndKinematics(
            placement.translation + lever,
            placement.rotation @ end.rotation,
            jacobian[:3] - pin.skew(lever) @ jacobian[3:],
            jacobian[3:],
            acceleration.linear + np.cross(alpha, lever) + np.cross(omega, np.cross(omega, lever)),
            alpha,
        )

    return stack(bounds, kinematics, robot.nv)


def test_the_rows_are_the_per_end_rows_and_a_wrong_lever_is_caught(linkage, rng):
    robot, bounds = linkage
    for _ in range(3):
        q, v = robot.random_configuration(rng), rng.normal(size=robot.nv)
        for ours, theirs in zip(constrained.state_rows(robot, bounds, q, v), per_end(robot, bounds, q, v), strict=True):
            assert np.allclose(ours, theirs, rtol=0.0, atol=1e-12)
    # the check can fail: the contact's point moved by 1 cm along its link gives other rows
    moved = constrained.bound(robot, [*robot.constraints, PointContact("rocker", (0.11, 0.0, 0.0), friction=0.4)])
    assert not np.allclose(constrained.state_rows(robot, moved, q, v)[1][-3:], per_end(robot, bounds, q, v)[1][-3:], atol=1e-4)


def test_the_same_state_gives_the_same_read_only_rows_and_another_state_new_ones(linkage, rng):
    robot, bounds = linkage
    q, v = robot.random_configuration(rng), rng.normal(size=robot.nv)
    first = constrained.state_rows(robot, bounds, q, v)
    again = constrained.state_rows(robot, bounds, q.copy(), v.copy())
    assert all(a is b for a, b in zip(first, again, strict=True))
    assert not any(array.flags.writeable for array in first)
    with pytest.raises(ValueError):
        first[1][0, 0] = 1.0
    other_v = constrained.state_rows(robot, bounds, q, v + 1.0)
    fresh = constrained.end_frames(robot, bounds).compute(q, v + 1.0)
    assert other_v[2] is not first[2] and np.array_equal(other_v[2], fresh[2]) and not np.allclose(other_v[2], first[2])
    assert fresh[1].flags.writeable  # what the public functions return is the caller's own
    tau = rng.normal(size=robot.nv)
    a, _ = constrained.forward_dynamics_unchecked(robot, bounds, q, v, tau)
    assert constrained.forward_dynamics_unchecked(robot, bounds, q, v, tau.copy())[0] is a
    moved = constrained.forward_dynamics_unchecked(robot, bounds, q, v, tau + 1.0)
    assert np.array_equal(moved[0], robot.constrained_forward_dynamics(q, v, tau + 1.0, [b.constraint for b in bounds])[0])


def test_threads_each_keep_their_own_state(linkage, rng):
    robot, bounds = linkage
    states = [(robot.random_configuration(rng), rng.normal(size=robot.nv)) for _ in range(24)]
    serial = [per_end(robot, bounds, q, v) for q, v in states]

    def rows(state):
        q, v = state
        return [np.array(row) for row in constrained.state_rows(robot, bounds, q, v)]

    with ThreadPoolExecutor(3) as pool:
        threaded = list(pool.map(rows, states * 5))
    for index, result in enumerate(threaded):
        for ours, theirs in zip(result, serial[index % len(states)], strict=True):
            assert np.allclose(ours, theirs, rtol=0.0, atol=1e-12)


def test_no_constraint_gives_rows_of_no_length_and_the_free_dynamics(linkage, rng):
    robot, _ = linkage
    q, v, tau = robot.random_configuration(rng), rng.normal(size=robot.nv), rng.normal(size=robot.nv)
    phi, jacobian, drift = constrained.end_frames(robot, ()).compute(q, v)
    assert (phi.shape, jacobian.shape, drift.shape) == ((0,), (0, robot.nv), (0,))
    batch = np.array([q, robot.random_configuration(rng)])
    assert robot.constraint_residual(batch, []).shape == (2, 0)
    assert robot.constraint_jacobian(batch, []).shape == (2, 0, robot.nv)
    assert robot.constraint_drift(batch, np.zeros((2, robot.nv)), []).shape == (2, 0)
    a, lam = robot.constrained_forward_dynamics(q, v, tau, [])
    assert lam.shape == (0,) and np.allclose(a, robot.forward_dynamics(q, v, tau), rtol=1e-12, atol=1e-12)
    # the check can fail: with the linkage's own loop the accelerations differ
    assert not np.allclose(robot.constrained_forward_dynamics(q, v, tau)[0], a, atol=1e-6)
