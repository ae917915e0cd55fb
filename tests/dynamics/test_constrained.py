"""Constrained dynamics on Robot: (v̇, λ) against Pinocchio's ``constraintDynamics`` called
directly, ``J`` and ``J̇ v`` against finite differences of ``Φ``, negative controls, the shape
rule, redundant and singular sets, and contact inverse dynamics of solo12 standing."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn.constraints import PointContact
from robodyn.dynamics import constrained
from robodyn.exceptions import InputError
from tests.constraints.linkages import (
    FOUR_BARS,
    closed_configuration,
    load_linkage,
    pinocchio_constraint_dynamics,
)

LINKAGES = [*FOUR_BARS, "slider_crank"]
TOLERANCE = 1e-9


def agreement(a: np.ndarray, lam: np.ndarray, a_ref: np.ndarray, lam_ref: np.ndarray) -> float:
    """The larger relative difference of accelerations and multipliers (the check every
    comparison here applies, negative controls included)."""
    return max(
        np.abs(a - a_ref).max() / max(np.abs(a_ref).max(), 1.0), np.abs(lam - lam_ref).max() / max(np.abs(lam_ref).max(), 1.0)
    )


def states(robot: robodyn.Robot, name: str, rng: np.random.Generator) -> list[tuple[np.ndarray, ...]]:
    """Random states, and for the four-bars closed ones moving along the loop (J v = 0)."""
    out = []
    for _ in range(3):
        out.append((robot.random_configuration(rng), rng.normal(size=robot.nv), rng.normal(size=robot.nv)))
    if name in FOUR_BARS:
        for crank in (0.4, 2.2, -1.9):
            q = closed_configuration(robot, name, crank)
            null = np.linalg.svd(robot.constraint_jacobian(q))[2][-1]
            out.append((q, 2.0 * null, rng.normal(size=robot.nv)))
    return out


@pytest.mark.parametrize("name", LINKAGES)
def test_accelerations_and_multipliers_agree_with_pinocchios_constraint_dynamics(name, rng):
    robot = load_linkage(name)
    for q, v, tau in states(robot, name, rng):
        a, lam = robot.constrained_forward_dynamics(q, v, tau)
        a_pin, lam_pin = pinocchio_constraint_dynamics(robot, robot.constraints, q, v, tau)
        assert agreement(a, lam, a_pin, lam_pin) < TOLERANCE


def test_a_wrong_sign_of_the_constraint_force_or_a_missing_drift_fails_the_same_check(rng):
    robot = load_linkage("four_bar_3d")
    q, v, tau = states(robot, "four_bar_3d", rng)[-1]
    a_pin, lam_pin = pinocchio_constraint_dynamics(robot, robot.constraints, q, v, tau)
    mass, bias = robot.mass_matrix(q), robot.nonlinear_effects(q, v)
    jacobian, drift = robot.constraint_jacobian(q), robot.constraint_drift(q, v)
    assert agreement(*constrained.solve_kkt(mass, tau - bias, jacobian, drift), a_pin, lam_pin) < TOLERANCE
    # M a = f − Jᵀ λ (with J a = −J̇ v): the same accelerations, the multipliers' sign flipped
    assert agreement(*constrained.solve_kkt(mass, tau - bias, -jacobian, -drift), a_pin, lam_pin) > 1e-3
    assert agreement(*constrained.solve_kkt(mass, tau - bias, jacobian, 0 * drift), a_pin, lam_pin) > 1e-3


@pytest.mark.parametrize("name", ["four_bar_3d", "slider_crank"])
def test_the_jacobian_and_drift_are_the_derivatives_of_the_residual(name, rng):
    robot = load_linkage(name)
    q, v = robot.random_configuration(rng), rng.normal(size=robot.nv)
    step = 1e-6
    numeric = np.array(
        [
            (robot.constraint_residual(q + step * e) - robot.constraint_residual(q - step * e)) / (2 * step)
            for e in np.eye(robot.nv)
        ]
    ).T
    assert np.allclose(robot.constraint_jacobian(q), numeric, atol=1e-8)
    second = (
        robot.constraint_residual(q + step * v) - 2 * robot.constraint_residual(q) + robot.constraint_residual(q - step * v)
    ) / step**2
    assert np.allclose(robot.constraint_drift(q, v), second, atol=2e-3 * max(1.0, np.abs(second).max()))
    step = 1e-5
    rate = (robot.constraint_jacobian(q + step * v) - robot.constraint_jacobian(q - step * v)) / (2 * step) @ v
    assert np.allclose(robot.constraint_drift(q, v), rate, atol=1e-7)


def test_a_batch_gives_the_stacked_one_state_results(rng):
    robot = load_linkage("parallelogram")
    count = 5
    q, v, tau = robot.random_configuration(rng, count), rng.normal(size=(count, 3)), rng.normal(size=(count, 3))
    a, lam = robot.constrained_forward_dynamics(q, v, tau)
    assert a.shape == (count, 3) and lam.shape == (count, 3)
    for row in range(count):
        a_one, lam_one = robot.constrained_forward_dynamics(q[row], v[row], tau[row])
        assert np.array_equal(a[row], a_one) and np.array_equal(lam[row], lam_one)
    assert robot.constraint_jacobian(q).shape == (count, 3, 3)
    assert robot.constraint_drift(q, v).shape == (count, 3)
    assert robot.constraint_residual(q).shape == (count, 3)


def test_a_redundant_row_is_reported_and_gives_finite_least_norm_multipliers(rng):
    robot = load_linkage("four_bar_3d")  # the loop's row along the joints' (oblique) axis repeats the others
    q = closed_configuration(robot, "four_bar_3d", 1.1)
    assert robot.constraint_rank(q) == 2
    a, lam = robot.constrained_forward_dynamics(q, np.zeros(3), np.zeros(3))
    normal = robot.constraint_jacobian(q)
    axis = np.linalg.svd(normal)[0][:, -1]  # the redundant direction of λ
    assert np.isfinite(a).all() and abs(axis @ lam) < 1e-9 * np.abs(lam).max()


def test_a_singular_configuration_never_gives_nan():
    robot = load_linkage("parallelogram")
    q = np.zeros(3)  # every bar on the ground line: the loop's rows lose rank
    a, lam = robot.constrained_forward_dynamics(q, np.zeros(3), np.ones(3))
    assert np.isfinite(a).all() and np.isfinite(lam).all()
    assert robot.constraint_rank(q) == 1


def test_a_mimic_robot_and_a_floating_base_take_constraints(rng):
    from pathlib import Path

    contacts = [PointContact("middle", (0.1, 0.0, 0.02), normal=(0.2, 0.1, 1.0), friction=0.0)]
    robot = robodyn.load(Path(__file__).parent.parent / "data" / "mimic_arm.urdf", constraints=contacts)
    q, v, tau = robot.random_configuration(rng), rng.normal(size=robot.nv), rng.normal(size=robot.nv)
    a, lam = robot.constrained_forward_dynamics(q, v, tau)
    assert np.allclose(robot.constraint_jacobian(q) @ a + robot.constraint_drift(q, v), 0.0, atol=1e-10)
    assert np.allclose(robot.mass_matrix(q) @ a + robot.nonlinear_effects(q, v), tau + robot.constraint_jacobian(q).T @ lam)


FEET = ["FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"]


def test_solo12_standing_on_four_feet_carries_its_weight_and_holds_still():
    robot = robodyn.load("solo12", gravity=(0.0, 0.0, -9.7))
    feet = [PointContact(foot, friction=0.7) for foot in FEET]
    q = robot.neutral_configuration()
    q[2] = 0.3
    q[7:] = np.tile([0.1, 0.8, -1.6], 4) * np.repeat([[1, 1, 1], [-1, 1, 1], [1, -1, -1], [-1, -1, -1]], 1, axis=0).ravel()
    zero = np.zeros(robot.nv)
    tau, lam = robot.contact_inverse_dynamics(q, zero, zero, feet)
    normals = lam.reshape(4, 3)[:, 2]
    weight = robot.total_mass * 9.7
    assert abs(normals.sum() - weight) < 1e-9 * weight
    assert np.all(tau[:6] == 0.0)
    a, lam_forward = robot.constrained_forward_dynamics(q, zero, tau, feet)
    assert np.abs(a).max() < 1e-9 and np.allclose(lam_forward, lam, atol=1e-9)


def test_contact_inverse_dynamics_refuses_an_unreachable_acceleration():
    robot = robodyn.load("solo12")
    zero = np.zeros(robot.nv)
    with pytest.raises(InputError, match="unactuated"):
        robot.contact_inverse_dynamics(robot.neutral_configuration(), zero, zero, [])


def test_an_overflow_is_refused_never_returned():
    from robodyn.constraints import PointAnchor
    from robodyn.exceptions import NonFiniteResultError

    robot = load_linkage("four_bar")
    huge = [PointAnchor("coupler", (1e308, 0, 0), "rocker", (0.3, 0, 0))]
    with pytest.raises(NonFiniteResultError):
        robot.constrained_forward_dynamics(np.zeros(3), np.ones(3), np.zeros(3), huge)


def test_a_weld_agrees_with_pinocchios_six_dimensional_constraint_on_the_weld(rng):
    """Pinocchio's 6-D constraint holds the relative twist at the first frame (and its
    spatial acceleration), robodyn's the velocities of the two frames' origins: the same
    where the weld holds (Φ = 0, J v = 0), which is where they are compared."""
    from robodyn.constraints import FrameAnchor
    from tests.constraints.linkages import DATA, GRAVITY

    weld = FrameAnchor("coupler", (0.05, 0.01, 0.0, 0.2, 0.0, 0.1), "crank", None, name="weld")
    robot = robodyn.load(DATA / "four_bar_3d.urdf", gravity=GRAVITY, constraints=[weld])
    welded = robot.joint_names.index("coupler_joint")
    for _ in range(3):
        q, v, tau = robot.random_configuration(rng), rng.normal(size=3), rng.normal(size=3)
        q[welded] = v[welded] = 0.0
        assert np.abs(robot.constraint_residual(q)).max() < 1e-15
        a, lam = robot.constrained_forward_dynamics(q, v, tau)
        assert agreement(a, lam, *pinocchio_constraint_dynamics(robot, [weld], q, v, tau)) < TOLERANCE


def test_an_empty_batch_gives_empty_stacks():
    robot = load_linkage("four_bar")
    empty = np.zeros((0, 3))
    a, lam = robot.constrained_forward_dynamics(empty, empty, empty)
    assert a.shape == (0, 3) and lam.shape == (0, 3)
    assert robot.constraint_jacobian(empty).shape == (0, 3, 3)
    assert robodyn.check_robot(robot, samples=0).passed


def _solo_standing(extra=()):
    robot = robodyn.load("solo12", gravity=(0.3, -0.2, -9.7))
    feet = [PointContact(foot, friction=0.7) for foot in FEET] + list(extra)
    q = robot.neutral_configuration()
    q[2] = 0.3
    q[7:] = np.tile([0.1, 0.8, -1.6], 4)
    return robot, constrained.bound(robot, feet), q


def test_a_full_rank_set_above_six_rows_solved_by_cholesky_is_the_eigendecompositions_solution(rng, monkeypatch):
    robot, bounds, q = _solo_standing()
    v, tau = rng.normal(size=robot.nv), rng.normal(size=robot.nv)
    mass, bias = robot.mass_matrix(q), robot.nonlinear_effects(q, v)
    _, jacobian, drift = constrained.state_rows(robot, bounds, q, v)
    assert len(drift) == 12 > constrained.EIGEN_ROWS
    cholesky = constrained.solve_kkt(mass, tau - bias, jacobian, drift)
    monkeypatch.setattr(constrained, "EIGEN_ROWS", 100)  # the eigendecomposition for every size
    eigen = constrained.solve_kkt(mass, tau - bias, jacobian, drift)
    assert agreement(*cholesky, *eigen) < 1e-12
    assert np.allclose(jacobian @ cholesky[0] + drift, 0.0, atol=1e-9)
    assert agreement(*constrained.solve_kkt(mass, tau - bias, jacobian, 0 * drift), *eigen) > 1e-3


def test_a_redundant_set_above_six_rows_gets_the_least_norm_multipliers(rng):
    # a fifth contact on a foot already held: 15 rows, 12 independent; the foot's force is
    # shared equally between its two contacts (the least-norm λ), never a NaN
    robot, bounds, q = _solo_standing([PointContact(FEET[0], friction=0.7)])
    v, tau = rng.normal(size=robot.nv), rng.normal(size=robot.nv)
    a, lam = constrained.forward_dynamics(robot, q, v, tau, [b.constraint for b in bounds])
    single, lam_single = constrained.forward_dynamics(robot, q, v, tau, [b.constraint for b in bounds[:4]])
    combined = lam[:12].copy()
    combined[:3] += lam[12:]
    assert np.isfinite(lam).all() and agreement(a, combined, single, lam_single) < 1e-9
    assert np.allclose(lam[:3], lam[12:], rtol=0.0, atol=1e-9 * np.abs(lam).max())
    assert not np.allclose(lam[:3], lam_single[:3], atol=1e-3)  # the check can fail: the force is split
