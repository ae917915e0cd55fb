"""The SIMD batches (robodyn.compiled.simd): every row of a batch bit-for-bit the scalar
single call, in every instruction set this CPU runs, remainders and threads included."""

from __future__ import annotations

import platform

import numpy as np
import pytest

import robodyn
from robodyn.compiled import build, compile, simd
from robodyn.compiled.robot import robot_key
from robodyn.exceptions import InputError
from tests.compiled_helpers import QUANTITIES, arguments, shared_cache
from tests.conftest import NONDEGENERATE_CASES

GRAVITY = [1.3, -0.8, -9.4]
THREADS = 2
X86 = platform.machine().lower() in ("x86_64", "amd64")


@pytest.fixture(scope="module", autouse=True)
def cache():
    """The session's compile cache (never the user's)."""
    with shared_cache() as folder:
        yield folder


#: A zoo arm and mimic joints on a tree under a tilted gravity, prismatic joints on oblique
#: axes (default gravity: the build test_kinematics.py makes, shared in a session).
CASES = {
    "ur5": ("ur5", {"gravity": GRAVITY}),
    "mimic_tree": (NONDEGENERATE_CASES["mimic_tree"][0], {**NONDEGENERATE_CASES["mimic_tree"][1], "gravity": GRAVITY}),
    "oblique": NONDEGENERATE_CASES["oblique"],
}


@pytest.fixture(scope="module", params=list(CASES))
def pair(request):
    source, options = CASES[request.param]
    robot = robodyn.load(source, **options)
    compiled = compile(robot, threads=THREADS)
    return robot, compiled


def _sizes(lanes: int) -> list[int]:
    """1, 7, 129 and a block a thread ± 1 (129 rows: two threads, each with a remainder)."""
    return sorted({1, 7, 129, lanes * THREADS - 1, lanes * THREADS + 1})


def _mismatched_rows(compiled, robot, rng, count: int) -> dict[str, int]:
    """For each quantity, how many rows of a batch of ``count`` differ in any bit from the
    single call on that row."""
    bad = {}
    for name, args in arguments(robot, rng, count).items():
        batch = getattr(compiled, name)(*args)
        single = [getattr(compiled, name)(*(arg[row] for arg in args)) for row in range(count)]
        bad[name] = sum(not np.array_equal(batch[row], single[row]) for row in range(count))
    return bad


def test_the_widest_instruction_set_this_cpu_runs_is_built_and_runs(pair):
    _, compiled = pair
    sets = simd.instruction_sets(compiled.module)
    assert compiled.instruction_set == sets[-1]
    if X86 and simd._cpu_flags() is not None:  # the vector variant built (a failed build would run scalar rows)
        assert sets == ("scalar", simd.build_variants()[0][0])


def _runs(name: str) -> bool:
    flags = simd._cpu_flags()
    return flags is not None and dict((v[0], v[2]) for v in simd.VARIANTS)[name] in flags


def _check_every_row(robot, compiled, rng) -> None:
    """Every row of batches of :func:`_sizes` equal to its single call, in the module's
    instruction set and then in scalar rows (``simd("scalar")``)."""
    for name in simd.instruction_sets(compiled.module)[::-1]:
        compiled.module.simd(name) if hasattr(compiled.module, "simd") else None
        assert compiled.instruction_set == name
        for count in _sizes(compiled.module.info()["lanes"]):
            bad = _mismatched_rows(compiled, robot, rng, count)
            assert set(bad) == set(QUANTITIES)
            assert not any(bad.values()), (name, count, bad)
    compiled.module.simd(simd.instruction_sets(compiled.module)[-1]) if hasattr(compiled.module, "simd") else None


def test_every_batch_row_equals_the_single_call_bit_for_bit(pair, rng):
    _check_every_row(*pair, rng)


@pytest.mark.slow
@pytest.mark.parametrize("variant", [name for name, _, _ in simd.VARIANTS])
def test_every_instruction_set_this_cpu_runs_is_bit_for_bit_the_single_call(variant, rng, monkeypatch):
    """Each variant (a build each; the fast tier checks the widest) on ur5 under a tilted gravity."""
    if not X86 or not _runs(variant):
        pytest.skip(f"this CPU does not run {variant}")
    monkeypatch.setenv(simd.ENVIRONMENT, variant)
    robot = robodyn.load(*CASES["ur5"][:1], **CASES["ur5"][1])
    compiled = compile(robot, threads=THREADS)
    assert compiled.instruction_set == variant
    _check_every_row(robot, compiled, rng)


def test_the_environment_forces_the_scalar_fallback_and_refuses_unknown_sets(pair, rng, monkeypatch):
    robot, compiled = pair
    if robot.name != "ur5":
        pytest.skip("one robot is enough (a build costs seconds; the others run scalar rows above)")
    monkeypatch.setenv(simd.ENVIRONMENT, "scalar")
    forced = compile(robot, threads=THREADS)
    assert forced.instruction_set == "scalar" and forced.module is not compiled.module
    assert not any(_mismatched_rows(forced, robot, rng, 129).values())
    assert not any(_mismatched_rows(compiled, robot, rng, 129).values())  # the default module untouched
    monkeypatch.setenv(simd.ENVIRONMENT, "auto")
    assert compile(robot, threads=THREADS).instruction_set == compiled.instruction_set
    monkeypatch.setenv(simd.ENVIRONMENT, "mmx")
    with pytest.raises(InputError, match="ROBODYN_SIMD"):
        compile(robot, threads=THREADS)


def test_negative_control_fused_multiply_add_breaks_the_bit_for_bit_check(pair, rng):
    """The same vector kernels with FMA contraction (AVX2 + FMA, -O2) round differently: the
    check above would notice a variant that is not the scalar kernel's arithmetic."""
    robot, compiled = pair
    if robot.name != "ur5":
        pytest.skip("one robot is enough (a build costs seconds)")
    if not X86 or not _runs("avx2") or "fma" not in (simd._cpu_flags() or ()):
        pytest.skip("needs an x86-64 CPU with AVX2 and FMA")
    kernels = build.cached_kernels(robot_key(robot))
    assert kernels is not None
    avx2 = tuple(variant for variant in simd.VARIANTS if variant[0] == "avx2")
    source = simd.vector_source(kernels, avx2)
    fused = source.replace('target("avx2")', 'target("avx2,fma"),optimize("O2","fp-contract=fast")')
    assert fused != source
    module = build.build_module(kernels + fused, label=robot.name, vector=False)
    module.simd("avx2")
    wrong = type(compiled)(robot, module, threads=THREADS)
    bad = _mismatched_rows(wrong, robot, rng, 129)
    assert bad["inverse_dynamics"] > 0 and bad["mass_matrix"] > 0, bad


def test_a_block_with_a_bad_row_reports_what_the_scalar_rows_report(pair, rng):
    """A NaN in one row (status 1) and velocities so large the results overflow (2; forward
    dynamics 3): the module's statuses are the scalar rows' in every instruction set."""
    robot, compiled = pair
    module, sets = compiled.module, simd.instruction_sets(compiled.module)
    q, v, a = (np.ascontiguousarray(x) for x in arguments(robot, rng, 129)["inverse_dynamics"])
    nan, huge = v.copy(), v.copy()
    nan[37, 0] = np.nan
    huge[64:67] = 1e300
    calls = {
        "tau": lambda w: module.tau(q, w, a, THREADS),
        "mass": lambda w: module.mass(np.where(np.isnan(w), np.nan, q), THREADS),
        "nle": lambda w: module.nle(q, w, THREADS),
        "fd": lambda w: module.fd(q, w, a, THREADS),
    }
    statuses = {}
    for name in sets:
        module.simd(name) if hasattr(module, "simd") else None
        statuses[name] = {kind: (call(nan), call(huge) if kind != "mass" else None) for kind, call in calls.items()}
    module.simd(sets[-1]) if hasattr(module, "simd") else None
    assert statuses["scalar"] == {"tau": (1, 2), "mass": (1, None), "nle": (1, 2), "fd": (1, 3)}
    assert all(found == statuses["scalar"] for found in statuses.values()), statuses
