"""The constraint algebra's rotation logarithm against an independent one (SciPy's rotation
vector), across the small-angle, general and half-turn branches."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from robodyn.constraints.algebra import rotation_log

AXIS = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])


@pytest.mark.parametrize("angle", [0.0, 1e-9, 3e-7, 2e-6, 0.4, 2.0, 2.5, np.pi - 2e-6, np.pi - 3e-7, np.pi])
@pytest.mark.parametrize("axis", [AXIS, -AXIS, np.array([0.0, 0.0, 1.0]), np.array([-1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])])
def test_the_rotation_log_is_the_rotation_vector_of_every_angle(axis, angle):
    rotation = Rotation.from_rotvec(axis * angle).as_matrix()
    vector = rotation_log(rotation)
    assert np.linalg.norm(vector) == pytest.approx(angle, abs=1e-12, rel=1e-9)
    assert np.allclose(Rotation.from_rotvec(vector).as_matrix(), rotation, atol=1e-12)
    if angle < np.pi:  # below a half turn the vector is unique
        assert np.allclose(vector, axis * angle, atol=1e-12, rtol=1e-9)


def test_negative_control_a_rotation_vector_check_tells_a_wrong_vector():
    rotation = Rotation.from_rotvec(AXIS * 2.0).as_matrix()
    assert not np.allclose(Rotation.from_rotvec(AXIS * 2.0 * 1.001).as_matrix(), rotation, atol=1e-12)
