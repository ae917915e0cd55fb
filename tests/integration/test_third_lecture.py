"""Issue 42: examples/third_lecture.ipynb runs headless and each section's law holds as printed."""

from __future__ import annotations

import re

import pytest

from tests.integration.test_notebook import run_notebook


@pytest.mark.slow  # two 2 s whole-body simulations of solo12: about two minutes
def test_the_third_lecture_notebook_runs_and_each_law_holds():
    text, data = run_notebook("third_lecture.ipynb")

    def number(pattern: str) -> float:
        return float(re.search(pattern, text).group(1))

    assert number(r"centre of mass vs the reference's sums: (\S+) m") <= 1e-12
    assert number(r"centroidal momentum vs the reference's sums: (\S+)") <= 1e-12
    assert number(r"wall force off the command by (\S+) ") <= 1e-6
    assert number(r"motion error off ë \+ Kd ė \+ Kp e = 0 by (\S+) of e0") <= 1e-3
    assert number(r"work of the commanded force along the motion: (\S+) J") <= 1e-9
    assert number(r"without decoupling: motion off its law by (\S+) of e0") > 1e-2
    assert number(r"command line: wall force off the command by (\S+) relative") <= 1e-6
    assert number(r"command line: motion off its law by (\S+) of e0") <= 1e-3
    assert number(r"normal force off 5 N after 0.5 s: (\S+) ") <= 1e-2
    assert number(r"hand off the circle after 0.5 s: (\S+) m") <= 1e-3
    assert number(r"Ki = 20: settled force off the command by (\S+) ") <= 1e-6
    assert number(r"Ki = 0: settled force off the command by (\S+) ") > 1e-3
    force, spring, series = (
        float(x) for x in re.search(r"force (\S+) N, K \(x_target − x\) (\S+) N, series law (\S+) N", text).groups()
    )
    assert force == pytest.approx(spring, rel=1e-6) and force == pytest.approx(series, rel=1e-6)
    assert number(r"base position error after 2 s: (\S+) m") < 1e-6
    assert number(r"base attitude error after 2 s: (\S+) rad") < 1e-6
    assert number(r"sum of f_z − m g at rest: (\S+) ") <= 1e-6
    assert number(r"smallest margin inside the friction cones: (\S+) N") > 0
    assert number(r"centre of mass off its shifted target after 2 s: (\S+) m") < 1e-4
    assert number(r"smallest margin inside the friction cones while shifting: (\S+) N") > 0
    assert sum("image/png" in d for d in data) == 2  # commanded vs measured force; the CoM over the support polygon
