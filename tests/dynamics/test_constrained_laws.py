"""Constrained dynamics' laws the comparisons with Pinocchio do not reach: the rank of a set
at any scale, the given set used (not the robot's own), a batch refused where one state is
asked."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn.constraints import PointContact
from robodyn.dynamics import constrained
from robodyn.exceptions import InputError
from tests.constraints.linkages import load_linkage

FEET = ["FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"]


@pytest.fixture(scope="module")
def solo():
    robot = robodyn.load("solo12", gravity=(0.3, -0.2, -9.7))
    q = robot.neutral_configuration()
    q[2] = 0.3
    q[7:] = np.tile([0.1, 0.8, -1.6], 4)
    return robot, q


@pytest.mark.parametrize("scale", [1e-12, 1.0, 1e6])
def test_the_rank_counts_independent_rows_whatever_the_jacobians_scale(solo, scale, monkeypatch):
    # four feet: 12 independent rows; a fifth contact on a foot already held adds 3 rows that
    # repeat it (its singular values are round-off, not 0): still 12, at any unit of length
    robot, q = solo
    feet = [PointContact(foot, friction=0.7) for foot in FEET]
    jacobian = constrained.constraint_jacobian
    monkeypatch.setattr(constrained, "constraint_jacobian", lambda *args: scale * jacobian(*args))
    assert constrained.constraint_rank(robot, q, feet) == 12
    assert constrained.constraint_rank(robot, q, [*feet, PointContact(FEET[0], friction=0.7)]) == 12
    # the count can be other than 12: two feet, and one frictionless row
    assert constrained.constraint_rank(robot, q, feet[:2]) == 6
    assert constrained.constraint_rank(robot, q, PointContact(FEET[1], friction=0.0)) == 1


def test_the_rank_is_of_the_given_constraints_and_of_one_configuration(rng):
    robot = load_linkage("four_bar_3d")
    q = robot.random_configuration(rng)
    assert (
        robot.constraint_rank(q) >= 2
    )  # its loop: two rows at least (the closed form's check: tests/dynamics/test_constrained.py)
    assert robot.constraint_rank(q, []) == 0
    assert robot.constraint_rank(q, PointContact("rocker", (0.1, 0.05, 0.02), normal=(0.6, 0.0, 0.8), friction=0.0)) == 1
    with pytest.raises(InputError):
        robot.constraint_rank(np.array([q, q]))


def test_contact_inverse_dynamics_of_a_fully_actuated_robot_is_its_inverse_dynamics_with_no_multipliers(rng):
    robot = load_linkage("four_bar")  # every joint actuated: the loop carries nothing
    q, v, a = (rng.normal(size=(4, robot.nv)) for _ in range(3))
    tau, lam = robot.contact_inverse_dynamics(q, v, a)
    assert np.array_equal(lam, np.zeros((4, 3)))
    assert np.allclose(tau, robot.inverse_dynamics(q, v, a), rtol=1e-12, atol=1e-12)
    empty = np.zeros((0, robot.nv))
    assert [array.shape for array in robot.contact_inverse_dynamics(empty, empty, empty)] == [(0, 3), (0, 3)]


def _one_foot_unbalance(jacobian, mass, direction):
    """``max |Sᵤ (M d − Jᵀ λ)|`` for the least-squares ``λ`` (NumPy's own solve): the unbalance
    of the acceleration ``d`` with one foot held, at rest and without gravity."""
    force = mass @ direction
    lam = np.linalg.lstsq(jacobian.T[:6], force[:6], rcond=None)[0]
    return np.abs(force[:6] - jacobian.T[:6] @ lam).max()


@pytest.mark.parametrize("large", [False, True], ids=["forces below 1 N", "forces of 1e4 N"])
def test_the_unbalance_threshold_binds_at_1e_8_of_the_largest_force_and_at_least_1e_8(large, rng):
    robot = robodyn.load("solo12", gravity=(0.0, 0.0, 0.0))
    q = robot.neutral_configuration()
    q[2], q[7:] = 0.3, np.tile([0.1, 0.8, -1.6], 4)
    foot, zero = PointContact(FEET[0], friction=0.7), np.zeros(robot.nv)
    jacobian, mass = robot.constraint_jacobian(q, foot), robot.mass_matrix(q)
    direction = rng.normal(size=robot.nv)
    unbalance = _one_foot_unbalance(jacobian, mass, direction)
    # a reachable part (M⁻¹ Jᵀ μ: the foot pushes) makes the forces large without unbalance
    reachable = np.linalg.solve(mass, jacobian.T @ rng.normal(size=3))
    reachable *= (1e4 if large else 0.0) / np.abs(mass @ reachable).max()
    for ratio, accepted in ((0.5, True), (1.5, False)):
        scale = 1.0
        for _ in range(3):  # the threshold depends a little on the unbalanced part's own forces
            largest = np.abs(mass @ (reachable + scale * direction)).max()
            scale = ratio * 1e-8 * max(1.0, largest) / unbalance
        a = reachable + scale * direction
        assert np.isclose(_one_foot_unbalance(jacobian, mass, a), ratio * 1e-8 * max(1.0, largest), rtol=1e-3)
        if accepted:
            tau, lam = robot.contact_inverse_dynamics(q, zero, a, foot)
            assert np.all(tau[:6] == 0.0) and np.allclose(mass @ a, tau + jacobian.T @ lam, rtol=0, atol=1e-7 * max(1.0, largest))
        else:
            with pytest.raises(InputError) as refused:
                robot.contact_inverse_dynamics(q, zero, a, foot)
            assert str(refused.value) == (
                "a must be an acceleration the constraints and the actuated joints can produce, got "
                f"{ratio * 1e-8 * max(1.0, largest):.3g} unbalanced on the unactuated coordinates."
            )


def test_a_massless_joint_is_refused_naming_the_robot_and_the_joint(tmp_path):
    text = robodyn.rp_arm_urdf().replace(
        "</robot>",
        '<joint name="finger" type="revolute"><parent link="link2"/><child link="tip"/><axis xyz="0 0 1"/>'
        '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint><link name="tip"/></robot>',
    )
    (tmp_path / "arm.urdf").write_text(text)
    robot = robodyn.load(tmp_path / "arm.urdf")
    wall = PointContact("end_effector", normal=(-1.0, 0.0, 0.0), friction=0.0, plane_point=(0.8, 0.0, 0.0))
    with pytest.raises(robodyn.SingularMassMatrixError) as refused:
        robot.constrained_forward_dynamics(np.zeros(3), np.zeros(3), np.zeros(3), wall)
    assert str(refused.value).startswith(f"robot {robot.name!r}: the mass matrix is singular") and "'finger'" in str(
        refused.value
    )


def test_an_overflow_is_refused_naming_the_robot_and_the_computation():
    from robodyn.constraints import PointAnchor
    from robodyn.exceptions import NonFiniteResultError

    robot = load_linkage("four_bar")
    huge = [PointAnchor("coupler", (1e308, 0, 0), "rocker", (0.3, 0, 0))]
    with pytest.raises(NonFiniteResultError) as refused:
        robot.constrained_forward_dynamics(np.zeros(3), np.ones(3), np.zeros(3), huge)
    assert str(refused.value) == f"robot {robot.name!r}: constrained dynamics overflowed to a non-finite value for finite inputs."
