"""The run plan: every argument checked once, into a frozen record every backend reads."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import robodyn
from robodyn.constraints import PointAnchor
from robodyn.exceptions import FrameError, InputError
from robodyn.sim.control import PDGravity
from robodyn.sim.ground import Ground
from robodyn.sim.plan import ExternalWrench, RunPlan, plan


@pytest.fixture(scope="module")
def rp_arm():
    return robodyn.load("rp_arm")


def test_a_plan_holds_the_checked_run_and_cannot_change(rp_arm):
    q0 = rp_arm.default_configuration()
    law = PDGravity(rp_arm, q0, kp=30.0, kd=3.0)
    made = plan(rp_arm, list(q0), [0.0, 0.0], 0.05, 1e-3, controller=law, control_period=5e-3)
    assert isinstance(made, RunPlan) and made.steps == 50 and made.every == 5 and made.control_period == 5e-3
    assert made.q0.dtype == np.float64 and made.times()[-1] == pytest.approx(0.05) and made.rk4
    with pytest.raises(dataclasses.FrozenInstanceError):
        made.steps = 3  # type: ignore[misc]
    assert plan(rp_arm, q0, np.zeros(2), 0.05, 1e-3, controller=law, hold=True).every == 1
    assert plan(rp_arm, q0, np.zeros(2), 0.05, 1e-3, hold=True).every is None  # passive: nothing sampled


@pytest.mark.parametrize(
    ("options", "argument"),
    [
        ({"integrator": "euler"}, "integrator"),
        ({"limits": "clip"}, "limits"),
        ({"engine": "warp"}, "engine"),
        ({"duration": 0.0505}, "duration"),
        ({"dt": -1.0}, "dt and duration"),
        ({"control_period": 1e-3}, "control_period"),  # without a controller
    ],
)
def test_each_bad_argument_is_refused_by_name(rp_arm, options, argument):
    arguments = {"duration": 0.05, "dt": 1e-3} | options
    duration, dt = arguments.pop("duration"), arguments.pop("dt")
    with pytest.raises(InputError) as refused:
        plan(rp_arm, rp_arm.default_configuration(), np.zeros(2), duration, dt, **arguments)
    assert refused.value.argument == argument


def test_a_wrench_on_an_unknown_frame_is_refused_at_plan_time(rp_arm):
    with pytest.raises(FrameError):
        plan(rp_arm, rp_arm.default_configuration(), np.zeros(2), 0.01, 1e-3, external=[ExternalWrench("nowhere", [1, 0, 0])])


@pytest.mark.parametrize("integrator", [None, "rk4", "semi-implicit-euler"])
def test_constraints_with_a_ground_are_refused_as_such_whatever_the_integrator(integrator):
    robot = robodyn.load("solo12", constraints=[PointAnchor("FL_FOOT", (0.0, 0.0, 0.0), name="foot")])
    q0 = robot.default_configuration()
    with pytest.raises(InputError) as raised:
        plan(robot, q0, np.zeros(robot.nv), 0.01, 1e-3, ground=Ground(), integrator=integrator)
    assert raised.value.argument == "ground" and "constraints=" in str(raised.value)
    assert "rk4" not in str(raised.value) and "semi-implicit" not in str(raised.value)
