"""examples/sequel.ipynb runs headless (nbclient) and shows what it promises."""

from __future__ import annotations

import re

import pytest

from tests.conftest import ROOT


@pytest.mark.slow  # like the lecture's notebook: a whole story, 6 s
def test_the_sequel_notebook_runs_and_reaches_deflects_and_observes_as_it_says():
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    notebook = nbformat.read(ROOT / "examples" / "sequel.ipynb", as_version=4)
    nbclient.NotebookClient(notebook, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(ROOT)}}).execute()
    outputs = [output for cell in notebook.cells if cell.cell_type == "code" for output in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    text = "".join(o.get("text", "") for o in outputs if o.output_type == "stream")
    data = [o.get("data", {}) for o in outputs if o.output_type in ("display_data", "execute_result")]

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
