"""robodyn.export.jax_functions and the standalone JAX module against the Pinocchio engine.

Every test enables float64 in a ``jax.enable_x64`` block: the global setting is left alone.
JAX is imported by the tests that use it (a second of CPU): a pytest-xdist worker that
collects this file but runs none of it never imports it.
"""

from __future__ import annotations

import ast

import numpy as np
import pytest

import robodyn
from robodyn.cli import main
from robodyn.exceptions import InputError
from robodyn.export import FUNCTIONS, jax_functions
from robodyn.export.functions import _run
from tests.conftest import NONDEGENERATE_CASES, random_states
from tests.export.cases import CASES, FAST_CASES, differences, exported


@pytest.fixture
def x64():
    import jax

    with jax.enable_x64(True):
        yield


@pytest.mark.parametrize(
    "case", [case if case == FAST_CASES[-1] else pytest.param(case, marks=pytest.mark.slow) for case in sorted(CASES)]
)
def test_every_jax_function_equals_the_pinocchio_engine(case, rng, x64):
    robot, source = exported(case, "jax")
    functions = _run(source)
    assert set(functions) == {*FUNCTIONS, *(f"frame_{kind}:{f}" for f in robot.frame_names for kind in ("position", "jacobian"))}
    q, v, a = (x[0] for x in random_states(robot, rng, 1))
    worst = differences(robot, functions, q, v, a)
    assert max(worst.values()) <= 1e-12, {k: d for k, d in worst.items() if d > 1e-12}


def test_jit_and_vmap_give_the_engine_on_a_batch(rng, x64):
    import jax

    robot, source = exported("gripper_locked_prismatic", "jax")
    functions = _run(source)
    q, v, a = random_states(robot, rng, 7)
    tau = np.asarray(jax.jit(jax.vmap(functions["inverse_dynamics"]))(q, v, a))
    assert tau.dtype == np.float64 and tau.shape == (7, robot.nv)
    assert np.max(np.abs(tau - robot.inverse_dynamics(q, v, a))) <= 1e-12 * max(1.0, np.max(np.abs(tau)))
    accelerations = np.asarray(jax.jit(jax.vmap(functions["forward_dynamics"]))(q, v, tau))
    assert np.max(np.abs(accelerations - a)) <= 1e-10 * max(1.0, np.max(np.abs(a)))
    # Negative control: the rows are not interchangeable.
    assert np.max(np.abs(tau[::-1] - robot.inverse_dynamics(q, v, a))) > 1e-3


def test_jax_grad_equals_finite_differences_of_the_engine(rng, x64):
    import jax

    robot, source = exported("gripper_locked_prismatic", "jax")
    functions = _run(source)
    q, v, tau = (x[0] for x in random_states(robot, rng, 1))
    weights = rng.normal(size=robot.nv)

    def objective(q):
        return weights @ functions["forward_dynamics"](q, v, tau)

    ours = np.asarray(jax.grad(objective)(q))
    h = 1e-6
    central = np.array(
        [
            weights @ (robot.forward_dynamics(q + h * e, v, tau) - robot.forward_dynamics(q - h * e, v, tau)) / (2 * h)
            for e in np.eye(robot.nv)
        ]
    )
    assert np.max(np.abs(ours - central)) < 1e-6 * max(1.0, np.max(np.abs(central)))
    assert np.max(np.abs(ours + central)) > 1e-3  # negative control: the opposite sign is far off


def test_without_float64_jax_functions_are_refused_in_one_line():
    import jax

    robot, _ = exported("oblique_locked")
    with jax.enable_x64(False), pytest.raises(InputError, match="jax_enable_x64"):
        jax_functions(robot)


@pytest.mark.slow  # the CasADi module's test runs the same CLI path in the fast tier
def test_the_cli_writes_a_standalone_module_that_imports_only_jax(tmp_path, rng, x64):
    path = tmp_path / "dyn_jax.py"
    urdf, options = NONDEGENERATE_CASES["oblique_locked"]
    lock = ",".join(f"{name}={value}" for name, value in options["lock"].items())
    assert main(["equations", str(urdf), "--lock", lock, "--format", "jax", "--out", str(path)]) == 0
    source = path.read_text()
    imported = {alias.name for node in ast.walk(ast.parse(source)) if isinstance(node, ast.Import) for alias in node.names}
    assert imported == {"jax", "jax.numpy"}
    robot = robodyn.load(urdf, **options)
    q, v, a = (x[0] for x in random_states(robot, rng, 1))
    assert max(differences(robot, _run(source), q, v, a).values()) <= 1e-12
