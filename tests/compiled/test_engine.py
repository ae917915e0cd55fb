"""A Robot whose kernels are built answers its single calls with them: Pinocchio's numbers to
1e-13, the same refusals word for word; a robot whose kernels are not built, or loaded with
engine="pinocchio", uses Pinocchio."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

import robodyn
from robodyn.compiled import build
from robodyn.exceptions import InputError, RobodynError
from tests.compiled.test_floating import FLOATING_TREE
from tests.compiled.test_floating import GRAVITY as FLOATING_GRAVITY
from tests.compiled_helpers import shared_cache
from tests.conftest import NONDEGENERATE_CASES, random_states

#: The robots each check runs on: a 3-D zoo arm, the oblique robot (its build is
#: test_kinematics.py's), mimic joints that are not the identity on a tree (mimic_tree, the
#: build test_simd.py and test_derivatives.py make), a floating tree with oblique joints, a
#: mimic joint and armature (test_floating.py's build). The zoo's mimic finger and floating
#: quadruped (a build of their own each, 11 s of CPU) run in the slow tier.
CASES = [
    "ur5",
    pytest.param("panda_mimic", marks=pytest.mark.slow),
    pytest.param("solo12", marks=pytest.mark.slow),
    "oblique",
    "mimic_tree",
    "floating_tree",
]
#: ur5 and mimic_tree under a tilted gravity: the builds tests/compiled/test_simd.py makes
#: (one per session), and a gravity that is not the default.
UR5_GRAVITY = [1.3, -0.8, -9.4]
QUANTITIES = ("inverse_dynamics", "forward_dynamics", "mass_matrix", "gravity", "nonlinear_effects")


@pytest.fixture(scope="module", autouse=True)
def cache():
    """The session's compile cache (never the user's)."""
    with shared_cache() as folder:
        yield folder


def _load(name: str, **options) -> robodyn.Robot:
    options.setdefault("engine", "auto")  # tests/compiled/conftest.py makes Pinocchio the default here
    if name == "floating_tree":
        return robodyn.load(FLOATING_TREE, floating_base=True, gravity=FLOATING_GRAVITY, armature={"j4": 0.02}, **options)
    if name in ("ur5", "mimic_tree"):
        options.setdefault("gravity", UR5_GRAVITY)
    if name in NONDEGENERATE_CASES:
        path, extra = NONDEGENERATE_CASES[name]
        return robodyn.load(str(path), **extra, **options)
    return robodyn.load("panda" if name == "panda_mimic" else name, **options)  # panda: its mimic finger


class _Pairs(dict):
    """Each case as (engine="auto", its kernels built) and (engine="pinocchio"), built when a
    test first asks for it (the slow tier's robots are never built by the fast one)."""

    def __missing__(self, name: str) -> tuple[robodyn.Robot, robodyn.Robot]:
        robodyn.compile(_load(name, engine="pinocchio"))  # builds once (cached afterwards)
        self[name] = (_load(name), _load(name, engine="pinocchio"))
        return self[name]


@pytest.fixture(scope="module")
def pairs() -> dict[str, tuple[robodyn.Robot, robodyn.Robot]]:
    """Each case as (engine="auto", its kernels built) and (engine="pinocchio")."""
    return _Pairs()


def _call(robot, method, q, v, x):
    arguments = {"mass_matrix": (q,), "gravity": (q,), "nonlinear_effects": (q, v)}.get(method, (q, v, x))
    return getattr(robot, method)(*arguments)


@pytest.mark.parametrize("name", CASES)
def test_a_robot_whose_kernels_are_built_answers_with_them_within_1e13_of_pinocchio(pairs, name, rng):
    fast, slow = pairs[name]
    assert (fast.handle.engine, slow.handle.engine) == ("compiled", "pinocchio")
    Q, V, X = random_states(fast, rng, 9)
    differ = 0
    for q, v, x in zip(Q, V, X, strict=True):
        for method in QUANTITIES:
            got, expected = _call(fast, method, q, v, x), _call(slow, method, q, v, x)
            assert got.shape == expected.shape
            scale = max(np.abs(expected).max(), 1.0)
            assert np.abs(got - expected).max() <= 1e-13 * scale, (method, np.abs(got - expected).max() / scale)
            differ += not np.array_equal(got, expected)
        # a batch goes through the kernels too: every row bit for bit its single call
        for method in QUANTITIES:
            stacked = _call(fast, method, Q, V, X)
            np.testing.assert_array_equal(stacked[3], _call(fast, method, Q[3], V[3], X[3]))
    assert differ > 0  # negative control: another engine answered (not Pinocchio's bits)


def test_the_mimic_robots_mass_matrix_is_the_reduced_one_of_its_coordinates(pairs, rng):
    fast, slow = pairs["mimic_tree"]  # multipliers 0.6, -1.8, -2.5 (a finger's 1 would hide a missing one)
    assert fast.mimic is not None and fast.nv == 3 and fast.mimic.model.nv == 6
    q = fast.random_configuration(rng)
    mass = fast.mass_matrix(q)
    assert mass.shape == (3, 3)
    np.testing.assert_array_equal(mass, mass.T)
    # against the expanded model's M projected independently: Sᵀ M_full S
    selection = fast.mimic.selection
    full = slow.mimic
    expanded = np.triu(_crba(full.model, full.q(q)))
    expanded = expanded + np.triu(expanded, 1).T
    np.testing.assert_allclose(mass, selection.T @ expanded @ selection, rtol=0, atol=1e-13 * np.abs(mass).max())
    np.testing.assert_allclose(mass, slow.mass_matrix(q), rtol=0, atol=1e-13 * np.abs(mass).max())


def _crba(model, q):
    import pinocchio as pin

    return pin.crba(model, model.createData(), q)


def _refusal(call) -> str:
    with pytest.raises(RobodynError) as raised:
        call()
    return f"{type(raised.value).__name__}: {raised.value}"


@pytest.mark.parametrize("name", CASES)
def test_hostile_inputs_get_the_same_refusals_with_the_kernels_on(pairs, name, rng):
    fast, slow = pairs[name]
    q, v, x = (array[0] for array in random_states(fast, rng, 1))
    bad_inputs = []
    for argument, size in (("q", fast.nq), ("v", fast.nv), ("x", fast.nv)):
        for index in sorted({0, size - 1}):
            for bad in (np.nan, np.inf, -np.inf):
                values = {"q": q.copy(), "v": v.copy(), "x": x.copy()}
                values[argument][index] = bad
                bad_inputs.append(values)
    bad_inputs += [
        {"q": q[:-1], "v": v, "x": x},  # wrong size
        {"q": q, "v": np.append(v, 0.0), "x": x},
        {"q": q[None, :], "v": v[None, :], "x": x[:, None]},  # mixed shapes
        {"q": q.astype(complex), "v": v, "x": x},
        {"q": np.stack([q, q]), "v": np.stack([v, v]), "x": np.stack([x, x, x])},  # rows disagree
    ]
    if fast.floating_base:
        unit = q.copy()
        unit[3:7] *= 1.01
        bad_inputs.append({"q": unit, "v": v, "x": x})
        batch = np.stack([q, unit, q])
        bad_inputs.append({"q": batch, "v": np.stack([v] * 3), "x": np.stack([x] * 3)})
    refused = 0
    for values in bad_inputs:
        for method in QUANTITIES:
            uses = {"mass_matrix": "q", "gravity": "q", "nonlinear_effects": "qv"}.get(method, "qvx")
            changed = [key for key in "qvx" if not np.array_equal(values[key], {"q": q, "v": v, "x": x}[key])]
            if not set(changed) <= set(uses):
                continue
            state = (values["q"], values["v"], values["x"])
            expected = _refusal(lambda m=method, s=state: _call(slow, m, *s))
            assert _refusal(lambda m=method, s=state: _call(fast, m, *s)) == expected
            refused += 1
    assert refused > 20


@pytest.mark.parametrize("name", ["ur5", pytest.param("panda_mimic", marks=pytest.mark.slow), "mimic_tree"])
def test_lists_other_dtypes_and_strided_arrays_give_the_same_numbers_as_float64_arrays(pairs, name, rng):
    fast, _ = pairs[name]
    q, v, x = (array[0] for array in random_states(fast, rng, 1))
    expected = fast.inverse_dynamics(q, v, x)
    np.testing.assert_array_equal(fast.inverse_dynamics(q.tolist(), v.tolist(), x.tolist()), expected)
    strided = np.repeat(q, 2)[::2]
    assert not strided.flags.c_contiguous
    np.testing.assert_allclose(fast.inverse_dynamics(strided, v, x), expected, rtol=1e-13, atol=1e-13)
    np.testing.assert_allclose(fast.mass_matrix(q.astype(np.float32)), fast.mass_matrix(q.astype(np.float32).astype(float)))


def test_a_robot_whose_kernels_are_not_built_uses_pinocchio(monkeypatch, tmp_path, cache):
    monkeypatch.setenv("ROBODYN_CACHE", str(tmp_path))  # an empty cache: nothing is built
    robot = _load("oblique")
    assert robot.handle.engine == "pinocchio" and build.lookup(robot) is None
    assert list(tmp_path.iterdir()) == []  # looking never builds
    monkeypatch.setenv("ROBODYN_CACHE", cache)
    fast = robodyn.compile(robot)
    assert robot.handle.engine == "pinocchio"  # compile() leaves the robot it was given as it was
    assert _load("oblique").handle.engine == "compiled"  # ... robots loaded afterwards get the kernels
    assert fast.robot is robot


def test_engine_pinocchio_never_uses_the_kernels_and_travels_with_the_robot(pairs, monkeypatch):
    fast, slow = pairs["ur5"]
    assert slow.handle.engine == "pinocchio" and build.lookup(slow) is not None
    again = pickle.loads(pickle.dumps(slow))
    assert again.options.engine == "pinocchio" and again.handle.engine == "pinocchio"
    fast_again = pickle.loads(pickle.dumps(fast))
    assert fast_again.options.engine == "auto" and fast_again.handle.engine == "compiled"
    with pytest.raises(InputError, match="engine"):
        robodyn.load("ur5", engine="compiled")
    monkeypatch.delenv("ROBODYN_ENGINE")
    assert robodyn.load("ur5", gravity=UR5_GRAVITY).handle.engine == "compiled"  # the default: "auto"
    monkeypatch.setenv("ROBODYN_ENGINE", "pinocchio")
    assert robodyn.load("ur5", gravity=UR5_GRAVITY).options.engine == "pinocchio"
    monkeypatch.setenv("ROBODYN_ENGINE", "fast")
    with pytest.raises(InputError, match="ROBODYN_ENGINE"):
        robodyn.load("ur5")
