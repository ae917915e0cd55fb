"""run_experiment and run_whatif: the library calls behind ``robodyn simulate`` and
``robodyn whatif``, with their files (issue 23)."""

from __future__ import annotations

import json

import robodyn
from robodyn.cli import main
from robodyn.trajectory import Trajectory
from robodyn.viz.experiment import run_experiment, run_whatif


def test_run_experiment_writes_the_trajectory_and_names_it_in_the_summary(tmp_path):
    robot = robodyn.load("rp_arm")
    summary = run_experiment(robot, duration=0.05, out=tmp_path / "m.csv")
    assert summary.files == (("trajectory", str(tmp_path / "m.csv")),)
    assert summary.to_dict()["trajectory"] == str(tmp_path / "m.csv")
    assert len(Trajectory.load(tmp_path / "m.csv")) == summary.steps + 1


def test_the_whatif_table_is_the_json_and_text_the_cli_prints(capsys):
    options = {"payloads": (0.0, 1.0), "duration": 0.5}
    assert main(["whatif", "rp_arm", "--payloads", "0,1", "--duration", "0.5", "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    table = run_whatif("rp_arm", **options)
    assert printed == json.loads(json.dumps(table.to_dict(), allow_nan=False))
    assert printed["torque_units"] == ["N m", "N"]  # joint1 revolute, joint2 prismatic: from robot.dofs
    assert main(["whatif", "rp_arm", "--payloads", "0,1", "--duration", "0.5"]) == 0
    assert capsys.readouterr().out.rstrip("\n") == table.text()


def test_the_whatif_plot_is_written_and_named(tmp_path):
    table = run_whatif("rp_arm", payloads=(0.0,), duration=0.5, plot=tmp_path / "w.png")
    assert (tmp_path / "w.png").read_bytes()[:4] == b"\x89PNG"
    assert table.to_dict()["plot"] == str(tmp_path / "w.png") and table.text().endswith(f"plot: {tmp_path / 'w.png'}")


def test_whatif_loads_the_robot_once(monkeypatch, capsys):
    import robodyn.sim.whatif as whatif

    calls = []
    original = whatif.load

    def counted(*args, **kwargs):
        calls.append(args)
        return original(*args, **kwargs)

    monkeypatch.setattr(whatif, "load", counted)
    monkeypatch.setattr(robodyn, "load", counted)
    assert main(["whatif", "ur5", "--payloads", "0", "--duration", "0.5", "--json"]) == 0
    assert len(calls) == 1 and json.loads(capsys.readouterr().out)["torque_units"] == ["N m"] * 6


def test_record_files_writes_the_page_and_says_what_it_wrote(tmp_path, capsys):
    from robodyn.viz.experiment import RecordingRun, record_files

    robot = robodyn.load("rp_arm")
    summary = run_experiment(robot, duration=0.2, out=tmp_path / "m.csv")
    run = record_files(robot, Trajectory.load(summary.files[0][1]).for_robot(robot), tmp_path / "m.html", fps=10)
    assert isinstance(run, RecordingRun) and run.path == str(tmp_path / "m.html")
    assert run.size == (tmp_path / "m.html").stat().st_size and run.extras == () and run.duration > 0
    assert run.text().startswith(f"wrote {tmp_path / 'm.html'} (") and " s at 10 fps, " in run.text()
    assert json.loads(json.dumps(run.to_dict()))["size_bytes"] == run.size
    argv = ["record", "rp_arm", "--trajectory", str(tmp_path / "m.csv"), "--out", str(tmp_path / "c.html"), "--fps", "10"]
    assert main(argv) == 0
    assert capsys.readouterr().out.startswith(f"wrote {tmp_path / 'c.html'} (")
    assert abs((tmp_path / "c.html").stat().st_size - run.size) < 0.01 * run.size  # the same page (meshcat's uuids aside)
