"""The options of `robodyn simulate` crossed pairwise (issue 39).

Options tested together only hide a crossed wire (a push lost under a held controller, a
gravity dropped on a floating base, a ground that keeps the other integrator). Every pair of
values of every two options (tests/cli/simulate_options.py's ``FACTORS``, the pairs the
command refuses left out) appears in some run of a small generated set; each run's file is
read back without robodyn and compared column by column, to 1e-12, with the Python API given
the same options (``robodyn.load``, the controller built by hand, ``robodyn.simulate``), and
its summary's settings, steps, units and limits checked. Each option alone:
tests/cli/test_simulate_options.py.
"""

from __future__ import annotations

import math

import pytest

from tests.cli.simulate_options import FACTORS, check_run, valid
from tests.pairwise import pairwise, uncovered_pairs

RUNS = pairwise(FACTORS, valid)


def test_the_runs_cover_every_pair_the_command_accepts_and_are_few():
    assert uncovered_pairs(RUNS, FACTORS, valid) == []
    assert all(valid(run) for run in RUNS)
    assert len(RUNS) <= 24 < math.prod(len(values) for values in FACTORS.values())


@pytest.mark.slow
@pytest.mark.parametrize("run", RUNS, ids=[str(k) for k in range(len(RUNS))])
def test_the_options_crossed_pairwise_write_the_python_apis_run(run, tmp_path):
    check_run(run, tmp_path)
