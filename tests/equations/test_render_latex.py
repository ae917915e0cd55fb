"""LaTeX and PDF output: typeset as a person would, compiled by a real TeX engine."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest

from robodyn.cli.app import main
from robodyn.equations import derive_equations, render
from robodyn.equations.render_latex import compile_latex
from tests.equations.derived import derived

RRP = str(Path(__file__).parents[1] / "data" / "rrp_arm.urdf")
DOCUMENTS = [
    ("rp_arm", {}),
    ("rp_arm", {"keep_params": True}),
    ("double_pendulum", {}),
    (RRP, {}),
    (RRP, {"keep_params": True}),
    ("ur5", {}),
]
needs_tex = pytest.mark.skipif(shutil.which("pdflatex") is None, reason="needs pdflatex (make tex installs TeX Live)")


def overfull_points(log: str) -> list[float]:
    return [float(m) for m in re.findall(r"Overfull \\hbox \(([0-9.]+)pt too wide", log)]


@pytest.mark.slow
def test_symbols_are_typeset_with_dots_numbers_and_upright_names():
    tex = render(derive_equations(RRP, keep_params=True), "latex")
    assert r"\dot q_{2}" in tex and r"\ddot q" in tex and r"q_{3}" in tex
    assert r"\texttt{shoulder yaw}" in tex  # the legend names the joint
    assert r"m_{\text{slider}}" in tex and r"I_{\text{upper\_arm},zz}" in tex
    assert "qd" not in tex.split(r"\begin{align*}", 1)[1]


def test_long_entries_are_broken_across_lines():
    tex = render(derived("ur5"), "latex")
    assert r"&\quad" in tex
    longest = max(len(line) for line in tex.splitlines() if "&" in line)
    assert longest < 400


def test_notebooks_get_latex():
    math = derive_equations("rp_arm")._repr_latex_()
    assert math.startswith(r"\begin{align*}") and r"M(q) &= \begin{bmatrix}" in math


def test_pdf_without_tex_is_one_line(monkeypatch, tmp_path, capsys):
    import robodyn.equations.render_latex as render_latex

    monkeypatch.setattr(render_latex.shutil, "which", lambda name: None)
    assert main(["equations", "rp_arm", "--symbolic", "--format", "pdf", "--out", str(tmp_path / "eq.pdf")]) == 2
    err = capsys.readouterr().err
    assert "pdflatex" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "eq.pdf").exists()


@needs_tex
def test_pdf_output(tmp_path):
    target = tmp_path / "rp_arm.pdf"
    assert main(["equations", "rp_arm", "--symbolic", "--format", "pdf", "--out", str(target)]) == 0
    assert target.read_bytes().startswith(b"%PDF")


@pytest.mark.slow
@needs_tex
@pytest.mark.parametrize(("name", "options"), DOCUMENTS, ids=[f"{Path(n).stem}{'-params' if o else ''}" for n, o in DOCUMENTS])
def test_every_latex_output_compiles_without_overfull_lines(name, options, tmp_path):
    tex = render(derive_equations(name, **options), "latex")
    pdf, log = compile_latex(tex, tmp_path)
    assert pdf.stat().st_size > 0
    assert not re.search(r"^! ", log, re.MULTILINE)
    assert max(overfull_points(log), default=0.0) <= 10.0


@needs_tex
def test_overfull_check_catches_a_wide_line(tmp_path):
    """Negative control: a line wider than the page is reported and would fail the check."""
    wide = r"\documentclass{article}\begin{document}\[" + "+".join(["x_{1}"] * 200) + r"\]\end{document}"
    _, log = compile_latex(wide, tmp_path)
    assert max(overfull_points(log), default=0.0) > 10.0
