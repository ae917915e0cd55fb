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
    yield robot, compiled
    compiled.module.simd(simd.instruction_sets(compiled.module)[-1]) if hasattr(compiled.module, "simd") else None


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


def test_the_widest_instruction_set_runs_by_default(pair):
    _, compiled = pair
    sets = simd.instruction_sets(compiled.module)
    assert compiled.instruction_set == sets[-1]
    if X86:  # the vector variants built (a failed build would fall back to scalar quietly)
        assert sets[:2] == ("scalar", "sse2")


def test_every_batch_row_equals_the_single_call_bit_for_bit(pair, rng):
    robot, compiled = pair
    for name in simd.instruction_sets(compiled.module):
        compiled.module.simd(name) if hasattr(compiled.module, "simd") else None
        assert compiled.instruction_set == name
        lanes = compiled.module.info()["lanes"]
        for count in _sizes(lanes):
            bad = _mismatched_rows(compiled, robot, rng, count)
            assert not any(bad.values()), (name, count, bad)
    assert set(bad) == set(QUANTITIES)


def test_the_environment_forces_the_scalar_fallback_and_refuses_unknown_sets(pair, rng, monkeypatch):
    robot, compiled = pair
    monkeypatch.setenv(simd.ENVIRONMENT, "scalar")
    forced = compile(robot, threads=THREADS)
    assert forced.instruction_set == "scalar"
    assert not any(_mismatched_rows(forced, robot, rng, 129).values())
    monkeypatch.setenv(simd.ENVIRONMENT, "auto")
    assert compile(robot, threads=THREADS).instruction_set == simd.instruction_sets(compiled.module)[-1]
    monkeypatch.setenv(simd.ENVIRONMENT, "mmx")
    with pytest.raises(InputError, match="ROBODYN_SIMD"):
        compile(robot, threads=THREADS)


def test_negative_control_fused_multiply_add_breaks_the_bit_for_bit_check(pair, rng):
    """The same vector kernels with FMA contraction (AVX2 + FMA, -O2) round differently: the
    check above would notice a variant that is not the scalar kernel's arithmetic."""
    robot, compiled = pair
    if robot.name != "ur5":
        pytest.skip("one robot is enough (a build costs seconds)")
    if not X86 or "avx2" not in simd.instruction_sets(compiled.module):
        pytest.skip("needs an x86-64 CPU with AVX2 and FMA")
    kernels = build.cached_kernels(robot_key(robot))
    assert kernels is not None
    fused = simd.vector_source(kernels).replace('target("avx2")', 'target("avx2,fma"),optimize("O2","fp-contract=fast")')
    module = build.build_module(kernels + fused, label=robot.name, vector=False)
    module.simd("avx2")
    wrong = type(compiled)(robot, module, threads=THREADS)
    bad = _mismatched_rows(wrong, robot, rng, 129)
    assert bad["inverse_dynamics"] > 0 and bad["mass_matrix"] > 0, bad
