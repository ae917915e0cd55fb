"""The compiled derivatives (∂τ, ∂q̈) against Pinocchio's analytical derivatives, finite
differences of the compiled kernels, and the identities ∂τ/∂a = M, ∂q̈/∂τ · M = I."""

from __future__ import annotations

import gc
import weakref

import numpy as np
import pinocchio as pin
import pytest

import robodyn
from robodyn.compiled import compile
from robodyn.compiled.derivatives import paired_trig
from robodyn.exceptions import InputError, SingularMassMatrixError
from tests.compiled_helpers import shared_cache
from tests.conftest import NONDEGENERATE_CASES
from tests.random_robots import urdf_from_seed

#: The issue's bar: the compiled derivatives within 1e-10 of Pinocchio's, relative to their size.
RTOL = 1e-10
GRAVITY = [1.3, -0.8, -9.4]


@pytest.fixture(scope="module", autouse=True)
def cache():
    """The session's compile cache (never the user's)."""
    with shared_cache() as folder:
        yield folder


def _pair(source, **options):
    robot = robodyn.load(source, **options)
    return robot, compile(robot, threads=2)


@pytest.fixture(scope="module")
def mimic_tree():
    """Mimic joints with multipliers 0.6, -1.8, -2.5 and offsets, a prismatic one, a tree,
    under a tilted gravity (the one compiled robot of the fast tier: a build costs seconds)."""
    path, options = NONDEGENERATE_CASES["mimic_tree"]
    return _pair(path, **options, gravity=GRAVITY)


def relative_error(ours: np.ndarray, theirs: np.ndarray, floor: float = 0.0) -> float:
    """``max |ours − theirs| / max(max |theirs|, floor)`` (the floor for a derivative that is
    zero by physics, such as a lone joint's ``∂τ/∂v``: rounding on both sides)."""
    assert ours.shape == theirs.shape, (ours.shape, theirs.shape)
    return float(np.abs(ours - theirs).max() / max(np.abs(theirs).max(), floor, np.finfo(float).tiny))


def pinocchio_tau_derivatives(robot, q, v, a):
    """``(∂τ/∂q, ∂τ/∂v, M)`` of one state by ``pin.computeRNEADerivatives``; with mimic
    joints on the expanded model through the linear map (``Sᵀ D S``)."""
    if robot.mimic is None:
        model, selection, offset = robot.model, np.eye(robot.nv), np.zeros(robot.nq)
    else:
        model, selection, offset = robot.mimic.model, robot.mimic.selection, robot.mimic.offset
    data = model.createData()  # kept alive: Pinocchio returns views of its arrays
    dq, dv, mass = (
        np.array(m) for m in pin.computeRNEADerivatives(model, data, selection @ q + offset, selection @ v, selection @ a)
    )
    mass = np.triu(mass) + np.triu(mass, 1).T  # Pinocchio fills the upper triangle
    return tuple(selection.T @ m @ selection for m in (dq, dv, mass))


def pinocchio_fd_derivatives(robot, q, v, tau):
    """``(∂q̈/∂q, ∂q̈/∂v, M⁻¹)`` by ``pin.computeABADerivatives`` (mimic joints: from the
    RNEA derivatives at ``a = q̈``, Pinocchio's ABA having no mimic joints)."""
    if robot.mimic is None:
        data = robot.model.createData()
        return tuple(np.array(m) for m in pin.computeABADerivatives(robot.model, data, q, v, tau))
    dq, dv, mass = pinocchio_tau_derivatives(robot, q, v, robot.forward_dynamics(q, v, tau))
    inverse = np.linalg.inv(mass)
    return -inverse @ dq, -inverse @ dv, inverse


def states(robot, rng, count=None):
    q = robot.random_configuration(rng, count)
    shape = (robot.nv,) if count is None else (count, robot.nv)
    v, a = rng.normal(size=shape), rng.normal(size=shape)
    return q, v, a, robot.inverse_dynamics(q, v, a)


def compare_with_pinocchio(robot, compiled, q, v, a, tau, rtol=RTOL) -> dict[str, float]:
    """Both derivative calls, one state or a batch, against Pinocchio's, row by row."""
    ours_tau = compiled.inverse_dynamics_derivatives(q, v, a)
    ours_fd = compiled.forward_dynamics_derivatives(q, v, tau)
    rows = [(q, v, a, tau)] if q.ndim == 1 else list(zip(q, v, a, tau, strict=True))
    errors = {}
    for index, (qi, vi, ai, ti) in enumerate(rows):
        pick = (lambda m: m) if q.ndim == 1 else (lambda m, index=index: m[index])
        for kind, ours, theirs in (
            ("tau", ours_tau, pinocchio_tau_derivatives(robot, qi, vi, ai)),
            ("fd", ours_fd, pinocchio_fd_derivatives(robot, qi, vi, ti)),
        ):
            floor = 1e-3 * max(float(np.abs(m).max()) for m in theirs)  # of the three matrices
            for name, mine, reference in zip(("dq", "dv", "third"), ours, theirs, strict=True):
                key = f"{kind}.{name}"
                errors[key] = max(errors.get(key, 0.0), relative_error(pick(mine), reference, floor))
    bad = {key: error for key, error in errors.items() if not error <= rtol}
    assert not bad, f"{robot.name}: compiled derivatives differ from Pinocchio's: {bad}"
    return errors


def test_compiled_derivatives_match_pinocchio_one_state_and_batches(mimic_tree, rng):
    robot, compiled = mimic_tree
    compare_with_pinocchio(robot, compiled, *states(robot, rng))
    for count in (1, 7, 129):  # 129: two threads, rows not a multiple of the thread count
        compare_with_pinocchio(robot, compiled, *states(robot, rng, count))


def test_batch_rows_are_bit_identical_to_single_calls(mimic_tree, rng):
    robot, compiled = mimic_tree
    q, v, a, tau = states(robot, rng, 129)
    for method, third in ((compiled.inverse_dynamics_derivatives, a), (compiled.forward_dynamics_derivatives, tau)):
        batch = method(q, v, third)
        for row in (0, 64, 65, 128):
            single = method(q[row], v[row], third[row])
            assert all(np.array_equal(b[row], s) for b, s in zip(batch, single, strict=True))


def _runs(instruction_set: str) -> bool:
    from robodyn.compiled.simd import VARIANTS, _cpu_flags

    flags = _cpu_flags() or frozenset()
    return any(name == instruction_set and target in flags for name, _, target in VARIANTS)


@pytest.mark.parametrize(
    ("instruction_set", "lanes"),
    # SSE2 runs on every x86-64 machine: the fast tier's; the wider sets (5 s each) in the slow tier
    [("sse2", 2), pytest.param("avx2", 4, marks=pytest.mark.slow), pytest.param("avx512", 8, marks=pytest.mark.slow)],
)
def test_batches_run_simd_blocks_whose_rows_are_bit_for_bit_the_single_call(instruction_set, lanes, monkeypatch, rng):
    """Each instruction set's blocks of L rows (the derivative module built for it, as
    ``$ROBODYN_SIMD`` picks): every row of batches of 1, 7, 2L - 1, 2L + 1 and 129 states (two
    threads, remainder rows through the pairs and the scalar call) equals its single call, and
    matches Pinocchio. The module says which blocks ran (negative control: not the pairs)."""
    if not _runs(instruction_set):
        pytest.skip(f"this CPU does not run {instruction_set}")
    monkeypatch.setenv("ROBODYN_SIMD", instruction_set)
    path, options = NONDEGENERATE_CASES["mimic_tree"]
    robot, compiled = _pair(path, **options, gravity=GRAVITY)
    module = compiled._derivatives()
    assert (module.info()["instruction_set"], module.info()["lanes"]) == (instruction_set, lanes)
    for count in sorted({1, 7, 2 * lanes - 1, 2 * lanes + 1, 129}):
        q, v, a, tau = states(robot, rng, count)
        for method, third in ((compiled.inverse_dynamics_derivatives, a), (compiled.forward_dynamics_derivatives, tau)):
            batch = method(q, v, third)
            for row in range(count):
                single = method(q[row], v[row], third[row])
                assert all(np.array_equal(b[row], s) for b, s in zip(batch, single, strict=True)), (count, row)
        if count == 129:
            compare_with_pinocchio(robot, compiled, q, v, a, tau)


def test_identities_dtau_da_is_m_and_dqdd_dtau_inverts_it(mimic_tree, rng):
    robot, compiled = mimic_tree
    q, v, a, tau = states(robot, rng, 7)
    dq, dv, mass = compiled.inverse_dynamics_derivatives(q, v, a)
    assert np.array_equal(mass, compiled.mass_matrix(q))
    # one state: the single call's M (compiled for its SIMD variant's instruction set) too
    assert np.array_equal(compiled.inverse_dynamics_derivatives(q[3], v[3], a[3])[2], compiled.mass_matrix(q[3]))
    ddq, ddv, inverse = compiled.forward_dynamics_derivatives(q, v, tau)
    assert np.abs(inverse @ mass - np.eye(robot.nv)).max() < 1e-10
    # ∂q̈/∂x = −M⁻¹ ∂τ/∂x at a = q̈ (here q̈ = a: tau was made from it)
    assert relative_error(ddq, -np.linalg.solve(mass, dq)) < 1e-10
    assert relative_error(ddv, -np.linalg.solve(mass, dv)) < 1e-10


def test_a_batchs_three_results_are_separate_arrays_freed_with_them(mimic_tree, rng):
    """A batch's results share one buffer: each is its own C-contiguous writable array (writing
    one leaves the others), and the buffer goes when they do (no reference kept)."""
    robot, compiled = mimic_tree
    q, v, a, tau = states(robot, rng, 9)
    for method, third in ((compiled.inverse_dynamics_derivatives, a), (compiled.forward_dynamics_derivatives, tau)):
        results = method(q, v, third)
        copies = [result.copy() for result in results]
        assert all(r.flags.c_contiguous and r.flags.writeable and r.shape == (9, robot.nv, robot.nv) for r in results)
        results[0][...] = np.nan
        assert all(np.array_equal(r, c) for r, c in zip(results[1:], copies[1:], strict=True))
        buffer = weakref.ref(results[0].base if results[0].base is not None else results[0])
        del results
        gc.collect()
        assert buffer() is None


def test_sin_and_cos_of_one_coordinate_are_paired_within_a_function_only():
    """The module's copy of the kernels computes sin and cos of a coordinate once (the same
    function, so the same bits); a sin in one kernel is never paired with a cos in another."""
    text = "\n".join(
        [
            "static void rd_a(const double *q, double *out) {",
            "    const double th1 = q[1];",
            "    const double t0 = rd_sin(th1);",
            "    const double t1 = t0 * 2.0;",
            "    const double t2 = rd_cos(th1);",
            "    out[0] = t1 + t2;",
            "}",
            "static void rd_b(const double *q, double *out) {",
            "    const double th1 = q[1];",
            "    const double t0 = rd_cos(th1);",
            "    out[0] = t0;",
            "}",
        ]
    )
    lines = paired_trig(text).splitlines()
    assert lines[2] == "    double t0, t2; rd_sincos(th1, &t0, &t2);"
    assert "    const double t2 = rd_cos(th1);" not in lines
    assert "    const double t0 = rd_cos(th1);" in lines  # rd_b's own, left alone


def _central_difference(function, x: np.ndarray, step: float) -> np.ndarray:
    """Columns ``(f(x + h e_j) − f(x − h e_j)) / 2h``."""
    columns = []
    for j in range(x.size):
        shift = np.zeros_like(x)
        shift[j] = step
        columns.append((function(x + shift) - function(x - shift)) / (2 * step))
    return np.stack(columns, axis=-1)


def test_compiled_derivatives_match_finite_differences_of_the_compiled_kernels(mimic_tree, rng):
    robot, compiled = mimic_tree
    q, v, a, tau = states(robot, rng)
    step = 1e-6
    dq, dv, _ = compiled.inverse_dynamics_derivatives(q, v, a)
    assert relative_error(dq, _central_difference(lambda x: compiled.inverse_dynamics(x, v, a), q, step)) < 1e-7
    assert relative_error(dv, _central_difference(lambda x: compiled.inverse_dynamics(q, x, a), v, step)) < 1e-7
    ddq, ddv, inverse = compiled.forward_dynamics_derivatives(q, v, tau)
    assert relative_error(ddq, _central_difference(lambda x: compiled.forward_dynamics(x, v, tau), q, step)) < 1e-7
    assert relative_error(ddv, _central_difference(lambda x: compiled.forward_dynamics(q, x, tau), v, step)) < 1e-7
    assert relative_error(inverse, _central_difference(lambda x: compiled.forward_dynamics(q, v, x), tau, step)) < 1e-7


def test_negative_control_a_perturbed_input_fails_the_comparison(mimic_tree, rng):
    """The compiled kernels fed a configuration 1e-7 off on one joint: the comparison with
    Pinocchio at the true state must fail (else it checks nothing)."""
    robot, compiled = mimic_tree
    q, v, a, tau = states(robot, rng)

    class Perturbed:
        def inverse_dynamics_derivatives(self, q, v, a):
            return compiled.inverse_dynamics_derivatives(q + np.eye(robot.nv)[1] * 1e-7, v, a)

        def forward_dynamics_derivatives(self, q, v, tau):
            return compiled.forward_dynamics_derivatives(q, v, tau)

    compare_with_pinocchio(robot, compiled, q, v, a, tau)
    with pytest.raises(AssertionError, match=r"tau\.dq"):
        compare_with_pinocchio(robot, Perturbed(), q, v, a, tau)


def test_derivative_inputs_are_checked_like_every_method(mimic_tree, rng):
    robot, compiled = mimic_tree
    q, v, a, tau = states(robot, rng)
    with pytest.raises(InputError, match="v"):
        compiled.inverse_dynamics_derivatives(q, v[:-1], a)
    with pytest.raises(InputError, match="tau"):
        compiled.forward_dynamics_derivatives(q, v, np.where(np.arange(robot.nv) == 1, np.nan, tau))
    with pytest.raises(InputError):
        compiled.inverse_dynamics_derivatives(q[None], v, a)  # a batch of one q with one v
    listed = compiled.inverse_dynamics_derivatives(list(q), list(v), [float(x) for x in a])  # the checked path
    assert all(np.array_equal(x, y) for x, y in zip(listed, compiled.inverse_dynamics_derivatives(q, v, a), strict=True))


def test_a_nan_in_one_row_of_a_batch_is_refused_naming_the_argument(mimic_tree, rng):
    robot, compiled = mimic_tree
    q, v, _, tau = states(robot, rng, 129)
    v[100, 1] = np.nan
    with pytest.raises(InputError, match=r"^v "):
        compiled.forward_dynamics_derivatives(q, v, tau)


def test_a_singular_mass_matrix_is_refused_like_the_forward_dynamics():
    """The last link massless (the singular robot of the compiled engine's tests)."""
    text = urdf_from_seed(3, 2, ["revolute"])
    head, _, _ = text.rpartition("<inertial>")
    text = (
        head + '<inertial><mass value="0"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>\n</robot>'
    )
    robot = robodyn.load(text, check_inertia=False)
    compiled = compile(robot)
    with pytest.raises(SingularMassMatrixError):
        compiled.forward_dynamics_derivatives(*np.zeros((3, robot.nv)))
    with pytest.raises(SingularMassMatrixError):
        compiled.forward_dynamics_derivatives(*np.zeros((3, 129, robot.nv)))


@pytest.mark.slow
@pytest.mark.parametrize(
    ("source", "options"),
    [
        ("ur5", {}),
        ("ur5", {"gravity": GRAVITY}),
        ("panda", {"lock": {"panda_finger_joint1": 0.0}}),
        ("panda", {}),
        ("rp_arm", {}),
        (*NONDEGENERATE_CASES["gripper"],),
        (*NONDEGENERATE_CASES["mimic_tree_locked"],),
        (NONDEGENERATE_CASES["oblique"][0], {"gravity": GRAVITY}),
        (*NONDEGENERATE_CASES["oblique_locked"],),
    ],
)
def test_compiled_derivatives_match_pinocchio_on_the_zoo(source, options, rng):
    robot, compiled = _pair(source, **options)
    compare_with_pinocchio(robot, compiled, *states(robot, rng))
    for count in (7, 129):
        compare_with_pinocchio(robot, compiled, *states(robot, rng, count))
