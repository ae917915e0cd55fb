"""robodyn.dynamics.robot: a thin front over its model handle (issue 23, Robot by composition).

Also here:

- Identities every robot's dynamics must satisfy, at seeded random states.

  Parametrised over both robot sets — every URDF in ``urdf/`` and a spread of zoo robots, and
  the non-degenerate robots of ``tests/data/robots`` fixed, floating (tilted) and locked
  (one suite since issue 23, where it stood twice): ``G = tau(q, 0, 0)``,
  ``C v = tau(q, v, 0) − G``, ``tau = M a + C v + G``, ``dM/dt = C + Cᵀ`` and ``dU/dq = G``
  (displacements by ``integrate``) by finite differences, ABA inverting RNEA, M symmetric
  positive definite and repeatable, ``T = ½ vᵀ M v``, the energy balance ``dE/dt = vᵀ τ``,
  Jacobians against finite differences of positions.
"""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn.dynamics import configurations, energies, regressor
from robodyn.dynamics.handle import ModelHandle
from tests.conftest import FAST_ZOO, NONDEGENERATE_CASES, URDF_FILES, random_state, random_states


def test_a_robot_holds_a_model_handle_and_is_no_handle_itself():
    robot = robodyn.load("panda")
    assert isinstance(robot.handle, ModelHandle) and not isinstance(robot, ModelHandle)
    assert robot.handle.model is robot.model and robot.handle.mimic is robot.mimic
    assert (robot.handle.nq, robot.handle.nv, robot.handle.floating_base) == (robot.nq, robot.nv, robot.floating_base)
    assert robot.data is robot.handle.data


def test_configurations_energies_and_the_regressor_through_the_handle_equal_the_robot_methods(rng):
    robot = robodyn.load("panda", floating_base=True)
    handle = robot.handle
    q, v, a = random_state(robot, rng)
    np.testing.assert_array_equal(configurations.lower_limits(robot.dofs), robot.lower_limits)
    np.testing.assert_array_equal(configurations.default_configuration(handle, robot.dofs), robot.default_configuration())
    draws = configurations.random_configuration(handle, robot.dofs, np.random.default_rng(3), 4)
    np.testing.assert_array_equal(draws, robot.random_configuration(np.random.default_rng(3), 4))
    assert energies.kinetic_energy(handle, q, v) == robot.kinetic_energy(q, v)
    assert energies.potential_energy(handle, q) == robot.potential_energy(q)
    np.testing.assert_array_equal(regressor.regressor(handle, q, v, a), robot.regressor(q, v, a))
    Y = regressor.regressor(handle, q, v, a)
    np.testing.assert_allclose(Y @ regressor.inertial_parameters(handle), robot.inverse_dynamics(q, v, a), atol=1e-9)


def test_the_regressor_names_its_friction_parameters_after_the_dofs():
    robot = robodyn.load("rp_arm", floating_base=True)
    names = regressor.parameter_names(robot, friction=True)
    dof_names = [dof.name for dof in robot.dofs]
    assert dof_names[:6] == ["base.x", "base.y", "base.z", "base.rx", "base.ry", "base.rz"]
    assert names[-2 * robot.nv :] == [f"fv[{n}]" for n in dof_names] + [f"fc[{n}]" for n in dof_names]
    assert not any("root_joint." in name for name in names)


def test_the_notebook_table_takes_its_units_from_the_dofs():
    html = robodyn.load("rp_arm")._repr_html_()
    revolute, prismatic = robodyn.load("rp_arm").dofs
    assert f"{revolute.effort_limit:.4g} N m" in html and f"{prismatic.effort_limit:.4g} N<" in html
    assert f"{prismatic.upper:.4g} m<" in html


#: Both robot sets, one case each: the URDFs of ``urdf/`` and a spread of zoo robots as
#: they load, and the non-degenerate robots fixed, floating (tilted) and locked.
CASES = {path.stem: (str(path), {}) for path in URDF_FILES} | {name: (name, {}) for name in FAST_ZOO} | NONDEGENERATE_CASES


@pytest.fixture(scope="module", params=list(CASES))
def robot(request):
    source, options = CASES[request.param]
    return robodyn.load(source, **options)


@pytest.fixture
def states(robot, rng):
    return random_states(robot, rng)


def scale(values: np.ndarray) -> float:
    return max(1.0, float(np.max(np.abs(values))))


def test_gravity_and_nonlinear_effects_are_inverse_dynamics_without_acceleration(robot, states):
    q, v, a = states
    tau = robot.inverse_dynamics(q, v, a)
    np.testing.assert_allclose(robot.gravity(q), robot.inverse_dynamics(q, 0 * v, 0 * a), atol=1e-10 * scale(tau))
    np.testing.assert_allclose(robot.nonlinear_effects(q, v), robot.inverse_dynamics(q, v, 0 * a), atol=1e-10 * scale(tau))


def test_equation_of_motion_is_assembled_from_its_terms(robot, states):
    q, v, a = states
    tau = robot.inverse_dynamics(q, v, a)
    for qi, vi, ai, taui in zip(q, v, a, tau, strict=True):
        assembled = robot.mass_matrix(qi) @ ai + robot.coriolis_matrix(qi, vi) @ vi + robot.gravity(qi)
        np.testing.assert_allclose(assembled, taui, atol=1e-9 * scale(tau))


def test_forward_dynamics_inverts_inverse_dynamics_one_state_and_a_batch(robot, states):
    q, v, a = states
    for qi, vi, ai in zip(q, v, a, strict=True):  # the single-state paths
        np.testing.assert_allclose(robot.forward_dynamics(qi, vi, robot.inverse_dynamics(qi, vi, ai)), ai, atol=1e-7 * scale(a))
    np.testing.assert_allclose(robot.forward_dynamics(q, v, robot.inverse_dynamics(q, v, a)), a, atol=1e-7 * scale(a))


def test_mass_matrix_is_symmetric_positive_definite_and_does_not_depend_on_earlier_calls(robot, states):
    q, _, _ = states
    first = robot.mass_matrix(q[0]).copy()
    for qi in q:
        mass = robot.mass_matrix(qi)
        np.testing.assert_array_equal(mass, mass.T)
        assert np.linalg.eigvalsh(mass).min() > 0
    np.testing.assert_array_equal(robot.mass_matrix(q[0]), first)  # Pinocchio's crba once kept state


def test_mass_matrix_derivative_is_c_plus_c_transpose(robot, states):
    q, v, _ = states
    step = 1e-6
    for qi, vi in zip(q, v, strict=True):
        m_dot = (robot.mass_matrix(robot.integrate(qi, step * vi)) - robot.mass_matrix(robot.integrate(qi, -step * vi))) / (
            2 * step
        )
        C = robot.coriolis_matrix(qi, vi)
        np.testing.assert_allclose(m_dot, C + C.T, atol=1e-6 * max(scale(m_dot), scale(robot.mass_matrix(qi)) * scale(vi)))


def test_kinetic_energy_is_half_v_m_v(robot, states):
    q, v, _ = states
    assert robot.kinetic_energy(q[0], v[0]) == pytest.approx(0.5 * v[0] @ robot.mass_matrix(q[0]) @ v[0], rel=1e-10)


def test_gravity_is_the_gradient_of_potential_energy(robot, states):
    q, step = states[0][0], 1e-6
    gradient = np.array(
        [
            (robot.potential_energy(robot.integrate(q, step * e)) - robot.potential_energy(robot.integrate(q, -step * e)))
            / (2 * step)
            for e in np.eye(robot.nv)
        ]
    )
    np.testing.assert_allclose(gradient, robot.gravity(q), atol=1e-6 * scale(robot.gravity(q)))


def test_energy_balance_along_the_motion(robot, states):
    """dE/dt = vᵀ τ along the motion a = ABA(q, v, τ), E = T + U: central differences at h
    and h/2, Richardson-extrapolated (error of order h⁴)."""
    q, v, tau = states
    for qi, vi, taui in zip(q, v, tau, strict=True):
        ai = robot.forward_dynamics(qi, vi, taui)

        def rate(h, qi=qi, vi=vi, ai=ai):
            def energy(t):
                q_t = robot.integrate(qi, t * vi + 0.5 * t * t * ai)
                return robot.kinetic_energy(q_t, vi + t * ai) + robot.potential_energy(q_t)

            return (energy(h) - energy(-h)) / (2 * h)

        power = vi @ taui
        size = abs(power) + robot.kinetic_energy(qi, vi) + abs(vi @ robot.gravity(qi))
        assert abs((4 * rate(5e-5) - rate(1e-4)) / 3 - power) < 1e-6 * size


def test_frame_jacobian_matches_finite_differences(robot, states):
    step = 1e-6
    frame = robot.spec.root if robot.nv == 0 else list(robot.spec.links)[-1]
    q, v, _ = states
    velocity = (
        robot.frame_position(robot.integrate(q[0], step * v[0]), frame)
        - robot.frame_position(robot.integrate(q[0], -step * v[0]), frame)
    ) / (2 * step)
    np.testing.assert_allclose(robot.frame_jacobian(q[0], frame)[:3] @ v[0], velocity, atol=1e-6 * scale(velocity))
