"""robodyn.dynamics.loading: one complete LoadOptions through load, rebuild and pickling (issue 23).

Issue 23 found that a robot loaded with ``max_dof=400`` could not be unpickled: the options
it travelled with lacked ``max_dof``, so the other side built it with the default limit.
A real 400-degree-of-freedom robot needs 4 GB of Pinocchio data, so these tests lower the
default limit instead (``MAX_DOF``) and load a small robot above it with ``max_dof=``.
"""

from __future__ import annotations

import copy
import copyreg
import pickle

import numpy as np
import pytest

import robodyn
from robodyn.dynamics import loading, options, pickling
from robodyn.dynamics.robot import Robot
from tests.conftest import random_state

#: Every option of robodyn.load, none at its default, on panda: a mimic finger, and a floating base here.
EVERY_OPTION = {
    "floating_base": True,
    "gravity": (0.5, -1.0, -9.0),
    "check_inertia": False,
    "strict": True,
    "lock": {"panda_joint7": 0.2},
    "threads": 1,
    "max_dof": 40,
    "max_bytes": 10_000_000,
}


@pytest.fixture
def small_default_limit(monkeypatch):
    """A default max_dof below the robots' size (what 300 is to a 400-dof robot), and no robot
    already unpickled in this process (so unpickling builds under that default)."""
    monkeypatch.setattr(options, "MAX_DOF", 5)
    pickling.clear()
    yield
    pickling.clear()


def _assert_same_dynamics(copy_, robot, rng):
    q, v, a = random_state(robot, rng, 7)
    np.testing.assert_array_equal(copy_.inverse_dynamics(q, v, a), robot.inverse_dynamics(q, v, a))
    np.testing.assert_array_equal(copy_.mass_matrix(q), robot.mass_matrix(q))
    np.testing.assert_array_equal(copy_.coriolis_matrix(q, v), robot.coriolis_matrix(q, v))
    np.testing.assert_array_equal(copy_.forward_dynamics(q, v, a), robot.forward_dynamics(q, v, a))
    np.testing.assert_array_equal(copy_.frame_position(q, copy_.end_effector), robot.frame_position(q, robot.end_effector))


def test_the_options_record_every_option_load_takes():
    robot = robodyn.load("panda", **EVERY_OPTION)
    recorded = robot.options
    assert recorded.floating_base is True and recorded.gravity == (0.5, -1.0, -9.0)
    assert (recorded.check_inertia, recorded.strict, recorded.threads) == (False, True, 1)
    assert recorded.lock == (("panda_joint7", 0.2),) and recorded.max_dof == 40 and recorded.max_bytes == 10_000_000
    assert robot.mimic is not None and robot.floating_base and "panda_joint7" not in robot.joint_names


def test_a_robot_loaded_with_max_dof_survives_pickling(small_default_limit, rng):
    with pytest.raises(robodyn.URDFError, match="max_dof"):
        robodyn.load("ur5")  # negative control: the lowered default really refuses it
    robot = robodyn.load("ur5", max_dof=10)
    copy_ = pickle.loads(pickle.dumps(robot))
    assert copy_ is not robot and copy_.options == robot.options and copy_.options.max_dof == 10
    _assert_same_dynamics(copy_, robot, rng)


def test_a_robot_loaded_with_every_option_survives_pickling(small_default_limit, rng):
    robot = robodyn.load("panda", **EVERY_OPTION)
    before = pickling.builds
    copy_ = pickle.loads(pickle.dumps(robot))
    assert pickling.builds == before + 1 and copy_ is not robot
    assert copy_.options == robot.options and copy_.urdf == robot.urdf
    assert copy_.joint_names == robot.joint_names and copy_.threads == 1 and copy_.mimic is not None
    np.testing.assert_array_equal(copy_.gravity_vector, [0.5, -1.0, -9.0])
    _assert_same_dynamics(copy_, robot, rng)


def test_rebuild_and_a_payload_keep_every_option(small_default_limit, rng):
    robot = robodyn.load("panda", **EVERY_OPTION)
    copy_ = loading.rebuild(robot)
    assert copy_ is not robot and copy_.model is not robot.model and copy_.options == robot.options
    _assert_same_dynamics(copy_, robot, rng)
    carrying = robodyn.attach_payload(robot, "panda_hand", 0.5)
    assert carrying.options == robot.options and carrying.nv == robot.nv


def test_pickling_is_registered_with_copyreg_beside_the_loader():
    assert copyreg.dispatch_table[Robot] is loading._reduce
    robot = robodyn.load("rp_arm")
    function, arguments = copyreg.dispatch_table[Robot](robot)
    assert function is loading.restore and arguments == (robot.source, robot.options)


def test_copy_and_deepcopy_return_the_robot_itself_and_rebuild_an_independent_one():
    robot = robodyn.load("rp_arm", gravity=(0.0, 0.0, -1.0))
    assert copy.copy(robot) is robot and copy.deepcopy(robot) is robot
    holder = copy.deepcopy({"robot": robot, "gains": [1.0]})
    assert holder["robot"] is robot
    independent = loading.rebuild(robot)
    independent.model.gravity.linear = np.array([0.0, 0.0, -5.0])
    np.testing.assert_array_equal(robot.gravity_vector, [0.0, 0.0, -1.0])  # the original is untouched
