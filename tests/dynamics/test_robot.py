"""robodyn.dynamics.robot: a thin front over its model handle (issue 23, Robot by composition)."""

from __future__ import annotations

import numpy as np

import robodyn
from robodyn.dynamics import configurations, energies, regressor
from robodyn.dynamics.handle import ModelHandle
from tests.conftest import random_state


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
