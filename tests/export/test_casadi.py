"""robodyn.export.casadi_functions and the standalone CasADi module against the Pinocchio engine."""

from __future__ import annotations

import ast
import importlib.util

import casadi as ca
import numpy as np
import pytest

import robodyn
from robodyn.cli import main
from robodyn.exceptions import FrameError, InputError
from robodyn.export import FUNCTIONS, casadi_functions, module_source
from robodyn.export.functions import _run
from tests.conftest import FAST_ZOO, NONDEGENERATE_CASES, random_states
from tests.equations.test_output import CANARY, hostile_urdf
from tests.export.cases import CASES, FAST_CASES, column, differences, exported


@pytest.mark.parametrize(
    "case", [case if case in FAST_CASES else pytest.param(case, marks=pytest.mark.slow) for case in sorted(CASES)]
)
def test_every_casadi_function_equals_the_pinocchio_engine_on_the_test_robots(case, rng):
    robot, source = exported(case)
    functions = _run(source)
    assert set(functions) == {*FUNCTIONS, *(f"frame_{kind}:{f}" for f in robot.frame_names for kind in ("position", "jacobian"))}
    for q, v, a in zip(*random_states(robot, rng, 3), strict=True):
        worst = differences(robot, functions, q, v, a)
        assert max(worst.values()) <= 1e-12, {k: d for k, d in worst.items() if d > 1e-12}


@pytest.mark.slow
@pytest.mark.parametrize("name", FAST_ZOO)
def test_every_casadi_function_equals_the_pinocchio_engine_on_zoo_arms(name, rng):
    robot, source = exported(name)
    functions = _run(source)
    for q, v, a in zip(*random_states(robot, rng, 3), strict=True):
        worst = differences(robot, functions, q, v, a)
        assert max(worst.values()) <= 1e-12, {k: d for k, d in worst.items() if d > 1e-12}


def test_negative_control_another_gravity_is_told_apart(rng):
    """Functions of the robot under standard gravity differ from the tilted-gravity robot's."""
    _, source = exported("gripper_locked_prismatic")
    tilted, _ = exported("gripper_tilted_gravity")
    q, v, a = (x[0] for x in random_states(tilted, rng, 1))
    worst = differences(tilted, _run(source), q, v, a)
    assert worst["gravity"] > 1e-3 and worst["inverse_dynamics"] > 1e-3
    assert worst["mass_matrix"] <= 1e-12  # gravity does not enter M


def test_casadis_own_derivatives_equal_finite_differences_of_the_engine(rng):
    robot, source = exported("gripper_locked_prismatic")
    functions = _run(source)
    q, v, a = (x[0] for x in random_states(robot, rng, 1))
    qs, vs, accs = (ca.SX.sym(name, robot.nv) for name in ("q", "v", "a"))
    tau = functions["inverse_dynamics"](qs, vs, accs)
    derivative = ca.Function("d", [qs, vs, accs], [ca.jacobian(tau, qs), ca.jacobian(tau, vs), ca.jacobian(tau, accs)])
    ours = [np.array(d) for d in derivative(q, v, a)]
    h, eye = 1e-6, np.eye(robot.nv)
    for ours_d, shift in zip(ours, ((1, 0, 0), (0, 1, 0), (0, 0, 1)), strict=True):

        def moved(sign, i, shift=shift):
            return robot.inverse_dynamics(*(x + sign * h * s * eye[i] for x, s in zip((q, v, a), shift, strict=True)))

        central = np.stack([(moved(1, i) - moved(-1, i)) / (2 * h) for i in range(robot.nv)], axis=1)
        assert np.max(np.abs(ours_d - central)) < 1e-6 * max(1.0, np.max(np.abs(central)))
    # Negative control: a finite difference with the wrong sign is far off.
    assert np.max(np.abs(ours[0] + ours[0])) > 1e-3


def test_kept_parameters_are_an_input_and_obey_the_scaling_law(rng):
    """With keep_params the functions take the parameters; at their values they equal the
    engine; masses and inertias doubled (centres of mass kept) double M, C v and G."""
    robot, _ = exported("oblique_locked")
    module = _run_module(module_source(robot, "casadi", keep_params=True))
    functions = module["functions"]()
    names, values = module["PARAMETER_NAMES"], np.array(module["PARAMETER_VALUES"])
    assert names and len(names) == len(values)
    q, v, a = (x[0] for x in random_states(robot, rng, 1))
    tau = column(functions["inverse_dynamics"](q, v, a, values))
    assert np.max(np.abs(tau - robot.inverse_dynamics(q, v, a))) <= 1e-12 * max(1.0, np.max(np.abs(tau)))
    doubled = np.array([2.0 * x if n.startswith(("m_", "I_")) else x for n, x in zip(names, values, strict=True)])
    assert np.allclose(column(functions["inverse_dynamics"](q, v, a, doubled)), 2 * tau, rtol=1e-12, atol=1e-12)
    half_g = np.array([0.5 * x if n.startswith("g") else x for n, x in zip(names, values, strict=True)])
    assert not np.allclose(column(functions["gravity"](q, half_g)), robot.gravity(q), atol=1e-6)  # negative control


def _run_module(source: str) -> dict:
    namespace: dict = {"__name__": "exported"}
    exec(compile(source, "<exported>", "exec"), namespace)
    return namespace


def test_the_cli_writes_a_standalone_module_that_imports_only_casadi(tmp_path, rng):
    path = tmp_path / "dyn.py"
    urdf, _ = NONDEGENERATE_CASES["gripper"]
    assert main(["equations", str(urdf), "--lock", "j_left=-0.015", "--format", "casadi", "--out", str(path)]) == 0
    tree = ast.parse(path.read_text())
    imported = {alias.name for node in ast.walk(tree) if isinstance(node, ast.Import | ast.ImportFrom) for alias in node.names}
    assert imported == {"casadi"}
    spec = importlib.util.spec_from_file_location("dyn", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    robot, _ = exported("gripper_locked_prismatic")
    q, v, a = (x[0] for x in random_states(robot, rng, 1))
    assert max(differences(robot, module.functions(), q, v, a).values()) <= 1e-12


def test_hostile_names_never_reach_the_code(tmp_path, monkeypatch, rng):
    monkeypatch.chdir(tmp_path)
    robot = robodyn.load(hostile_urdf())
    source = module_source(robot, "casadi")
    tree = ast.parse(source)
    names = [node.value for node in ast.walk(tree) if isinstance(node, ast.Constant) and isinstance(node.value, str)]
    assert set(robot.joint_names) <= set(names) and set(robot.frame_names) <= set(names)
    assert all(line.isascii() and line.isprintable() for line in source.splitlines())
    functions = _run(source)
    assert not (tmp_path / CANARY).exists()
    q, v, a = (x[0] for x in random_states(robot, rng, 1))
    assert max(differences(robot, functions, q, v, a).values()) <= 1e-12
    # Negative control: the names do break code when pasted raw.
    with pytest.raises(SyntaxError):
        compile(f"JOINT_NAMES = ['{robot.joint_names[0]}']", "<raw>", "exec")


def test_forward_dynamics_is_the_tree_factorisation_not_a_dense_inverse():
    """A branching robot's forward dynamics costs less than M, C v + G and a dense solve."""
    robot, source = exported("gripper_locked_prismatic")
    functions = _run(source)
    q = ca.SX.sym("q", robot.nv)
    dense = ca.Function("dense", [q], [ca.solve(functions["mass_matrix"](q), ca.SX.ones(robot.nv))])
    assert functions["forward_dynamics"].n_instructions() < functions["mass_matrix"].n_instructions() + (
        functions["nonlinear_effects"].n_instructions() + dense.n_instructions()
    )


def test_floating_bases_and_unknown_frames_are_refused_in_one_line():
    with pytest.raises(InputError, match="fixed-base"):
        casadi_functions(robodyn.load(NONDEGENERATE_CASES["oblique_floating"][0], floating_base=True))
    with pytest.raises(FrameError):
        module_source(exported("oblique_locked")[0], "casadi", frames=["no such frame"])
    with pytest.raises(InputError, match="backend"):
        module_source(exported("oblique_locked")[0], "fortran")  # type: ignore[arg-type]
