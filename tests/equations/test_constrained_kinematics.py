"""The constrained ends' kinematics in closed form: a weld's rotation rows ``sin θ a`` against
SciPy's rotation vector."""

from __future__ import annotations

import numpy as np
import sympy as sp
from scipy.spatial.transform import Rotation

from robodyn.equations.constrained_kinematics import sine_vector


def test_the_sine_vector_is_the_sine_of_the_angle_times_the_axis_of_any_rotation(rng):
    for vector in (*rng.normal(size=(4, 3)), np.array([0.0, 0.0, 0.3]), np.array([1e-3, -2.0, 0.0])):
        rotation = Rotation.from_rotvec(vector)
        angle = np.linalg.norm(vector)
        shown = np.array(sine_vector(sp.Matrix(rotation.as_matrix())), dtype=float).ravel()
        assert np.allclose(shown, np.sin(angle) * vector / angle, rtol=0, atol=1e-12)
        # the check can fail: the inverse rotation gives the opposite sign
        assert not np.allclose(
            np.array(sine_vector(sp.Matrix(rotation.inv().as_matrix())), dtype=float).ravel(), shown, atol=1e-3
        )
