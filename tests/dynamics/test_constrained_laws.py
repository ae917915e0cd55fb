"""Constrained dynamics' laws the comparisons with Pinocchio do not reach: the rank of a set
at any scale, the given set used (not the robot's own), a batch refused where one state is
asked."""

from __future__ import annotations

import warnings

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
    with pytest.raises(InputError, match=r"must be a link of robot 'four_bar_3d' \("):
        robot.constraint_rank(q, PointContact("nowhere", friction=0.0))


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


def test_an_overflow_is_refused_naming_the_robot_and_the_computation_without_a_warning():
    from robodyn.constraints import PointAnchor
    from robodyn.exceptions import NonFiniteResultError

    robot = load_linkage("four_bar")
    sentence = f"robot {robot.name!r}: constrained dynamics overflowed to a non-finite value for finite inputs."
    huge = [PointAnchor("coupler", (1e308, 0, 0), "rocker", (0.3, 0, 0))]  # the Delassus matrix's solver fails
    overflowing = ((np.zeros(3), np.ones(3), np.zeros(3), huge), (np.zeros(3), np.ones(3), np.array([0.0, 0.0, 1e308])))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # refused, not warned about
        for arguments in (*overflowing, (np.zeros(3), np.ones(3), np.array([0.0, 0.0, 1e308]), [])):  # the last: λ empty
            with pytest.raises(NonFiniteResultError) as refused:
                robot.constrained_forward_dynamics(*arguments)
            assert str(refused.value) == sentence
    with (
        np.errstate(all="ignore"),
        pytest.raises(np.linalg.LinAlgError, match=r"^the Delassus matrix's eigendecomposition did not converge$"),
    ):
        constrained.solve_kkt(np.eye(2), np.ones(2), np.array([[np.inf, 1.0], [1.0, 2.0]]), np.ones(2))


@pytest.mark.parametrize("scale", [1e-4, 1.0, 1e4, 1e12])
def test_a_row_nearly_repeating_another_shares_its_force_whatever_the_robots_mass(solo, scale, rng):
    # the four feet's 12 rows and a foot's 3 rows again, off by 1e-7 of J's largest entry (a
    # stand-in Jacobian): the Delassus matrix's Cholesky factorisation succeeds (its smallest
    # eigenvalues are 1e-13 of the largest, not round-off), but they are below the tolerance:
    # the least-norm λ shares the foot's force equally. M and the forces scaled by k (a robot
    # k times heavier): v̇ the same, λ k times.
    robot, q = solo
    v, tau = rng.normal(size=robot.nv), rng.normal(size=robot.nv)
    mass, force = robot.mass_matrix(q), tau - robot.nonlinear_effects(q, v)
    feet = constrained.bound(robot, [PointContact(foot, friction=0.7) for foot in FEET])
    _, jacobian, drift = constrained.state_rows(robot, feet, q, v)
    again = jacobian[:3] + 1e-7 * np.abs(jacobian).max() * rng.normal(size=(3, robot.nv))
    a, lam = constrained.solve_kkt(scale * mass, scale * force, np.vstack([jacobian, again]), np.concatenate([drift, drift[:3]]))
    a_single, lam_single = constrained.solve_kkt(scale * mass, scale * force, jacobian, drift)
    size = np.abs(lam_single).max()
    assert np.allclose(a, a_single, rtol=0, atol=1e-5 * np.abs(a_single).max())
    assert np.allclose(lam[:3], lam[12:], rtol=0, atol=1e-5 * size)
    shared = lam[:12].copy()
    shared[:3] += lam[12:]
    assert np.allclose(shared, lam_single, rtol=0, atol=1e-5 * size)
    assert np.allclose(lam_single / scale, constrained.solve_kkt(mass, force, jacobian, drift)[1], rtol=1e-9, atol=1e-12 * size)
    # the check can fail: the foot's force all on one of its two contacts
    assert not np.allclose(lam[:3], lam_single[:3], rtol=0, atol=1e-3 * size)


def test_the_inner_loops_dynamics_refuse_a_mass_matrix_without_a_cholesky_factor_naming_the_robot(tmp_path):
    text = robodyn.rp_arm_urdf().replace(
        "</robot>",
        '<joint name="finger" type="revolute"><parent link="link2"/><child link="tip"/><axis xyz="0 0 1"/>'
        '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint><link name="tip"/></robot>',
    )
    (tmp_path / "arm.urdf").write_text(text)
    robot = robodyn.load(tmp_path / "arm.urdf")
    with pytest.raises(robodyn.SingularMassMatrixError, match=f"^robot {robot.name!r}: the mass matrix is singular"):
        constrained.forward_dynamics_unchecked(robot, (), np.zeros(3), np.zeros(3), np.zeros(3))


def test_the_kkt_solve_refuses_a_mass_matrix_that_is_not_positive_definite_and_takes_no_coordinate():
    with pytest.raises(robodyn.SingularMassMatrixError) as refused:
        constrained.solve_kkt(-np.eye(2), np.ones(2), np.ones((1, 2)), np.ones(1))
    assert refused.value.joints == [] and str(refused.value) == (
        "robot 'robot': the mass matrix is singular, so forward dynamics is undefined (the accelerations are not finite)."
    )
    a, lam = constrained.solve_kkt(np.zeros((0, 0)), np.zeros(0), np.zeros((2, 0)), np.zeros(2))
    assert (a.shape, lam.shape) == ((0,), (2,)) and not lam.any()


def test_a_mass_matrix_without_a_cholesky_factor_is_refused_naming_the_joints_that_move_no_inertia(monkeypatch):
    # the neck's mass matrix at its singular configuration, less 1e-9: its Cholesky
    # factorisation fails (a round-off pivot of the exact one is positive: refused after)
    from tests.dynamics.test_inertia_rank_refusals import NECK, TAU

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        neck = robodyn.load(NECK, gravity=(0.4, -0.3, -9.6))
    exact = neck.mass_matrix
    monkeypatch.setattr(neck, "mass_matrix", lambda q: exact(q) - 1e-9 * np.eye(2))
    with pytest.raises(robodyn.SingularMassMatrixError) as refused:
        neck.constrained_forward_dynamics(np.zeros(2), np.zeros(2), TAU, constraints=[])
    assert refused.value.joints == ["nod", "pitch"] and str(refused.value).startswith("robot 'neck': ")


def test_a_constraint_on_a_link_no_joint_moves_carries_no_force(rng):
    robot = load_linkage("four_bar")
    q, v, tau = robot.random_configuration(rng), rng.normal(size=3), rng.normal(size=3)
    a = robot.constrained_forward_dynamics(q, v, tau)[0]
    a_base, lam_base = robot.constrained_forward_dynamics(q, v, tau, [PointContact("base", friction=0.0)])
    assert np.array_equal(lam_base, [0.0]) and np.allclose(a_base, robot.forward_dynamics(q, v, tau), rtol=1e-12, atol=1e-12)
    assert not np.allclose(a_base, a, atol=1e-6)  # the check can fail: the loop's own rows do act
