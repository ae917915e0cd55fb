"""Bugs the differential harness found in the code it was written on, kept as regressions.

Each names the case that found it (``ROBODYN_DIFFERENTIAL_SEED=generator:seed``)."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn.exceptions import SingularMassMatrixError
from tests.random_robots import urdf_from_seed

pytestmark = pytest.mark.differential


def test_a_massless_floating_root_with_one_child_is_refused_not_answered():
    """random_tree:31 with floating_base=True (found before the generator gave floating roots
    a mass): a massless root link with one moving child has a singular M (the root's six
    motions move the child as its joint does); ABA returned finite, arbitrary accelerations,
    different for one state and a batch. Now forward dynamics and simulate refuse it."""
    text = urdf_from_seed(31, 1, ["fixed", "continuous"])
    robot = robodyn.load(text, floating_base=True)
    q = robot.random_configuration(np.random.default_rng(0))
    assert np.linalg.eigvalsh(robot.mass_matrix(q))[0] < 1e-12  # singular indeed
    with pytest.raises(SingularMassMatrixError, match="root_joint"):
        robot.forward_dynamics(q, np.zeros(robot.nv), np.zeros(robot.nv))
    with pytest.raises(SingularMassMatrixError):
        robodyn.simulate(robot, q, np.zeros(robot.nv), 0.01, 1e-3)
    # Negative controls: the same root with two moving children, or with a mass, is regular.
    for source in (urdf_from_seed(5, 2, ["revolute"]).replace('parent link="link1"', 'parent link="link0"'),
                   text.replace('<link name="link0"/>', '<link name="link0"><inertial><mass value="1"/>'
                                '<inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>')):  # fmt: skip
        regular = robodyn.load(source, floating_base=True)
        assert regular.massless_joints == []
        state = regular.random_configuration(np.random.default_rng(1))
        assert np.all(np.isfinite(regular.forward_dynamics(state, np.zeros(regular.nv), np.zeros(regular.nv))))


def test_a_batch_of_one_state_of_a_one_joint_robot_stays_a_batch():
    """Seed random_tree:310003 (slow sweep): Pinocchio takes a (1, 1) array for a vector of
    one entry, so the single-call fast path answered a batch of one state of a one-joint robot
    with one state's shape ((1,) instead of (1, 1)); every quantity keeps the batch's shape."""
    robot = robodyn.load(
        "<robot name='one'><link name='a'/><link name='b'><inertial><mass value='1.3'/>"
        "<inertia ixx='0.1' ixy='0' ixz='0' iyy='0.2' iyz='0' izz='0.1'/></inertial></link>"
        "<joint name='j' type='continuous'><parent link='a'/><child link='b'/><origin xyz='0.1 0 0'/>"
        "<axis xyz='0 1 0'/></joint></robot>"
    )
    q, v = np.array([[0.3]]), np.array([[0.1]])
    for value, shape in (
        (robot.inverse_dynamics(q, v, v), (1, 1)),
        (robot.forward_dynamics(q, v, v), (1, 1)),
        (robot.gravity(q), (1, 1)),
        (robot.nonlinear_effects(q, v), (1, 1)),
        (robot.mass_matrix(q), (1, 1, 1)),
        (robot.inverse_dynamics(q[0], v[0], v[0]), (1,)),
        (robot.mass_matrix(q[0]), (1, 1)),
    ):
        assert np.shape(value) == shape
