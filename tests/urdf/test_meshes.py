"""One rule for every bad mesh: the model loads, lint warns, drawings show a placeholder box
(issue 29, item 6: a FIFO made ``record`` fail with exit 2)."""

from __future__ import annotations

import os
import signal

import numpy as np
import pytest

import robodyn
from robodyn.cli import main
from robodyn.trajectory import Trajectory
from robodyn.urdf.sources import lint_source

STL_TRIANGLE = (
    b"\0" * 80 + (1).to_bytes(4, "little") + np.array([0, 0, 1, 0, 0, 0, 0.1, 0, 0, 0, 0.1, 0], "<f4").tobytes() + b"\0\0"
)


@pytest.fixture
def fifo_arm(tmp_path):
    """The RP arm whose first visual is a mesh that is a FIFO (nobody ever writes to it)."""
    os.mkfifo(tmp_path / "pipe.stl")
    text = robodyn.rp_arm_urdf().replace(
        '<geometry><box size="0.5 0.05 0.05"/></geometry>', '<geometry><mesh filename="pipe.stl"/></geometry>', 1
    )
    path = tmp_path / "arm.urdf"
    path.write_text(text)
    previous = signal.signal(signal.SIGALRM, lambda *_: (_ for _ in ()).throw(TimeoutError("blocked on the FIFO")))
    signal.alarm(60)
    yield path
    signal.alarm(0)
    signal.signal(signal.SIGALRM, previous)


def test_a_fifo_mesh_is_a_lint_warning_like_a_missing_one(fifo_arm):
    problems = lint_source(str(fifo_arm))
    assert [p.severity for p in problems] == ["warning"]
    assert "not a regular file" in problems[0].rule and "placeholder" in problems[0].rule


def test_record_draws_a_fifo_mesh_as_the_placeholder_box_with_one_warning(fifo_arm, tmp_path, capsys):
    robot = robodyn.load(fifo_arm)
    t = np.linspace(0, 0.5, 6)
    q = np.column_stack([np.linspace(0, 0.5, 6), np.full(6, 0.1)])
    Trajectory(t, q, np.zeros_like(q), np.zeros_like(q), np.zeros_like(q), robot.joint_names, robot.name).save(tmp_path / "m.csv")
    out = tmp_path / "m.html"
    code = main(["record", str(fifo_arm), "--trajectory", str(tmp_path / "m.csv"), "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 0, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("robodyn: warning: link ") and "placeholder box" in lines[0]
    assert "not a regular file" in lines[0] and out.stat().st_size > 10_000


def test_is_regular_file_follows_links_and_never_opens(tmp_path):
    from robodyn.urdf.meshes import is_regular_file

    (tmp_path / "mesh.stl").write_bytes(b"solid x\nendsolid x\n")
    os.mkfifo(tmp_path / "pipe.stl")
    (tmp_path / "link.stl").symlink_to(tmp_path / "mesh.stl")
    assert is_regular_file(tmp_path / "mesh.stl") and is_regular_file(tmp_path / "link.stl")
    assert not is_regular_file(tmp_path / "pipe.stl") and not is_regular_file(tmp_path / "missing.stl")
    assert not is_regular_file(tmp_path)
