"""simulate(engine="compiled") gives the Pinocchio engine's trajectory, or refuses in one line."""

from __future__ import annotations

import shutil

import numpy as np
import pytest

import robodyn
from robodyn.dynamics.loading import rebuild
from robodyn.exceptions import CompileError, InputError
from robodyn.sim.control import ComputedTorque, PDGravity, TaskSpace, quintic_reference
from robodyn.sim.simulation import ExternalWrench

pytestmark = pytest.mark.skipif(shutil.which("cc") is None and shutil.which("gcc") is None, reason="no C compiler")


def _laws(robot, q0):
    target = q0 + 0.3
    return {
        "passive": None,
        "pd": PDGravity(rebuild(robot), target),
        "computed-torque": ComputedTorque(rebuild(robot), quintic_reference(q0, target, 0.4)),
    }


@pytest.mark.parametrize("name", ["ur5", "rp_arm"])
@pytest.mark.parametrize("law", ["passive", "pd", "computed-torque"])
@pytest.mark.parametrize("integrator", ["rk4", "semi-implicit-euler"])
def test_compiled_engine_equals_the_pinocchio_engine(name, law, integrator):
    robot = robodyn.load(name)
    q0 = robot.default_configuration()
    controller = _laws(robot, q0)[law]
    options = {"controller": controller, "integrator": integrator, "limits": "ignore"}
    python = robodyn.simulate(robot, q0, np.zeros(robot.nv), 0.5, 1e-3, **options)
    compiled = robodyn.simulate(robot, q0, np.zeros(robot.nv), 0.5, 1e-3, engine="compiled", **options)
    scale = max(1.0, np.abs(python.q).max())
    np.testing.assert_allclose(compiled.q, python.q, atol=1e-9 * scale)
    np.testing.assert_allclose(compiled.tau, python.tau, atol=1e-8 * max(1.0, np.abs(python.tau).max()))
    assert compiled.joint_names == python.joint_names and len(compiled) == len(python)


def test_a_python_controller_is_held_every_control_period():
    robot = robodyn.load("rp_arm")
    q0 = robot.default_configuration()
    law = TaskSpace(rebuild(robot), robot.end_effector, np.array([0.7, 0.0, 0.7]))
    held = robodyn.simulate(robot, q0, np.zeros(2), 0.2, 1e-3, controller=law, hold=True, limits="ignore")
    compiled = robodyn.simulate(
        robot, q0, np.zeros(2), 0.2, 1e-3, controller=law, engine="compiled", control_period=1e-3, limits="ignore"
    )
    np.testing.assert_allclose(compiled.q, held.q, atol=1e-9)


def test_refusals_are_one_line_robodyn_errors():
    robot = robodyn.load("rp_arm")
    q0 = robot.default_configuration()
    with pytest.raises(InputError, match="engine"):
        robodyn.simulate(robot, q0, np.zeros(2), 0.1, 1e-3, engine="warp")
    with pytest.raises(InputError, match="enforce"):
        robodyn.simulate(robot, q0, np.zeros(2), 0.1, 1e-3, engine="compiled", limits="enforce")
    wrench = ExternalWrench(robot.end_effector, np.array([1.0, 0, 0, 0, 0, 0]))
    with pytest.raises(InputError, match="wrench"):
        robodyn.simulate(robot, q0, np.zeros(2), 0.1, 1e-3, engine="compiled", external=[wrench])
    floating = robodyn.load("solo12")
    with pytest.raises(CompileError):
        robodyn.simulate(floating, floating.default_configuration(), np.zeros(floating.nv), 0.1, 1e-3, engine="compiled")


def test_compiled_runs_warn_about_limits_like_the_python_engine():
    robot = robodyn.load("rp_arm")
    q0 = robot.default_configuration()
    with pytest.warns(robodyn.JointLimitWarning) as python:
        robodyn.simulate(robot, q0, np.zeros(2), 1.0, 1e-3)
    with pytest.warns(robodyn.JointLimitWarning) as compiled:
        robodyn.simulate(robot, q0, np.zeros(2), 1.0, 1e-3, engine="compiled")
    assert str(python[0].message) == str(compiled[0].message)
