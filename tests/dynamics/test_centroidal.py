"""Issue 42, centroidal quantities: ``Robot.center_of_mass``, ``centroidal_momentum`` and
``centroidal_momentum_matrix`` (Pinocchio's composite rigid-body route) against the
reference's own sums body by body (``Σ mᵢ pᵢ / m``, ``Σ mᵢ vᵢ``, ``Σ (pᵢ − c) × mᵢ vᵢ +
Iᵢ ωᵢ``), at random states of a 6-joint arm, a mimic arm, a floating quadruped and a
floating robot with an oblique prismatic joint, under non-default gravity."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
import robodyn.reference as reference
from robodyn.exceptions import InputError
from robodyn.reference import centroidal as reference_centroidal
from tests.conftest import NONDEGENERATE, random_states

ROBOTS = {
    "ur5": ("ur5", {}),
    "panda (mimic)": ("panda", {}),
    "solo12 (floating)": ("solo12", {}),
    "oblique prismatic (floating)": (NONDEGENERATE / "oblique.urdf", {"floating_base": True}),
}
GRAVITY = (0.7, -0.4, -9.6)


def to_reference(robot: robodyn.Robot, model, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``q``, ``v`` in the reference's joint order (joints matched by name)."""
    base_q, base_v = (7, 6) if robot.floating_base else (0, 0)
    mine, theirs = robot.joint_names[1 if base_q else 0 :], model.joint_names[1 if base_q else 0 :]
    order = [mine.index(name) for name in theirs]
    q_ref = np.concatenate([q[..., :base_q], q[..., base_q:][..., order]], axis=-1)
    v_ref = np.concatenate([v[..., :base_v], v[..., base_v:][..., order]], axis=-1)
    return q_ref, v_ref


@pytest.mark.parametrize("case", list(ROBOTS))
def test_centre_of_mass_and_centroidal_momentum_agree_with_the_references_sums(case, rng):
    source, options = ROBOTS[case]
    robot = robodyn.load(source, gravity=GRAVITY, **options)
    model = reference.load(source, gravity=GRAVITY, floating_base=robot.floating_base)
    q, v, _ = random_states(robot, rng, 5)
    q_ref, v_ref = to_reference(robot, model, q, v)
    com, momentum = robot.center_of_mass(q), robot.centroidal_momentum(q, v)
    np.testing.assert_allclose(com, model.center_of_mass(q_ref), rtol=0, atol=1e-12)
    scale = max(1.0, float(np.abs(momentum).max()))
    np.testing.assert_allclose(momentum, model.centroidal_momentum(q_ref, v_ref), rtol=0, atol=1e-12 * scale)
    # the linear momentum is m ċ (m: the moving bodies' mass, links welded to the world not
    # counted), ċ by differencing c(q) along v
    moving = model.body_motion(q_ref, v_ref)[0].sum()
    if robot.floating_base:
        assert moving == pytest.approx(robot.total_mass, rel=1e-12)
    step = 1e-6
    ahead, behind = robot.integrate(q, step * v), robot.integrate(q, -step * v)
    rate = (robot.center_of_mass(ahead) - robot.center_of_mass(behind)) / (2 * step)
    np.testing.assert_allclose(momentum[:, :3], moving * rate, atol=1e-7 * scale)


@pytest.mark.parametrize("case", ["panda (mimic)", "solo12 (floating)"])
def test_one_state_gives_one_row_of_the_batch_and_the_matrix_maps_v_to_the_momentum(case, rng):
    source, options = ROBOTS[case]
    robot = robodyn.load(source, **options)
    q, v, _ = random_states(robot, rng, 3)
    matrix = robot.centroidal_momentum_matrix(q)
    assert matrix.shape == (3, 6, robot.nv)
    np.testing.assert_allclose(np.einsum("nij,nj->ni", matrix, v), robot.centroidal_momentum(q, v), atol=1e-13)
    np.testing.assert_array_equal(robot.center_of_mass(q[1]), robot.center_of_mass(q)[1])
    np.testing.assert_array_equal(robot.centroidal_momentum(q[2], v[2]), robot.centroidal_momentum(q, v)[2])
    assert robot.center_of_mass(q[:0]).shape == (0, 3)


def test_the_inertia_in_the_wrong_frame_fails_the_same_check(rng):
    """Negative control: the sums with each body's inertia in its own frame (``Īᵢ``, not
    ``Rᵢ Īᵢ Rᵢᵀ``), or the angular momentum about the origin instead of the centre of
    mass, disagree with Pinocchio far beyond the tolerance."""
    robot = robodyn.load("solo12")
    model = reference.load("solo12", floating_base=True)
    q, v, _ = random_states(robot, rng, 4)
    q_ref, v_ref = to_reference(robot, model, q, v)
    masses, coms, velocities, inertias, omegas = model.body_motion(q_ref, v_ref)
    right = reference_centroidal.centroidal_momentum(masses, coms, velocities, inertias, omegas)
    np.testing.assert_allclose(right, robot.centroidal_momentum(q, v), atol=1e-12)
    local = np.broadcast_to(model._inertias[None, : len(masses)], inertias.shape)
    wrong = reference_centroidal.centroidal_momentum(masses, coms, velocities, local, omegas)
    assert np.abs(wrong - right).max() > 1e-4
    about_origin = right[:, 3:] + np.cross(model.center_of_mass(q_ref), right[:, :3])
    assert np.abs(about_origin - right[:, 3:]).max() > 1e-3


def test_a_wrong_size_or_non_finite_state_is_refused(rng):
    robot = robodyn.load("ur5")
    with pytest.raises(InputError):
        robot.center_of_mass(np.zeros(robot.nq + 1))
    with pytest.raises(InputError):
        robot.centroidal_momentum(np.zeros(robot.nq), np.full(robot.nv, np.nan))
