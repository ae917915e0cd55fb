"""The whole zoo (slow tier): every robot loads with a robodyn error or satisfies the identities."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn.urdf.zoo import zoo_names
from tests.conftest import random_state


@pytest.mark.slow
@pytest.mark.parametrize("name", zoo_names())
def test_zoo_robot_loads_cleanly_and_its_dynamics_are_consistent(name, rng):
    try:
        robot = robodyn.load(name)
    except robodyn.RobodynError as error:
        assert str(error).startswith(name), error  # names the robot; a reason, not a crash
        return
    for _ in range(3):
        q, v, a = random_state(robot, rng)
        tau = robot.inverse_dynamics(q, v, a)
        scale = max(1.0, np.abs(tau).max())
        assembled = robot.mass_matrix(q) @ a + robot.coriolis_matrix(q, v) @ v + robot.gravity(q)
        np.testing.assert_allclose(assembled, tau, atol=1e-8 * scale)
        if robot.massless_joints:
            with pytest.raises(robodyn.SingularMassMatrixError, match=robot.massless_joints[0]):
                robot.forward_dynamics(q, v, tau)
        else:
            np.testing.assert_allclose(robot.forward_dynamics(q, v, tau), a, atol=1e-6 * max(1.0, np.abs(a).max()))
