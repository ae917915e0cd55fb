"""`robodyn simulate` writes all of its files or none, and takes --compiled."""

from __future__ import annotations

import json
import shutil

import pytest

from robodyn.cli.app import main


def test_a_failed_output_leaves_every_earlier_file_untouched(tmp_path, capsys):
    old = tmp_path / "m.csv"
    old.write_text("the user's old trajectory\n")
    status = main(
        ["simulate", "rp_arm", "--duration", "0.1", "--out", str(old), "--record", str(tmp_path / "missing" / "m.html")]
    )
    assert status == 2
    error = capsys.readouterr().err.strip()
    assert error.count("\n") == 0 and "does not exist" in error
    assert old.read_text() == "the user's old trajectory\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.csv"]  # no temporary left behind


def test_outputs_are_written_together_when_all_succeed(tmp_path, capsys):
    status = main(
        ["simulate", "rp_arm", "--duration", "0.1", "--out", str(tmp_path / "m.npz"), "--plot", str(tmp_path / "m.png"), "--json"]
    )
    assert status == 0
    summary = json.loads(capsys.readouterr().out)
    assert (tmp_path / "m.npz").is_file() and (tmp_path / "m.png").is_file()
    assert summary["engine"] == "pinocchio"


@pytest.mark.skipif(shutil.which("cc") is None and shutil.which("gcc") is None, reason="no C compiler")
def test_compiled_flag_gives_the_same_summary(capsys):
    arguments = ["simulate", "ur5", "--controller", "pd", "--target", "0.3,-1.2,1.0,-0.5,0.4,0.2", "--duration", "0.5", "--json"]
    assert main(arguments) == 0
    python = json.loads(capsys.readouterr().out)
    assert main([*arguments, "--compiled"]) == 0
    compiled = json.loads(capsys.readouterr().out)
    assert compiled["engine"] == "compiled"
    for left, right in zip(python["final_q"], compiled["final_q"], strict=True):
        assert abs(left - right) < 1e-9
    assert main(["simulate", "solo12", "--duration", "0.1", "--compiled"]) == 2
    assert "floating" in capsys.readouterr().err
