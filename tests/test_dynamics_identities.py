"""Identities every robot's dynamics must satisfy, at seeded random states.

Parametrised over every URDF in ``urdf/`` and a spread of zoo robots: ``G = tau(q, 0, 0)``,
``C v = tau(q, v, 0) − G``, ``tau = M a + C v + G``, ``dM/dt = C + Cᵀ`` and ``dU/dq = G``
by finite differences, ABA inverting RNEA, ``T = ½ vᵀ M v``, Jacobians against finite
differences of positions.
"""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from tests.conftest import FAST_ZOO, URDF_FILES, random_state

SOURCES = [str(path) for path in URDF_FILES] + FAST_ZOO
IDS = [path.stem for path in URDF_FILES] + FAST_ZOO


@pytest.fixture(scope="module", params=SOURCES, ids=IDS)
def robot(request):
    return robodyn.load(request.param)


def scale(values: np.ndarray) -> float:
    return max(1.0, float(np.max(np.abs(values))))


def test_gravity_is_inverse_dynamics_at_rest(robot, rng):
    for _ in range(10):
        q, _, _ = random_state(robot, rng)
        zeros = np.zeros(robot.nv)
        np.testing.assert_allclose(
            robot.gravity(q), robot.inverse_dynamics(q, zeros, zeros), atol=1e-10 * scale(robot.gravity(q))
        )


def test_equation_of_motion_is_assembled_from_its_terms(robot, rng):
    for _ in range(10):
        q, v, a = random_state(robot, rng)
        tau = robot.inverse_dynamics(q, v, a)
        assembled = robot.mass_matrix(q) @ a + robot.coriolis_matrix(q, v) @ v + robot.gravity(q)
        np.testing.assert_allclose(assembled, tau, atol=1e-9 * scale(tau))
        np.testing.assert_allclose(
            robot.nonlinear_effects(q, v), robot.inverse_dynamics(q, v, np.zeros(robot.nv)), atol=1e-9 * scale(tau)
        )


def test_forward_dynamics_inverts_inverse_dynamics(robot, rng):
    for _ in range(10):
        q, v, a = random_state(robot, rng)
        recovered = robot.forward_dynamics(q, v, robot.inverse_dynamics(q, v, a))
        np.testing.assert_allclose(recovered, a, atol=1e-7 * scale(a))


def test_mass_matrix_is_symmetric_positive_definite(robot, rng):
    for _ in range(10):
        M = robot.mass_matrix(robot.random_configuration(rng))
        np.testing.assert_array_equal(M, M.T)
        assert np.linalg.eigvalsh(M).min() > 0


def test_mass_matrix_derivative_is_c_plus_c_transpose(robot, rng):
    step = 1e-6
    for _ in range(5):
        q, v, _ = random_state(robot, rng)
        m_dot = (robot.mass_matrix(q + step * v) - robot.mass_matrix(q - step * v)) / (2 * step)
        C = robot.coriolis_matrix(q, v)
        np.testing.assert_allclose(m_dot, C + C.T, atol=1e-6 * scale(m_dot))


def test_kinetic_energy_is_half_v_m_v(robot, rng):
    q, v, _ = random_state(robot, rng)
    assert robot.kinetic_energy(q, v) == pytest.approx(0.5 * v @ robot.mass_matrix(q) @ v, rel=1e-10)


def test_gravity_is_the_gradient_of_potential_energy(robot, rng):
    step = 1e-6
    q = robot.random_configuration(rng)
    gradient = np.array(
        [(robot.potential_energy(q + step * e) - robot.potential_energy(q - step * e)) / (2 * step) for e in np.eye(robot.nv)]
    )
    np.testing.assert_allclose(gradient, robot.gravity(q), atol=1e-6 * scale(robot.gravity(q)))


def test_frame_jacobian_matches_finite_differences(robot, rng):
    step = 1e-6
    frame = robot.spec.root if robot.nv == 0 else list(robot.spec.links)[-1]
    q, v, _ = random_state(robot, rng)
    velocity = (robot.frame_position(q + step * v, frame) - robot.frame_position(q - step * v, frame)) / (2 * step)
    np.testing.assert_allclose(robot.frame_jacobian(q, frame)[:3] @ v, velocity, atol=1e-6)
