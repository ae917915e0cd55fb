"""examples/lecture.ipynb runs headless (nbclient) and shows what it promises."""

from __future__ import annotations

import re

import pytest

from tests.conftest import ROOT


@pytest.mark.slow
def test_lecture_notebook_runs_with_its_outputs():
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    notebook = nbformat.read(ROOT / "examples" / "lecture.ipynb", as_version=4)
    nbclient.NotebookClient(notebook, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(ROOT)}}).execute()
    outputs = [output for cell in notebook.cells if cell.cell_type == "code" for output in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    text = "".join(o.get("text", "") for o in outputs if o.output_type == "stream")
    data = [o.get("data", {}) for o in outputs if o.output_type in ("display_data", "execute_result")]
    assert "<table>" in data[0]["text/html"] and "prismatic" in data[0]["text/html"]  # the robot
    assert sum("text/latex" in d for d in data) == 2  # tau_1, tau_2
    assert float(re.search(r"largest difference: (\S+)", text).group(1)) < 1e-9
    assert float(re.search(r"final distance to target: (\S+) m", text).group(1)) < 1e-3
    assert sum("image/png" in d for d in data) == 2  # the simulation and what-if figures
    assert any("<iframe" in d.get("text/html", "") for d in data)  # the recording inline
    assert "peak joint2 [N]" in text and "heaviest variant: steel, 2 kg" in text
