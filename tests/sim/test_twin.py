"""Every controller the library and the CLI offer owns its compiled twin, or says why not.

The library's controllers are found by reading robodyn.sim (every class with a
``__call__(self, t, q, v)``), the CLI's by running each name of ``robodyn simulate
--controller``: each has ``twin_refusal()`` and ``compiled()``; where the twin is refused
the reason is one sentence. Adding a controller without a twin (or a stated reason) fails here.
"""

from __future__ import annotations

import ast
import importlib
import inspect

import numpy as np
import pytest

import robodyn
from robodyn.compiled.controllers import TWINS, HasTwin, c_constants, check_layout, size
from robodyn.sim.control import ComputedTorque, PDGravity, TaskSpace
from robodyn.sim.experiment import CONTROLLERS, run_simulation
from tests.conftest import ROOT

#: The controllers without a twin, each with its reason.
NO_TWIN: dict[str, str] = {
    "RecordedStand": "Stand's recording wrapper (the stand run keeps the QP's forces): as Stand",
    "Stand": "a QP a step (Clarabel) over contact forces on a ground, which the compiled engine does not model",
    "HybridForceMotion": "the third lecture's force/motion law runs from Python (pressing a surface: a constrained plant, which the compiled engine does not model)",
}


def library_controllers() -> list[type]:
    """Every class of robodyn.sim whose ``__call__`` takes ``(t, q, v)``: a controller."""
    found = []
    for path in sorted((ROOT / "robodyn" / "sim").glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ClassDef):
                calls = [f for f in node.body if isinstance(f, ast.FunctionDef) and f.name == "__call__"]
                if calls and [a.arg for a in calls[0].args.args] == ["self", "t", "q", "v"]:
                    found.append((path.stem, node.name))
    return [getattr(importlib.import_module(f"robodyn.sim.{module}"), name) for module, name in found]


def test_every_library_controller_owns_a_twin_or_states_why_not():
    classes = library_controllers()
    assert len(classes) >= 6  # PD, computed torque, task space, OSC, impedance, LQR
    for cls in classes:
        has_methods = all(inspect.isfunction(getattr(cls, name, None)) for name in ("twin_refusal", "compiled"))
        assert has_methods or cls.__name__ in NO_TWIN, f"{cls.__name__}: no compiled twin and no stated reason"


@pytest.mark.parametrize("name", [name for name in CONTROLLERS if name not in ("passive", "stand")])  # stand: NO_TWIN
def test_every_cli_controller_owns_a_twin(name, monkeypatch):
    """The controller ``robodyn simulate --controller NAME`` builds, caught on its way to the run."""
    from robodyn.sim import experiment

    built = []
    monkeypatch.setattr(experiment, "simulate_run", lambda *args, **kwargs: built.append(kwargs["controller"]) or 1 / 0)
    robot = robodyn.load("rp_arm")
    q0 = robot.default_configuration()
    target = (q0 + 0.1).tolist() if name in ("pd", "computed-torque", "lqr") else [0.7, 0.0, 0.7]
    with pytest.raises(ZeroDivisionError):
        run_simulation(robot, controller=name, target=target, duration=0.01)
    assert isinstance(built[0], HasTwin) and built[0].twin_refusal() is None


def test_a_refused_twin_says_why_in_one_sentence():
    robot = robodyn.load("rp_arm")
    custom = ComputedTorque(robot, lambda t: (np.zeros(2), np.zeros(2), np.zeros(2)))
    assert custom.twin_refusal() == "computed torque compiles along a quintic_reference only"

    class Louder(PDGravity):
        def __call__(self, t, q, v):
            return 2.0 * super().__call__(t, q, v)

    assert "changes PDGravity's law" in Louder(robot, np.zeros(2)).twin_refusal()
    assert "floating base" in TaskSpace(robodyn.load("solo12"), "FL_FOOT", np.zeros(3)).twin_refusal()


def test_each_twins_parameters_have_the_size_its_layout_declares():
    """The layout the C macros are generated from matches what ``params`` packs (rp_arm, 2 joints)."""
    robot = robodyn.load("rp_arm")
    from robodyn.compiled import controllers as twins

    model = None  # params never reads the model
    made = {
        twins.CompiledPDGravity: twins.CompiledPDGravity(model, np.zeros(2)),  # type: ignore[arg-type]
        twins.CompiledComputedTorque: twins.CompiledComputedTorque(model, np.zeros(2), np.ones(2), 1.0),  # type: ignore[arg-type]
        twins.CompiledTaskSpace: twins.CompiledTaskSpace(model, "end_effector"),  # type: ignore[arg-type]
        twins.CompiledOperationalSpace: twins.CompiledOperationalSpace(model, "end_effector", rotation=np.eye(3)),  # type: ignore[arg-type]
        twins.CompiledImpedance: twins.CompiledImpedance(model, "end_effector"),  # type: ignore[arg-type]
        twins.CompiledLQR: twins.CompiledLQR(model, np.zeros((2, 4)), np.zeros(2), np.eye(2), np.zeros(4)),  # type: ignore[arg-type]
    }
    assert set(made) == set(TWINS)
    for twin_class, twin in made.items():
        assert twin.params(robot.nv).size == size(twin_class, robot.nv), twin_class.__name__
        assert check_layout(twin, robot.nv).size == size(twin_class, robot.nv)
    header = c_constants()
    for kind, twin_class in enumerate(TWINS, start=1):
        assert f"#define RD_KIND_{twin_class.law} {kind}\n" in header
    runtime = (ROOT / "robodyn" / "compiled" / "runtime.c").read_text(encoding="utf-8")
    assert "sizes[" not in runtime and "kind == 1" not in runtime  # no hand-kept table or bare kind left
