"""robodyn.compiled against Pinocchio (the Robot): values, shapes, input checks, cache, refusals."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import robodyn
from robodyn.compiled import build, codegen, compile
from robodyn.exceptions import CompileError, CompilerNotFoundError, InputError, SingularMassMatrixError
from tests.compiled_helpers import QUANTITIES, RTOL, arguments, compare, compiled_pair, relative_error, shared_cache
from tests.conftest import ROOT
from tests.random_robots import JOINT_TYPES, urdf_from_seed

MIMIC_TREE = ROOT / "tests" / "data" / "compiled_mimic_tree.urdf"


@pytest.fixture(scope="module", autouse=True)
def cache():
    """The session's compile cache (never the user's)."""
    with shared_cache() as folder:
        yield folder


@pytest.fixture(scope="module")
def mimic_tree():
    return compiled_pair(MIMIC_TREE)


@pytest.fixture(scope="module")
def rp_arm():
    return compiled_pair("rp_arm")


@pytest.mark.parametrize("source", ["rp_arm", "double_pendulum", MIMIC_TREE])
def test_compiled_matches_pinocchio_one_state_and_batches(source, rng):
    robot, compiled = compiled_pair(source)
    compare(compiled, robot, rng)
    compare(compiled, robot, rng, count=7)
    compare(compiled, robot, rng, count=1000)  # several threads


def test_mimic_map_is_exercised(mimic_tree):
    robot, _ = mimic_tree
    assert robot.mimic is not None and robot.nv == 3
    multiplier = robot.mimic.selection[robot.mimic.selection[:, 0] != 0, 0]
    assert sorted(multiplier) == pytest.approx([-1.7, 1.0])


def test_negative_control_a_wrong_compiled_robot_fails_the_comparison(rng, tmp_path):
    """One link 1e-6 heavier: the comparison helper must notice (else it checks nothing)."""
    robot = robodyn.load("rp_arm")
    mass = re.search(r'<mass value="([^"]+)"', robot.urdf)
    heavier = float(mass.group(1)) * (1 + 1e-6)
    path = tmp_path / "heavier.urdf"
    path.write_text(robot.urdf[: mass.start(1)] + repr(heavier) + robot.urdf[mass.end(1) :], encoding="utf-8")
    wrong = compile(robodyn.load(path))
    with pytest.raises(AssertionError, match="compiled differs"):
        compare(wrong, robot, rng)
    args = arguments(robot, rng)["inverse_dynamics"]
    tau = robot.inverse_dynamics(*args)
    assert relative_error(tau * (1 + 10 * RTOL), tau) > RTOL


@pytest.mark.slow
@pytest.mark.parametrize(
    ("source", "options"),
    [
        ("ur5", {}),
        ("panda", {}),
        ("panda", {"lock": {"panda_finger_joint1": 0.013}}),
        ("double_pendulum_continuous", {}),
        ("z1", {}),
        ("kinova", {"check_inertia": False}),
        ("so101", {"check_inertia": False}),
    ],
)
def test_compiled_zoo_arms_match_pinocchio(source, options, rng):
    robot, compiled = compiled_pair(source, **options)
    compare(compiled, robot, rng)
    compare(compiled, robot, rng, count=500)


def _random_tree(seed: int, joints: int, types: list[str], rng: np.random.Generator) -> None:
    robot, compiled = compiled_pair(urdf_from_seed(seed, joints, types))
    compare(compiled, robot, rng, count=20, rtol=RTOL)


@settings(max_examples=2, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(seed=st.integers(0, 2**32 - 1), joints=st.integers(1, 3), types=JOINT_TYPES)
def test_random_trees_match_pinocchio(seed, joints, types, rng):
    _random_tree(seed, joints, types, rng)


@pytest.mark.slow
@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(seed=st.integers(0, 2**32 - 1), joints=st.integers(1, 7), types=JOINT_TYPES)
def test_random_trees_match_pinocchio_many(seed, joints, types, rng):
    _random_tree(seed, joints, types, rng)


# --------------------------------------------------------------------------------------
# The Robot's shape rules and input checks
# --------------------------------------------------------------------------------------
def test_shapes_follow_the_robot(mimic_tree, rng):
    robot, compiled = mimic_tree
    n = robot.nv
    for count, lead in ((None, ()), (4, (4,)), (0, (0,))):
        args = (
            arguments(robot, rng, count)
            if count != 0
            else {k: tuple(np.zeros((0, n)) for _ in v) for k, v in arguments(robot, rng).items()}
        )
        for name in QUANTITIES:
            expected = (*lead, n, n) if name == "mass_matrix" else (*lead, n)
            assert getattr(compiled, name)(*args[name]).shape == expected


def test_other_array_kinds_take_the_checked_path(mimic_tree, rng):
    robot, compiled = mimic_tree
    q, v, a = arguments(robot, rng, 6)["inverse_dynamics"]
    expected = robot.inverse_dynamics(q, v, a)
    fortran = [np.asfortranarray(x) for x in (q, v, a)]
    strided = [np.repeat(x, 2, axis=0)[::2] for x in (q, v, a)]
    assert relative_error(compiled.inverse_dynamics(*[x.tolist() for x in (q, v, a)]), expected) <= RTOL
    assert relative_error(compiled.inverse_dynamics(*fortran), expected) <= RTOL
    assert relative_error(compiled.inverse_dynamics(*strided), expected) <= RTOL
    assert relative_error(compiled.inverse_dynamics(q[0].tolist(), v[0], a[0]), expected[0]) <= RTOL
    assert relative_error(compiled.mass_matrix(q.astype(">f8")), robot.mass_matrix(q)) <= RTOL


@pytest.mark.parametrize(
    "bad",
    [
        {"q": np.zeros(2)},
        {"q": np.array([0.1, np.nan, 0.2])},
        {"v": np.array([0.0, np.inf, 0.0])},
        {"q": np.zeros((3, 3)), "v": np.zeros((2, 3)), "a": np.zeros((3, 3))},
        {"q": "abc"},
    ],
)
def test_bad_inputs_get_the_robots_error(mimic_tree, bad):
    robot, compiled = mimic_tree
    args = {"q": np.zeros(3), "v": np.zeros(3), "a": np.zeros(3)} | bad
    with pytest.raises(InputError) as theirs:
        robot.inverse_dynamics(**args)
    with pytest.raises(InputError) as ours:
        compiled.inverse_dynamics(**args)
    assert str(ours.value) == str(theirs.value)
    with pytest.raises(InputError):
        compiled.forward_dynamics(args["q"], args["v"], args["a"])


def test_nan_in_one_row_of_a_batch_is_refused(mimic_tree, rng):
    robot, compiled = mimic_tree
    q, v = arguments(robot, rng, 300)["nonlinear_effects"]
    v[211, 1] = np.nan
    with pytest.raises(InputError, match=r"^v "):
        compiled.nonlinear_effects(q, v)


def test_singular_mass_matrix_is_refused_like_the_robot(tmp_path):
    text = urdf_from_seed(3, 2, ["revolute"])
    head, _, _ = text.rpartition("<inertial>")
    text = (
        head + '<inertial><mass value="0"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>\n</robot>'
    )
    robot = robodyn.load(text, check_inertia=False)
    compiled = compile(robot)
    zero = np.zeros(robot.nv)
    with pytest.raises(SingularMassMatrixError):
        robot.forward_dynamics(zero, zero, zero)
    with pytest.raises(SingularMassMatrixError):
        compiled.forward_dynamics(zero, zero, zero)
    with pytest.raises(SingularMassMatrixError):
        compiled.forward_dynamics(np.zeros((200, robot.nv)), np.zeros((200, robot.nv)), np.zeros((200, robot.nv)))


def test_no_compiler_says_what_to_install_and_pinocchio_keeps_working(monkeypatch, rp_arm):
    robot, _ = rp_arm
    monkeypatch.setenv("CC", "no-such-compiler-robodyn")
    with pytest.raises(CompilerNotFoundError, match="install") as error:
        compile(robot)
    assert "\n" not in str(error.value)
    assert robot.inverse_dynamics(np.zeros(2), np.zeros(2), np.zeros(2)).shape == (2,)


def test_bad_threads_are_refused(rp_arm):
    robot, _ = rp_arm
    for threads in (0, -1, 1.5, True):
        with pytest.raises(InputError, match="threads"):
            compile(robot, threads=threads)


def test_generated_code_has_no_urdf_names(mimic_tree):
    """Every identifier of the generated kernels is the generator's own (t0, th1, q, mb, ...)."""
    robot, _ = mimic_tree
    from robodyn.compiled.robot import robot_key

    kernels = build.cached_kernels(robot_key(robot))
    assert kernels is not None
    code = re.sub(r"/\*.*?\*/", "", kernels.replace(codegen.trig_source(), ""), flags=re.S)  # less sin/cos (fixed text)
    code = re.sub(r"\b\d[\d.]*e[-+]?\d+", "0", code)  # the exponents of float literals
    identifiers = set(re.findall(r"[A-Za-z_][A-Za-z_0-9]*", code))
    generated = re.compile(r"^(t|r|th|thd|thdd)\d+$")
    words = {
        "static",
        "void",
        "const",
        "double",
        "int",
        "for",
        "define",
        "RD_NV",
        "RD_NQ",
        "RD_QUATERNION_TOLERANCE",
        "rd_parent",
        "rd_depth",
        "rd_ancestor",
        "q",
        "v",
        "a",
        "g",
        "M",
        "nle",
        "tau",
        "i",
        "j",
        "mb",
        "hb",
        "gb",
        "tb",
        "ab",
        "fb",
        "sin",
        "cos",
        "rd_sin",
        "rd_cos",
        "pow",
        "sqrt",
        "M_SQRT2",
        "M_SQRT1_2",
        "rd_gravity",
        "rd_nle",
        "rd_mass",
        "rd_mass_nle",
        "rd_tau",
    }
    assert {name for name in identifiers if not generated.match(name)} <= words
    assert '"' not in code and "&" not in code


# --------------------------------------------------------------------------------------
# The cache
# --------------------------------------------------------------------------------------
def test_second_compile_uses_the_cache(rp_arm, monkeypatch):
    robot, compiled = rp_arm
    monkeypatch.setattr(build, "_compile", lambda *a, **k: pytest.fail("compiled again"))
    monkeypatch.setattr("robodyn.compiled.robot.generate_kernels", lambda robot: pytest.fail("derived again"))
    again = compile(robot)
    assert again.module is compiled.module


@pytest.mark.slow
def test_two_processes_compiling_at_once_both_succeed(tmp_path):
    script = textwrap.dedent(
        """
        import numpy as np, robodyn
        from robodyn.compiled import compile
        robot = robodyn.load("pendulum")
        q = np.full(robot.nv, 0.3); print(repr(float(np.abs(compile(robot).gravity(q) - robot.gravity(q)).max())))
        """
    )
    env = os.environ | {"ROBODYN_CACHE": str(tmp_path)}
    processes = [subprocess.Popen([sys.executable, "-c", script], env=env, stdout=subprocess.PIPE, text=True) for _ in range(2)]
    outputs = [process.communicate(timeout=300)[0] for process in processes]
    assert all(process.returncode == 0 for process in processes)
    assert all(abs(float(output)) < 1e-12 for output in outputs)
    leftovers = [path.name for path in (tmp_path / "compiled").iterdir() if path.name.startswith(".")]
    assert leftovers == []
    assert len(list((tmp_path / "compiled").glob("rd_*"))) == 1


def test_an_unwritable_cache_is_a_one_line_error(rp_arm, monkeypatch, tmp_path):
    robot, _ = rp_arm
    blocker = tmp_path / "file"
    blocker.write_text("not a folder", encoding="utf-8")
    monkeypatch.setenv("ROBODYN_CACHE", str(blocker))
    with pytest.raises(CompileError, match="ROBODYN_CACHE") as error:
        compile(robot)
    assert "\n" not in str(error.value)


def test_threads_split_rows_without_changing_results(mimic_tree, rng):
    robot, compiled = mimic_tree
    q, v, tau = arguments(robot, rng, 1000)["forward_dynamics"]
    one = compile(robot, threads=1).forward_dynamics(q, v, tau)
    np.testing.assert_array_equal(compiled.forward_dynamics(q, v, tau), one)
    np.testing.assert_array_equal(np.stack([compiled.forward_dynamics(*row) for row in zip(q, v, tau, strict=True)]), one)
