"""`robodyn simulate --ground [HEIGHT] --friction MU --contact FRAME[,...]`: a robot on the ground."""

from __future__ import annotations

import csv
import shlex
from pathlib import Path

import pytest

from robodyn.cli.app import main
from tests.conftest import ROOT

BOX = str(Path(__file__).parents[1] / "data" / "contact" / "box.urdf")
MJCF_BOX = str(Path(__file__).parents[1] / "data" / "mjcf" / "contact_box.xml")
FEET = "FL_FOOT,FR_FOOT,HL_FOOT,HR_FOOT"


def run(capsys, *argv: str) -> tuple[int, str, str]:
    status = main(list(argv))
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def test_solo12_lands_on_its_feet_and_stands_under_a_pd_hold(capsys, tmp_path):
    out = tmp_path / "solo.csv"
    status, text, _ = run(
        capsys, "simulate", "solo12", "--ground", "--contact", FEET, "--controller", "pd", "--target", ",".join(["0"] * 12),
        "--kp", "5", "--kd", "0.1", "--duration", "0.6", "--out", str(out), "--record", str(tmp_path / "solo.html"),
    )  # fmt: skip
    assert status == 0 and (tmp_path / "solo.html").stat().st_size > 0  # with each foot's force as an arrow
    assert "engine: pinocchio (contact with a ground (the compiled engine models none))" in text
    assert "integrator semi-implicit-euler" in text and "contacts active at the end: 4 of 4" in text
    assert "final total 24.525 N" in text  # m g of solo12's 2.5 kg
    with out.open() as stream:
        next(stream)
        header = next(csv.reader([next(stream)]))
    assert "f[FL_FOOT].z" in header and "contact[HR_FOOT]" in header


def test_the_readmes_box_drops_flat_onto_its_files_floor_and_carries_its_weight(capsys):
    example = str(Path(__file__).parents[2] / "examples" / "ground_box.xml")
    status, text, _ = run(capsys, "simulate", example, "--ground", "--q0", "0,0,0.25,0,0,0,1", "--duration", "1")
    assert status == 0 and "ground (the file's plane): height 0 m, normal (0.0, 0.0, 1.0), μ 0.5; 8 contact points" in text
    assert "final total 24.525 N" in text and "deepest penetration: 0 m" in text  # m g of 2.5 kg


def test_a_floating_robot_without_a_ground_says_its_base_falls_freely(capsys):
    status, text, _ = run(capsys, "simulate", BOX, "--floating-base", "--duration", "0.01", "--engine", "pinocchio")
    assert status == 0 and "no ground: the base falls freely" in text


@pytest.mark.parametrize(
    ("model", "flags", "said"),
    [
        (MJCF_BOX, [], "ground (the file's plane): height 0.1 m, normal (0.0, 0.0, 1.0), μ 0.7;"),
        (MJCF_BOX, ["--friction", "0.25"], "ground (the file's plane, μ given): height 0.1 m, normal (0.0, 0.0, 1.0), μ 0.25;"),
        (
            MJCF_BOX,
            ["0.05"],
            "ground (flat at the height given, the file's plane's μ): height 0.05 m, normal (0.0, 0.0, 1.0), μ 0.7;",
        ),
        (MJCF_BOX, ["0.05", "--friction", "0.25"], "ground: height 0.05 m, normal (0.0, 0.0, 1.0), μ 0.25;"),
        (
            BOX,
            ["--floating-base"],
            "ground (flat at height 0: the file states no plane): height 0 m, normal (0.0, 0.0, 1.0), μ 1;",
        ),
    ],
)
def test_ground_without_a_height_is_the_files_plane_else_flat_at_zero(capsys, model, flags, said):
    status, text, _ = run(capsys, "simulate", model, "--duration", "0.002", "--ground", *flags)
    assert status == 0 and said in text


@pytest.mark.parametrize(
    ("flags", "said"),
    [
        (["--contact", "box"], "--contact must be given only with --ground"),
        (["--friction", "0.5"], "--friction must be given only with --ground"),
        (["--ground", "--friction", "-1"], "--friction must be"),
        (["--ground", "--integrator", "rk4"], "--integrator must be 'semi-implicit-euler' with a ground"),
        (["--ground", "--compiled"], "--ground must be left out for --engine compiled"),
        (["--ground", "--out", "x.npz"], "--out must be a .csv file for a run on the ground"),
        (["--ground", "--contact", "nope"], "has no frame named 'nope'"),
    ],
)
def test_impossible_ground_runs_are_one_stderr_line_and_exit_2(capsys, flags, said):
    status, _, err = run(capsys, "simulate", BOX, "--floating-base", "--duration", "0.01", *flags)
    assert status == 2 and said in err and len(err.strip().splitlines()) == 1


def _readme_ground_commands() -> list[list[str]]:
    """The ``robodyn`` commands of the README's ground section run from the repository's root."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    section = text[text.index("## Robots on the ground") :]
    block = section[section.index("```shell") + len("```shell") : section.index("```", section.index("```shell") + 3)]
    return [shlex.split(line)[1:] for line in block.splitlines() if line.startswith("robodyn ")]


@pytest.mark.slow
def test_the_readmes_ground_commands_run_from_the_repositorys_root(capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    commands = _readme_ground_commands()
    assert [command[1] for command in commands][:2] == ["examples/ground_box.xml", "tests/data/mjcf/contact_quadruped.xml"]
    assert commands[2][1].startswith("~/.cache/robodyn/gymnasium/")  # the ant: run by tests/sim/test_gymnasium_ground.py
    for command in commands[:2]:
        status, text, err = run(capsys, *command)
        assert status == 0 and "contacts active at the end" in text, err


def test_a_divergence_from_damping_on_a_light_body_is_warned_and_explained_on_the_command_line(capsys, tmp_path):
    from tests.sim.test_simulation import LIGHT_FINGER

    path = tmp_path / "finger.xml"
    path.write_text(LIGHT_FINGER)
    status, _, err = run(capsys, "simulate", str(path), "--duration", "0.1")
    warning, error = err.strip().splitlines()[-2:]
    assert status == 2 and "largest stable step" in warning and "'fingertip'" in warning
    assert error.startswith("robodyn: error: simulation diverged") and "damping on light links" in error
    assert "use dt <= " in error


def feet_anchored(tmp_path) -> str:
    path = tmp_path / "feet.yaml"
    path.write_text("anchor:\n" + "".join(f"  - {{frame1: {foot}, point1: [0, 0, 0]}}\n" for foot in FEET.split(",")))
    return str(path)


@pytest.mark.parametrize("integrator", [[], ["--integrator", "rk4"]])
def test_constraints_with_a_ground_are_refused_in_one_line_naming_both_flags(capsys, tmp_path, integrator):
    argv = ["simulate", "solo12", "--constraints", feet_anchored(tmp_path), "--ground", "--duration", "0.01", *integrator]
    status, _, err = run(capsys, *argv)
    assert status == 2 and err.count("\n") == 1
    assert "--ground" in err and "--constraints" in err and "--integrator" not in err


def test_a_floating_robot_its_constraints_hold_is_not_said_to_fall_freely(capsys, tmp_path):
    status, text, _ = run(capsys, "simulate", "solo12", "--constraints", feet_anchored(tmp_path), "--duration", "0.002")
    assert status == 0 and "falls freely" not in text
