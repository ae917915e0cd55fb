"""Issue 42: the reference's own centroidal sums (no Pinocchio), checked by laws of their
own: the linear momentum is ``m ċ`` (``ċ`` by differencing the reference's ``c(q)``), and a
uniform translation of a floating robot changes its linear momentum by ``m u`` and not its
angular momentum about the centre of mass."""

from __future__ import annotations

import numpy as np

import robodyn.reference as reference
from tests.conftest import NONDEGENERATE


def test_the_references_linear_momentum_is_the_mass_times_its_centre_of_mass_velocity(rng):
    model = reference.load(NONDEGENERATE / "oblique.urdf", floating_base=True, gravity=(0.5, 0.2, -9.7))
    q = np.concatenate([[0.1, -0.2, 0.3], [0.2, -0.1, 0.3], rng.uniform(-1, 1, model.nq - 6)])
    q[3:7] = np.array([0.2, -0.1, 0.3, 0.9]) / np.linalg.norm([0.2, -0.1, 0.3, 0.9])
    velocity = rng.normal(size=model.nv)
    momentum = model.centroidal_momentum(q, velocity)
    mass = model.body_motion(q[None], velocity[None])[0].sum()
    step = 1e-6

    def moved(sign: float) -> np.ndarray:  # q along the joints' rates; the base by its world velocity
        out = q.copy()
        out[7:] += sign * step * velocity[6:]
        x, y, z, w = q[3:7]
        rotation = np.array(
            [
                [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
            ]
        )
        out[:3] += sign * step * rotation @ velocity[:3]
        omega = sign * step * velocity[3:6]  # body axes: q ⊗ exp(ω/2)
        half = np.concatenate([0.5 * omega, [1.0]])
        out[3:7] = _product(q[3:7], half / np.linalg.norm(half))
        return out

    rate = (model.center_of_mass(moved(1.0)) - model.center_of_mass(moved(-1.0))) / (2 * step)
    np.testing.assert_allclose(momentum[:3], mass * rate, atol=1e-7 * max(1.0, np.abs(momentum).max()))


def test_a_uniform_translation_leaves_the_angular_momentum_about_the_centre_of_mass(rng):
    model = reference.load("solo12", floating_base=True)
    q = np.concatenate([[0.0, 0.0, 0.3], [0.0, 0.0, 0.0, 1.0], rng.uniform(-1, 1, 12)])
    velocity = rng.normal(size=model.nv)
    shifted = velocity.copy()
    shifted[:3] += [0.4, -0.7, 0.2]  # identity base attitude: body axes are world axes
    before, after = model.centroidal_momentum(q, velocity), model.centroidal_momentum(q, shifted)
    mass = model.body_motion(q[None], velocity[None])[0].sum()
    np.testing.assert_allclose(after[:3] - before[:3], mass * np.array([0.4, -0.7, 0.2]), atol=1e-12)
    np.testing.assert_allclose(after[3:], before[3:], atol=1e-12)
    stacked = model.centroidal_momentum(np.stack([q, q]), np.stack([velocity, shifted]))
    np.testing.assert_array_equal(stacked[1], after)


def _product(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product of quaternions (x, y, z, w)."""
    av, aw, bv, bw = a[:3], a[3], b[:3], b[3]
    return np.concatenate([aw * bv + bw * av + np.cross(av, bv), [aw * bw - av @ bv]])
