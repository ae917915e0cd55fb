"""A robot's programs are derived once: the kernels, the derivatives and the export print from them."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn.compiled import cache, programs
from robodyn.export import programs as export_programs_module
from robodyn.export.programs import export_programs
from tests.compiled_helpers import compiled_pair


@pytest.fixture(scope="module")
def rp_arm():
    return compiled_pair("rp_arm", gravity=(0.2, -0.4, -9.7))


def _no_derivation(monkeypatch) -> None:
    def fail(*args, **kwargs):
        pytest.fail("derived the dynamics again")

    for module in (programs, export_programs_module):
        monkeypatch.setattr(module, "derive_compact", fail)
        monkeypatch.setattr(module, "derive_newton_euler", fail)


def test_the_export_prints_the_compiled_engines_derivation(rp_arm, monkeypatch):
    robot, _ = rp_arm
    shared = programs.dynamics_programs(robot)
    _no_derivation(monkeypatch)
    exported = export_programs(robot)
    assert exported.tau is shared.tau
    assert exported.dynamics.assignments == tuple(shared.compact.assignments)
    with pytest.raises(pytest.fail.Exception, match="derived the dynamics again"):  # negative control
        export_programs(robot, keep_params=True)


def test_a_new_process_reads_the_programs_from_the_cache_and_an_empty_cache_derives(rp_arm, monkeypatch, tmp_path):
    robot, _ = rp_arm
    programs.dynamics_programs(robot)
    monkeypatch.setattr(programs, "_DERIVED", {})  # as a new process
    _no_derivation(monkeypatch)
    again = programs.dynamics_programs(robot)
    # The pickled programs are the same program: tau at a state, through sympy.
    q, qd, qdd = (again.tau.inputs[name] for name in ("q", "qd", "qdd"))
    values = dict(zip([*q, *qd, *qdd], [0.3, 0.1, -0.5, 0.7, 1.1, -0.2], strict=True))
    for symbol, expression in again.tau.assignments:
        values[symbol] = float(expression.xreplace(values))
    tau = [float(expression.xreplace(values)) for expression in again.tau.outputs["tau"]]
    expected = robot.inverse_dynamics(np.array([0.3, 0.1]), np.array([-0.5, 0.7]), np.array([1.1, -0.2]))
    assert np.allclose(tau, expected, rtol=1e-12, atol=1e-12)
    monkeypatch.setattr(programs, "_DERIVED", {})
    monkeypatch.setenv("ROBODYN_CACHE", str(tmp_path))  # negative control: nothing there
    with pytest.raises(pytest.fail.Exception, match="derived the dynamics again"):
        programs.dynamics_programs(robot)


def test_a_damaged_pickle_is_derived_again_and_replaced(rp_arm, monkeypatch, tmp_path):
    robot, _ = rp_arm
    monkeypatch.setenv("ROBODYN_CACHE", str(tmp_path))
    monkeypatch.setattr(programs, "_DERIVED", {})
    calls = []

    def derive() -> list[int]:
        calls.append(1)
        return [len(calls)]

    assert programs.derived(robot, "a test", derive) == [1]
    monkeypatch.setattr(programs, "_DERIVED", {})
    assert programs.derived(robot, "a test", derive) == [1] and len(calls) == 1  # from the pickle
    (pickled,) = (tmp_path / "compiled").glob("prog-*.pickle")
    pickled.write_bytes(pickled.read_bytes()[:5])
    monkeypatch.setattr(programs, "_DERIVED", {})
    assert programs.derived(robot, "a test", derive) == [2]
    monkeypatch.setattr(programs, "_DERIVED", {})
    assert programs.derived(robot, "a test", derive) == [2] and len(calls) == 2
    assert [path.name for path in (tmp_path / "compiled").iterdir() if path.name.startswith(".")] == []


def test_another_robot_is_another_key(rp_arm):
    robot, _ = rp_arm
    assert cache.robot_key(robot) != cache.robot_key(robodyn.load("rp_arm"))
