"""An MJCF ``<equality connect>`` is MuJoCo's constraint (the outside engine): at random
configurations of the four-bar (tests/data/constraints/four_bar.xml) away from the one it
closes at, robodyn's residual ``Φ`` and Jacobian ``J`` are MuJoCo's ``efc_pos`` and
``efc_J`` of the connect's three rows — the anchor on ``body1`` minus its partner on
``body2``, which a crossed pair of bodies (or ends) would change. The control: the same
point anchor with its bodies crossed disagrees."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import robodyn
from robodyn.constraints import PointAnchor
from robodyn.exceptions import RobodynWarning
from tests.constraints.linkages import DATA

mujoco = pytest.importorskip("mujoco")  # the bench extra
MJCF = DATA / "four_bar.xml"


def test_the_connects_residual_and_jacobian_are_mujocos_away_from_the_closed_configuration():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RobodynWarning)
        robot = robodyn.load(MJCF)
    (loop,) = robot.constraints
    crossed = PointAnchor(str(loop.frame2), loop.point1, loop.frame1)  # the control
    model = mujoco.MjModel.from_xml_path(str(MJCF))
    data = mujoco.MjData(model)
    rng = np.random.default_rng(11)
    for _ in range(3):
        q = rng.uniform(-0.6, 0.6, robot.nq)
        data.qpos[:], _ = robot.to_mujoco(q)
        mujoco.mj_forward(model, data)
        rows = np.flatnonzero(data.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY)
        assert len(rows) == 3 and np.abs(data.efc_pos[rows]).max() > 1e-2  # open, away from q = 0
        np.testing.assert_allclose(robot.constraint_residual(q), data.efc_pos[rows], atol=1e-12)
        jacobian = data.efc_J.reshape(data.nefc, model.nv)[rows]
        np.testing.assert_allclose(robot.constraint_jacobian(q), jacobian, atol=1e-12)
        assert np.abs(robot.constraint_residual(q, crossed) - data.efc_pos[rows]).max() > 1e-3
