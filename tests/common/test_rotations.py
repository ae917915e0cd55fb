"""robodyn.common.rotations: the quaternion algebra (x, y, z, w) against Pinocchio's quaternions."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from robodyn.common.rotations import quaternion_conjugate, quaternion_product, rotate_inverse


@pytest.fixture
def quaternions(rng):
    values = rng.normal(size=(20, 4))
    return values / np.linalg.norm(values, axis=1, keepdims=True)


def _pin(row: np.ndarray) -> pin.Quaternion:
    return pin.Quaternion(row[3], row[0], row[1], row[2])  # (w, x, y, z) constructor


def test_the_hamilton_product_is_pinocchios_quaternion_product(quaternions):
    left, right = quaternions[:10], quaternions[10:]
    product = quaternion_product(left, right)
    expected = np.array([(_pin(a) * _pin(b)).coeffs() for a, b in zip(left, right, strict=True)])
    np.testing.assert_allclose(product, expected, atol=1e-14)
    assert not np.allclose(product, quaternion_product(right, left))  # not commutative: the order is checked


def test_a_unit_quaternion_times_its_conjugate_is_the_identity(quaternions):
    identity = quaternion_product(quaternions, quaternion_conjugate(quaternions))
    np.testing.assert_allclose(identity, np.tile([0.0, 0.0, 0.0, 1.0], (len(quaternions), 1)), atol=1e-14)


def test_rotate_inverse_applies_the_transposed_rotation_matrix(quaternions, rng):
    vectors = rng.normal(size=(len(quaternions), 3))
    expected = np.array([_pin(q).toRotationMatrix().T @ v for q, v in zip(quaternions, vectors, strict=True)])
    np.testing.assert_allclose(rotate_inverse(quaternions, vectors), expected, atol=1e-14)
    np.testing.assert_allclose(rotate_inverse(-quaternions, vectors), expected, atol=1e-14)  # q and -q: one rotation
