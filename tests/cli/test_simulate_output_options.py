"""The options of `robodyn simulate` that choose an engine or write a picture, each alone (issue 39).

``--plot`` and ``--record`` add their file and leave the motion bit for bit (the trajectory
written beside them read back without robodyn); ``--engine compiled`` (and ``--compiled``,
the same) writes the Python API's compiled run to 1e-12 and the Pinocchio engine's to 1e-9.
The others: tests/cli/test_simulate_options.py; ``--png`` needs Chromium and is left to
tests/viz; ``--keyframe``: tests/cli/test_start.py; ``--constraints``: tests/cli/test_constraints_option.py.
"""

from __future__ import annotations

import contextlib
import io
import json
import shutil
import struct
import warnings

import numpy as np
import pytest

import robodyn
from robodyn.cli.app import main
from tests.cli.simulate_options import DEFAULT, DURATION, arguments_of, robot_of
from tests.differential.pairs import written_columns


def command(argv: list[str]) -> dict:
    stdout, stderr = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr):
        assert main(argv) == 0, stderr.getvalue()
    return json.loads(stdout.getvalue())


def runs(run: dict, option: list[str], folder) -> tuple[dict, dict, dict]:
    """The run with the option and without it: its summary, both files' columns."""
    base = arguments_of(run | {"json": True}, None)
    summary = command([*base, *option, "--out", str(folder / "with.csv")])
    command([*base, "--out", str(folder / "without.csv")])
    return summary, written_columns(folder / "with.csv"), written_columns(folder / "without.csv")


def png_size(path) -> tuple[int, int]:
    """Width and height of a PNG file, from its header (signature, then the IHDR chunk)."""
    data = path.read_bytes()[:24]
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and data[12:16] == b"IHDR"
    return struct.unpack(">II", data[16:24])


@pytest.mark.slow
def test_plot_alone_writes_a_png_and_leaves_the_motion(tmp_path):
    summary, columns, without = runs(dict(DEFAULT), ["--plot", str(tmp_path / "run.png")], tmp_path)
    assert summary["plot"] == str(tmp_path / "run.png") and min(png_size(tmp_path / "run.png")) >= 300
    assert {name: list(values) for name, values in columns.items()} == {name: list(values) for name, values in without.items()}


@pytest.mark.slow
def test_record_alone_writes_an_html_animation_and_leaves_the_motion(tmp_path):
    run = DEFAULT | {"model": "xacro"}  # the arm draws its meshes (the oblique robot has no visual)
    summary, columns, without = runs(run, ["--record", str(tmp_path / "run.html")], tmp_path)
    html = (tmp_path / "run.html").read_text()
    assert summary["recording"] == str(tmp_path / "run.html") and html.lstrip().lower().startswith("<!doctype html")
    assert len(html) > 10_000
    assert {name: list(values) for name, values in columns.items()} == {name: list(values) for name, values in without.items()}


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("cc") is None and shutil.which("gcc") is None, reason="no C compiler")
def test_the_compiled_engine_writes_the_librarys_compiled_run(tmp_path):
    run = DEFAULT | {"joint_friction": False}  # the compiled loop has the joints' damping, not stick-slip
    summary, columns, _ = runs(run, ["--engine", "compiled"], tmp_path)
    assert summary["engine"] == "compiled"
    command([*arguments_of(run | {"json": True}, None), "--compiled", "--out", str(tmp_path / "flag.csv")])
    flag = written_columns(tmp_path / "flag.csv")
    assert {name: list(values) for name, values in flag.items()} == {name: list(values) for name, values in columns.items()}
    robot = robot_of(run)
    start, rest = robot.default_configuration(), np.zeros(robot.nv)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        compiled = robodyn.simulate(robot, start, rest, DURATION, 1e-3, engine="compiled", joint_friction=False)
        python = robodyn.simulate(robot, start, rest, DURATION, 1e-3, engine="pinocchio", joint_friction=False)
    for kind in ("q", "v", "a"):
        for k, dof in enumerate(robot.dofs):
            written = columns[f"{kind}[{dof.name}]"]
            np.testing.assert_allclose(written, getattr(compiled, kind)[:, k], rtol=0, atol=1e-12 * max(1, np.abs(written).max()))
            np.testing.assert_allclose(written, getattr(python, kind)[:, k], rtol=0, atol=1e-9 * max(1, np.abs(written).max()))


def test_compiled_with_another_engine_is_one_stderr_line_naming_both(capsys):
    assert main([*arguments_of(dict(DEFAULT), None), "--compiled", "--engine", "pinocchio"]) == 2
    error = capsys.readouterr().err
    assert error.count("\n") == 1 and "--compiled" in error and "--engine pinocchio" in error
