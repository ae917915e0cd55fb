"""The generated RP arm against its hand-written closed form and against physical laws."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn.reference import rp_closed_form as closed
from robodyn.urdf.models import GENERATED, RPArmParameters, rp_arm_urdf
from tests.conftest import ROOT

PARAMETERS = [
    RPArmParameters(),
    RPArmParameters(l1=0.8, m1=3.5, m2=0.7, l2=0.6, width=0.08, Iz1=0.3, Iz2=0.05),
]


def relative_error(actual: np.ndarray, expected: np.ndarray) -> float:
    return float(np.max(np.abs(actual - expected)) / max(1.0, float(np.max(np.abs(expected)))))


@pytest.mark.parametrize("name", sorted(GENERATED))
def test_committed_urdf_equals_generator_output(name):
    assert (ROOT / "urdf" / f"{name}.urdf").read_text(encoding="utf-8") == GENERATED[name]()


@pytest.mark.parametrize("parameters", PARAMETERS, ids=["default", "custom"])
def test_pinocchio_matches_closed_form(parameters, rng):
    robot = robodyn.load(rp_arm_urdf(parameters))
    q = robot.random_configuration(rng, 500)
    v, a = rng.normal(size=(2, 500, 2)) * 2
    assert relative_error(robot.mass_matrix(q), closed.mass_matrix(parameters, q)) < 1e-10
    assert relative_error(robot.gravity(q), closed.gravity(parameters, q)) < 1e-10
    assert relative_error(robot.nonlinear_effects(q, v) - robot.gravity(q), closed.coriolis_forces(parameters, q, v)) < 1e-10
    assert relative_error(robot.inverse_dynamics(q, v, a), closed.inverse_dynamics(parameters, q, v, a)) < 1e-10
    assert relative_error(robot.kinetic_energy(q, v), closed.kinetic_energy(parameters, q, v)) < 1e-10
    assert relative_error(robot.potential_energy(q), closed.potential_energy(parameters, q)) < 1e-10


def test_pinocchio_coriolis_matrix_is_the_christoffel_form_for_the_rp_arm(rng):
    parameters = PARAMETERS[0]
    robot = robodyn.load("rp_arm")
    q = robot.random_configuration(rng, 100)
    v = rng.normal(size=(100, 2))
    assert relative_error(robot.coriolis_matrix(q, v), closed.coriolis_matrix(parameters, q, v)) < 1e-10


def test_closed_form_mass_matrix_is_symmetric_positive_definite(rng):
    q = np.column_stack([rng.uniform(-np.pi, np.pi, 200), rng.uniform(0, 0.3, 200)])
    for M in closed.mass_matrix(PARAMETERS[0], q):
        assert np.allclose(M, M.T)
        assert np.linalg.eigvalsh(M).min() > 0


def test_mdot_minus_2c_is_skew_symmetric(rng):
    robot = robodyn.load("rp_arm")
    step = 1e-6
    for _ in range(50):
        q = robot.random_configuration(rng)
        v = rng.normal(size=2)
        m_dot = (robot.mass_matrix(q + step * v) - robot.mass_matrix(q - step * v)) / (2 * step)
        skew = m_dot - 2 * robot.coriolis_matrix(q, v)
        assert np.allclose(skew, -skew.T, atol=1e-7)


def test_hand_calculation_at_a_known_state():
    """Arm horizontal, at rest, link 2 extended by 0.1 m: the static torques by hand."""
    p = PARAMETERS[0]
    robot = robodyn.load("rp_arm")
    # Link 1 (2 kg) at 0.25 m and link 2 (1 kg) at 0.5 + 0.1 + 0.2 = 0.8 m hold the shoulder.
    expected_shoulder = (2.0 * 0.25 + 1.0 * 0.8) * 9.81
    tau = robot.inverse_dynamics([0.0, 0.1], [0.0, 0.0], [0.0, 0.0])
    assert tau == pytest.approx([expected_shoulder, 0.0], abs=1e-12)
    # Pointing straight up, the slider carries the whole weight of link 2.
    assert robot.gravity([np.pi / 2, 0.1])[1] == pytest.approx(p.m2 * 9.81, rel=1e-12)


def test_positive_q1_lifts_the_end_effector():
    robot = robodyn.load("rp_arm")
    assert robot.frame_position([0.0, 0.0], "end_effector") == pytest.approx([0.9, 0.0, 0.0], abs=1e-12)
    lifted = robot.frame_position([0.3, 0.0], "end_effector")
    assert lifted[2] == pytest.approx(0.9 * np.sin(0.3), abs=1e-12)
