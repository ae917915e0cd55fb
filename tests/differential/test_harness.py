"""The differential harness: every pair of paths (:mod:`tests.differential.pairs`) on seeded
cases (:mod:`tests.differential.cases`) — a few of each generator in the fast tier, many
in the slow tier. A failure names the case, its seed and the line that replays it."""

from __future__ import annotations

import zlib

import numpy as np
import pytest

from tests.differential.cases import Case, draw_cases
from tests.differential.pairs import PAIRS, Pair

pytestmark = pytest.mark.differential

#: Seeds of the fast tier (fixed: the same cases every run) and of the slow sweep.
FAST_SEED, SLOW_SEED = 31, 310_000
FAST = draw_cases(2, base_seed=FAST_SEED)
SLOW = draw_cases(12, base_seed=SLOW_SEED)


def _params(cases: list[Case], *, fast: bool):
    params = []
    for pair in PAIRS.values():
        chosen = [case for case in cases if pair.applies(case)]
        limit = pair.fast_cases if fast else pair.slow_cases
        if limit is not None:
            chosen = [case for case in chosen if pair.max_dof is None or case.robot().nv <= pair.max_dof]
            chosen = sorted(chosen, key=lambda case: case.robot().nv)[:limit] if fast else chosen[:limit]
        params += [pytest.param(pair, case, id=f"{pair.name}-{case.id}") for case in chosen]
    return params


def _run(pair: Pair, case: Case) -> None:
    if pair.max_dof is not None and case.robot().nv > pair.max_dof:
        pytest.skip(f"{pair.name} runs on robots of at most {pair.max_dof} degrees of freedom")
    rng = np.random.default_rng([case.seed, zlib.crc32(pair.name.encode())])
    pair.check(case, rng)


@pytest.mark.parametrize(("pair", "case"), _params(FAST, fast=True))
def test_paths_agree_on_the_fast_cases(pair, case):
    _run(pair, case)


@pytest.mark.slow
@pytest.mark.parametrize(("pair", "case"), _params(SLOW, fast=False))
def test_paths_agree_on_the_sweep(pair, case):
    _run(pair, case)
