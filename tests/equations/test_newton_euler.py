"""The symbolic Newton–Euler program against the Pinocchio engine, and its refusals.

The program (:func:`robodyn.equations.newton_euler.derive_newton_euler`) is the one the
compact equations and the compiled ``tau`` kernel are built from; here its ``tau`` is
evaluated in floating point and compared with ``robodyn.load(...).inverse_dynamics``.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import sympy as sp

import robodyn
from robodyn import reference
from robodyn.equations.compact import derive_compact
from robodyn.equations.newton_euler import derive_newton_euler
from robodyn.equations.program import Program, evaluate
from robodyn.exceptions import InputError
from robodyn.reference.numeric import ReferenceRobot
from tests.conftest import ROOT

#: Not the default gravity, and off every axis, so a gravity term in the wrong frame shows.
GRAVITY = (0.7, -1.3, -9.2)
ROBOTS = ["rp_arm", "ur5", "panda", str(ROOT / "tests/data/rrp_arm.urdf"), str(ROOT / "tests/data/mimic_arm.urdf")]
#: Largest error relative to the torques' size: the program is exact up to float rounding.
RTOL = 1e-10


def _engine_and_program(name: str, **options) -> tuple[robodyn.Robot, ReferenceRobot, Program]:
    robot = robodyn.load(name, gravity=GRAVITY)
    model = reference.load(name, gravity=GRAVITY)
    return robot, model, derive_newton_euler(model, **options)


def _program_tau(program: Program, model: ReferenceRobot, robot, q, v, a) -> np.ndarray:
    """The program's tau at a state of the robot, in the robot's joint order."""
    order = [robot.joint_names.index(name) for name in model.joint_names]
    tau = evaluate(program, {"q": q[order], "qd": v[order], "qdd": a[order]})["tau"]
    out = np.empty_like(tau)
    out[order] = tau
    return out


def _error(ours: np.ndarray, theirs: np.ndarray) -> float:
    return float(np.abs(ours - theirs).max() / max(1.0, np.abs(theirs).max()))


@pytest.mark.parametrize("name", ROBOTS, ids=lambda n: n.rsplit("/", 1)[-1])
def test_the_program_gives_pinocchios_torques_at_random_states(name, rng):
    robot, model, program = _engine_and_program(name)
    assert model.nv == robot.nv and sorted(model.joint_names) == sorted(robot.joint_names)
    for _ in range(5):
        q = robot.random_configuration(rng)
        v, a = rng.normal(size=(2, robot.nv))
        assert _error(_program_tau(program, model, robot, q, v, a), robot.inverse_dynamics(q, v, a)) < RTOL


def test_a_mimic_joint_enters_through_its_leader(rng):
    """panda's second finger follows the first: the program has one coordinate for both."""
    _, model, program = _engine_and_program("panda")
    assert len(model.tree.bodies) == len(program.inputs["q"]) + 1
    assert len(program.outputs["tau"]) == len(program.inputs["q"]) == 8


def test_kept_parameters_give_the_same_torques(rng):
    robot, model, program = _engine_and_program(str(ROOT / "tests/data/rrp_arm.urdf"), keep_params=True)
    kinds = {kind for kind, _, _ in program.labels.values()}
    assert {"m", "c", "I", "g"} <= kinds and set(program.parameters) == set(program.labels)
    q = robot.random_configuration(rng)
    v, a = rng.normal(size=(2, robot.nv))
    assert _error(_program_tau(program, model, robot, q, v, a), robot.inverse_dynamics(q, v, a)) < RTOL


def test_the_compact_equations_and_the_program_agree(rng):
    """``M q̈ + C q̇ + G`` of the compact form equals the program's ``tau`` (both built from
    the same passes; a pass that drifted apart would show here)."""
    model = reference.load("ur5", gravity=GRAVITY)
    program = derive_newton_euler(model)
    compact = derive_compact(model, symbols=tuple(list(program.inputs[k]) for k in ("q", "qd", "qdd")), snap=1e-15)
    q, v, a = rng.normal(size=(3, model.nv))
    terms = evaluate(compact.program(), {"q": q, "qd": v})
    tau = terms["M"].reshape(model.nv, model.nv) @ a + terms["Cv"] + terms["G"]
    assert _error(tau, evaluate(program, {"q": q, "qd": v, "qdd": a})["tau"]) < RTOL


def test_a_floating_base_is_refused_by_name():
    model = reference.load("rp_arm", floating_base=True)
    with pytest.raises(InputError, match="fixed-base robot") as caught:
        derive_newton_euler(model)
    assert caught.value.argument == "robot"
    with pytest.raises(InputError, match="fixed-base robot"):
        derive_compact(model)


def test_negative_control_a_heavier_link_fails_the_comparison(rng):
    robot, model, _ = _engine_and_program("ur5")
    bodies = list(model.tree.bodies)
    bodies[2] = dataclasses.replace(bodies[2], mass=bodies[2].mass * 1.01)
    heavier = dataclasses.replace(model.tree, bodies=bodies)
    changed = ReferenceRobot(heavier, name=model.name, urdf=model.urdf, spec=model.spec, gravity=model.gravity_vector)
    program = derive_newton_euler(changed)
    q = robot.random_configuration(rng)
    v, a = rng.normal(size=(2, robot.nv))
    assert _error(_program_tau(program, changed, robot, q, v, a), robot.inverse_dynamics(q, v, a)) > 1e3 * RTOL


def test_negative_control_a_perturbed_assignment_fails_the_comparison(rng):
    robot, model, program = _engine_and_program("ur5")
    assignments = list(program.assignments)
    middle = len(assignments) // 2
    symbol, expr = assignments[middle]
    assignments[middle] = (symbol, expr * (1 + sp.Rational(1, 10**6)))
    perturbed = dataclasses.replace(program, assignments=tuple(assignments))
    q = robot.random_configuration(rng)
    v, a = rng.normal(size=(2, robot.nv))
    expected = robot.inverse_dynamics(q, v, a)
    assert _error(_program_tau(program, model, robot, q, v, a), expected) < RTOL
    assert _error(_program_tau(perturbed, model, robot, q, v, a), expected) > 1e-9


def _free_base_programs(rng):
    """The floating oblique robot's reference robot and its free-base programs (tau; M, C v, G)."""
    from robodyn.equations.newton_euler import BaseSymbols, floating_reference
    from tests.conftest import NONDEGENERATE_CASES

    path = str(NONDEGENERATE_CASES["oblique_floating"][0])
    model = reference.load(path, floating_base=True, gravity=GRAVITY)
    base = BaseSymbols.make()
    folded = floating_reference(model)
    return model, derive_newton_euler(folded, free_base=base), derive_compact(folded, free_base=base, cse=False).program()


def test_a_free_base_program_gives_the_references_floating_dynamics(rng):
    """Base rows (force then moment, base frame) and joint rows of tau, M, C v, G against the
    reference's floating model (its own Lagrangian, no Pinocchio), at a tilted pose; negative
    control: the velocity in world axes fails."""
    model, tau_program, compact = _free_base_programs(rng)
    n = model.nv - 6
    quaternion = rng.normal(size=4)
    q = np.concatenate([rng.normal(size=3), quaternion / np.linalg.norm(quaternion), rng.normal(size=n)])
    v, a = rng.normal(size=model.nv), rng.normal(size=model.nv)

    def inputs(v):
        return {"q": q[7:], "qd": v[6:], "qdd": a[6:], "base_q": q[3:7], "base_v": v[:6], "base_a": a[:6]}

    def torques(v):
        out = evaluate(tau_program, inputs(v))
        return np.concatenate([out["base"], out["tau"]])

    expected = model.inverse_dynamics(q, v, a)
    assert np.abs(torques(v) - expected).max() < RTOL * np.abs(expected).max()
    world = v.copy()
    world[:3] = v[3:6]  # a wrong velocity (the angular part as the linear one)
    assert np.abs(torques(world) - expected).max() > 1e-3 * np.abs(expected).max()
    out = evaluate(compact, {key: value for key, value in inputs(v).items() if key in compact.inputs})
    M = model.mass_matrix(q)
    M_ours = np.zeros_like(M)
    M_ours[:6] = out["base_M"].reshape(6, -1)
    M_ours[:, :6] = M_ours[:6].T
    M_ours[6:, 6:] = out["M"].reshape(n, n)
    assert np.abs(M_ours - M).max() < RTOL * np.abs(M).max()
    nle = np.concatenate([out["base_Cv"] + out["base_G"], out["Cv"] + out["G"]])
    assert np.abs(nle - model.nonlinear_effects(q, v)).max() < RTOL * np.abs(nle).max()
