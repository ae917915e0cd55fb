"""What the compiled backend cannot run, said once; auto reports the first reason, compiled raises it;
choosing never loads the code generator."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import robodyn
from robodyn.exceptions import InputError
from robodyn.sim import compiled_backend, engine, pinocchio_loop
from robodyn.sim.observer import MomentumObserver
from robodyn.sim.plan import ExternalWrench, plan
from tests.conftest import ROOT


def test_unsupported_lists_every_reason_in_order_and_the_engines_use_the_first():
    robot = robodyn.load("rp_arm")
    q0 = robot.default_configuration()
    push = ExternalWrench(robot.end_effector, [1.0, 0.0, 0.0])
    observer = MomentumObserver(robot, 10.0, torque="sampled")
    options = {"external": [push], "observer": observer, "limits": "enforce"}
    reasons = compiled_backend.unsupported(plan(robot, q0, np.zeros(2), 0.01, 1e-3, **options))
    assert [reason.split(" (")[0] for reason in reasons] == ["external wrenches", "a momentum observer", "limits enforced"]
    assert pinocchio_loop.unsupported(plan(robot, q0, np.zeros(2), 0.01, 1e-3, **options)) == []
    assert engine.choose(plan(robot, q0, np.zeros(2), 0.01, 1e-3, engine="auto", **options)) == ("pinocchio", reasons[0])
    with pytest.raises(InputError, match="external wrenches") as refused:
        engine.choose(plan(robot, q0, np.zeros(2), 0.01, 1e-3, engine="compiled", **options))
    assert refused.value.argument == "external"  # the parameter that asks for what it lacks
    assert compiled_backend.unsupported(plan(robot, q0, np.zeros(2), 0.01, 1e-3)) == []  # negative control


def test_choosing_auto_for_a_robot_not_compiled_loads_no_code_generator(tmp_path):
    code = (
        "import sys, numpy as np, robodyn; from robodyn.sim.simulation import simulate_run; "
        "r = robodyn.load('solo12'); "
        "_, run = simulate_run(r, r.default_configuration(), np.zeros(r.nv), 0.01, 1e-3, limits='ignore'); "
        "print(run.engine, 'sympy' in sys.modules, run.compile_time)"
    )
    env = {"ROBODYN_CACHE": str(tmp_path), "PATH": "/usr/bin:/bin"}
    result = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, env=env, check=True, timeout=120
    )
    engine_name, loaded, seconds = result.stdout.split()
    assert (engine_name, loaded) == ("pinocchio", "False")
    assert float(seconds) < 0.5  # a cache lookup (was 2 s: importing sympy)
