"""examples/lecture.ipynb and examples/sequel.ipynb run headless (nbclient) and show what they promise."""

from __future__ import annotations

import re

import pytest

from tests.conftest import ROOT


def run_notebook(name: str) -> tuple[str, list[dict]]:
    """Execute ``examples/<name>`` with no error: its printed text and its display data."""
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    notebook = nbformat.read(ROOT / "examples" / name, as_version=4)
    nbclient.NotebookClient(notebook, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(ROOT)}}).execute()
    outputs = [output for cell in notebook.cells if cell.cell_type == "code" for output in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    text = "".join(o.get("text", "") for o in outputs if o.output_type == "stream")
    data = [o.get("data", {}) for o in outputs if o.output_type in ("display_data", "execute_result")]
    return text, data


@pytest.mark.slow
def test_lecture_notebook_runs_with_its_outputs():
    text, data = run_notebook("lecture.ipynb")
    assert "<table>" in data[0]["text/html"] and "prismatic" in data[0]["text/html"]  # the robot
    assert sum("text/latex" in d for d in data) == 2  # tau_1, tau_2
    assert float(re.search(r"largest difference: (\S+)", text).group(1)) < 1e-9
    assert float(re.search(r"final distance to target: (\S+) m", text).group(1)) < 1e-3


@pytest.mark.slow  # a whole story, 6 s
def test_the_sequel_notebook_runs_and_reaches_deflects_and_observes_as_it_says():
    text, data = run_notebook("sequel.ipynb")

    def number(pattern: str) -> float:
        return float(re.search(pattern, text).group(1))

    assert number(r"final position error: (\S+) m") < 1e-6
    assert number(r"final orientation error: (\S+) rad") < 1e-6
    assert number(r"largest difference of the hand's path: (\S+) m") < 1e-6
    assert number(r"joints apart at the end: (\S+) rad") > 0.05  # the posture did move the arm
    assert number(r"deflection off by (\S+) %") < 1.0
    work, stored = number(r"work of the push: (\S+) J"), number(r"stored in the spring: (\S+) J")
    assert work > stored > 0
    assert number(r"online vs offline: (\S+)") <= 1e-9
    assert number(r"estimate vs applied after settling: (\S+) N m") < 0.05
    assert "last significant joint: joint2" in text
    assert sum("image/png" in d for d in data) == 1  # estimated vs applied
    assert any("<iframe" in d.get("text/html", "") for d in data)  # the recording inline


@pytest.mark.slow  # two IPOPT solves and an animation, about 10 s
def test_the_optimization_notebook_solves_both_motions_within_the_limits():
    text, data = run_notebook("optimization.ipynb")
    assert text.count("Solve_Succeeded") == 2
    assert float(re.search(r"largest RNEA residual: (\S+)", text).group(1)) < 1e-9
    assert text.count("limits broken: 0") == 2
    shoulder = float(re.search(r"peak torques: shoulder (\S+) N m", text).group(1))
    assert shoulder <= 5.0 + 1e-6  # weaker than the 9.2 N m that would lift it directly
    assert sum("<iframe" in d.get("text/html", "") for d in data) == 1  # the RP arm's recording
    assert any("animation" in d.get("text/html", "").lower() for d in data)  # the swing-up
