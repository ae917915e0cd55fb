"""One dynamics protocol: the Pinocchio robot and the compiled robot answer the same calls."""

from __future__ import annotations

import inspect

import numpy as np
import pytest

import robodyn
from robodyn.compiled import CompiledRobot
from robodyn.dynamics.protocol import METHODS, Dynamics
from robodyn.dynamics.robot import Robot
from tests.compiled_helpers import compiled_pair


def _mismatches(cls: type) -> list[str]:
    """The protocol's methods whose signature in ``cls`` is not the protocol's (names, kinds,
    defaults and annotations of every parameter, and the return annotation)."""
    return [
        f"{cls.__name__}.{method}{inspect.signature(getattr(cls, method))}"
        for method in METHODS
        if str(inspect.signature(getattr(cls, method))) != str(inspect.signature(getattr(Dynamics, method)))
    ]


def test_robot_and_compiled_robot_have_the_protocols_signatures():
    assert _mismatches(Robot) == []
    assert _mismatches(CompiledRobot) == []
    assert set(METHODS) == {name for name in vars(Dynamics) if not name.startswith("_")} - {"name", "nq", "nv", "joint_names"}


def test_negative_control_a_method_without_joint_friction_is_told_apart():
    class Older(CompiledRobot):
        def inverse_dynamics(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:  # type: ignore[override]
            return super().inverse_dynamics(q, v, a)

    assert [entry.split("(")[0] for entry in _mismatches(Older)] == ["Older.inverse_dynamics"]


@pytest.fixture(scope="module")
def rough(tmp_path_factory):
    """The RP arm with viscous damping and Coulomb friction in its joints, a tilted gravity."""
    text = robodyn.load("rp_arm").urdf
    for joint, (b, f) in {"joint1": (0.3, 0.7), "joint2": (1.1, 2.5)}.items():
        head = f'<joint name="{joint}"'
        start = text.index(head)
        end = text.index("</joint>", start)
        text = text[:end] + f'  <dynamics damping="{b}" friction="{f}"/>\n  ' + text[end:]
    path = tmp_path_factory.mktemp("rough") / "rough_arm.urdf"
    path.write_text(text, encoding="utf-8")
    return compiled_pair(str(path), gravity=(0.4, -0.3, -9.6))


def test_both_engines_are_dynamics_and_give_the_same_friction_torques(rough, rng):
    robot, compiled = rough
    assert isinstance(robot, Dynamics) and isinstance(compiled, Dynamics)
    assert np.all(robot.joint_friction > 0) and np.all(robot.joint_damping > 0)
    for count in (None, 67):
        shape = (robot.nv,) if count is None else (count, robot.nv)
        q, v, a = (rng.uniform(-1, 1, shape) for _ in range(3))
        ours = compiled.inverse_dynamics(q, v, a, joint_friction=True)
        theirs = robot.inverse_dynamics(q, v, a, joint_friction=True)
        assert np.abs(ours - theirs).max() < 1e-12 * max(1.0, np.abs(theirs).max())
        rigid = compiled.inverse_dynamics(q, v, a)
        assert np.abs(ours - rigid).min() > 0.1  # negative control: the friction torques are there
        friction = robot.joint_damping * v + robot.joint_friction * np.sign(v)
        assert np.allclose(ours - rigid, friction, rtol=1e-12, atol=1e-12)  # b v + f sign(v), by hand


def test_the_compiled_coriolis_matrix_times_v_is_the_compiled_c_v(rough, rng):
    """``C(q, v) v = (C v + G) − G`` with the compiled kernels on the right: a check of the
    matrix against independent code, one state and a batch."""
    robot, compiled = rough
    for count in (None, 5):
        shape = (robot.nv,) if count is None else (count, robot.nv)
        q, v = rng.uniform(-1, 1, shape), rng.uniform(-2, 2, shape)
        C = compiled.coriolis_matrix(q, v)
        assert C.shape == (*shape[:-1], robot.nv, robot.nv)
        cv = np.einsum("...ij,...j->...i", C, v)
        expected = compiled.nonlinear_effects(q, v) - compiled.gravity(q)
        assert np.abs(cv - expected).max() < 1e-12 * max(1.0, np.abs(expected).max())
        assert np.abs(expected).max() > 1e-3  # not zero by accident
