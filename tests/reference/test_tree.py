"""Armature in the reference's tree: one rotor body a joint, so every method that sums over
bodies includes it — the numeric reference, the closed form, the compact equations, the
Newton–Euler program and the compiled engine — checked against Pinocchio's ``model.armature``
and against ``M + diag(a)`` by hand."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

import robodyn
from robodyn import reference
from robodyn.equations.compact import derive_compact
from robodyn.equations.newton_euler import derive_newton_euler
from robodyn.equations.program import evaluate
from robodyn.reference.regressor import reference_parameters
from robodyn.reference.symbolic import derive
from tests.conftest import NONDEGENERATE

#: The RP arm: a revolute joint (armature in [kg m²]) and a prismatic one (in [kg]).
RP_ARMATURE = {"joint1": 0.05, "joint2": 0.7}


def test_the_closed_form_gets_the_armature_on_the_diagonal_exactly():
    with_rotors = derive(reference.load("rp_arm", armature=RP_ARMATURE))
    plain = derive(reference.load("rp_arm"))
    assert sp.simplify(with_rotors.M - plain.M) == sp.diag(sp.Rational(1, 20), sp.Rational(7, 10))
    assert sp.simplify(with_rotors.C - plain.C) == sp.zeros(2, 2)  # constant: no Coriolis term
    assert sp.simplify(with_rotors.G - plain.G) == sp.zeros(2, 1)  # massless: no weight


def test_the_compact_equations_and_the_newton_euler_program_include_the_armature(rng):
    robot = robodyn.load("rp_arm", armature=RP_ARMATURE, gravity=[0.5, 0.0, -9.7])
    model = reference.load("rp_arm", armature=RP_ARMATURE, gravity=[0.5, 0.0, -9.7])
    compact = derive_compact(model).program()
    program = derive_newton_euler(model)
    for _ in range(5):
        q, v, a = robot.random_configuration(rng), rng.normal(size=2), rng.normal(size=2)
        terms = evaluate(compact, {"q": q, "qd": v})
        np.testing.assert_allclose(terms["M"].reshape(2, 2), robot.mass_matrix(q), atol=1e-12)
        np.testing.assert_allclose(
            evaluate(program, {"q": q, "qd": v, "qdd": a})["tau"], robot.inverse_dynamics(q, v, a), atol=1e-12
        )
    plain = robodyn.load("rp_arm", gravity=[0.5, 0.0, -9.7])
    assert np.abs(terms["M"].reshape(2, 2) - plain.mass_matrix(q)).max() > 0.04  # negative control


def test_rotors_carry_no_rigid_body_parameter_and_no_link_of_the_robot():
    model = reference.load(NONDEGENERATE / "mimic_tree.urdf", armature={"j_shoulder": 0.02, "j_finger": 0.003})
    rotors = [body for body in model.tree.bodies if body.rotor]
    assert [body.joint for body in rotors] == ["j_shoulder", "j_finger"]
    assert all(body.mass == 0 and body.parent == -1 and body.link not in model.spec.links for body in rotors)
    plain = reference.load(NONDEGENERATE / "mimic_tree.urdf")
    np.testing.assert_array_equal(reference_parameters(model), reference_parameters(plain))
    assert model.joint_names == plain.joint_names


@pytest.mark.slow
def test_the_compiled_engine_includes_the_armature_of_mimic_joints(rng, tmp_path, monkeypatch):
    monkeypatch.setenv("ROBODYN_CACHE", str(tmp_path))
    robot = robodyn.load(NONDEGENERATE / "mimic_gripper.urdf", armature={"j_rotate": 0.02, "j_thumb": 0.003, "j_right": 0.2})
    compiled = robodyn.compile(robot)
    q, v, a = robot.random_configuration(rng, 7), rng.normal(size=(7, robot.nv)), rng.normal(size=(7, robot.nv))
    tau = robot.inverse_dynamics(q, v, a)
    assert np.abs(compiled.mass_matrix(q) - robot.mass_matrix(q)).max() < 1e-12
    assert np.abs(compiled.inverse_dynamics(q, v, a) - tau).max() < 1e-11
    assert np.abs(compiled.forward_dynamics(q, v, tau) - a).max() < 1e-10
