"""TorquesRun: the result of ``robodyn torques`` with its units, JSON and text (issue 23).

Also here:

- `robodyn torques` and robodyn.scale.torques_file: inverse dynamics over a file, in chunks.
"""

from __future__ import annotations

import csv
import json
import os
import subprocess
import sys
import textwrap
import warnings

import numpy as np
import pytest

import robodyn
from robodyn.cli import main
from robodyn.exceptions import InputError, TrajectoryError
from robodyn.scale.datasets import Dataset
from robodyn.scale.torques import TorquesRun, torques_file
from robodyn.sim.simulation import simulate
from robodyn.trajectory import Trajectory
from tests.sim.robots import SLIDER_URDF


@pytest.fixture
def slider_run(tmp_path):
    """A floating-base robot with a revolute and a prismatic joint, and a motion of it."""
    robot = robodyn.load(SLIDER_URDF, floating_base=True)
    q0 = robot.default_configuration()
    v0 = np.linspace(-0.5, 0.5, robot.nv)
    path = tmp_path / "motion.csv"
    simulate(robot, q0, v0, 0.05, 1e-3).save(path)
    return robot, path


def test_the_csv_header_and_the_text_carry_the_dofs_names_and_units(slider_run, tmp_path, capsys):
    robot, path = slider_run
    out = tmp_path / "tau.csv"
    assert main(["torques", SLIDER_URDF, "--floating-base", str(path), "--out", str(out)]) == 0
    text = capsys.readouterr().out
    with out.open() as handle:
        header = next(row for row in csv.reader(handle) if row and not row[0].startswith("#"))
    names = ["base.x", "base.y", "base.z", "base.rx", "base.ry", "base.rz", "shoulder", "slide"]
    assert [column for column in header if column.startswith("tau[")] == [f"tau[{name}]" for name in names]
    assert [column for column in header if column.startswith("q[")][3:7] == [
        "q[base.qx]",
        "q[base.qy]",
        "q[base.qz]",
        "q[base.qw]",
    ]
    lines = {line.split(":")[0].strip(): line for line in text.splitlines() if line.startswith("  ")}
    assert set(lines) == set(names)
    for dof in robot.dofs:
        assert lines[dof.name].endswith(f" {dof.effort_unit}") and f" {dof.effort_unit}, " in lines[dof.name]
    assert lines["base.x"].endswith(" N") and lines["base.rx"].endswith(" N m")
    assert lines["slide"].endswith(" N") and lines["shoulder"].endswith(" N m")


def test_to_dict_is_the_json_the_cli_prints(slider_run, capsys):
    robot, path = slider_run
    assert main(["torques", SLIDER_URDF, "--floating-base", str(path), "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    run = torques_file(robot, path)
    assert isinstance(run, TorquesRun)
    assert printed == run.to_dict()
    assert list(printed["peak_abs_torque"]) == [dof.name for dof in robot.dofs]
    assert run.units == tuple(dof.effort_unit for dof in robot.dofs)


def test_an_overflow_is_refused_by_the_library_naming_trajectory_and_leaves_no_file(tmp_path):
    robot = robodyn.load("rp_arm")
    count = 5
    t = np.arange(count) * 0.01
    q = np.zeros((count, 2))
    v = np.full((count, 2), 1e80)  # C(q, v) v ≈ 1e160: finite; its square is not
    source, out = tmp_path / "fast.npz", tmp_path / "out.csv"
    Trajectory(t, q, v, np.zeros_like(v), None, list(robot.joint_names), robot.name).save(source)
    with warnings.catch_warnings(), pytest.raises(InputError) as raised:
        warnings.simplefilter("error")  # refused, not warned about
        torques_file(robot, source, out)
    assert raised.value.argument == "trajectory" and "finite" in str(raised.value)
    assert not out.exists() and not list(tmp_path.glob("*.part"))


@pytest.fixture(scope="module")
def panda():
    return robodyn.load("panda")


@pytest.fixture(scope="module")
def driven(panda):
    """A panda trajectory under a non-trivial torque: ABA gave a, so RNEA must give tau back."""
    rng = np.random.default_rng(3)
    gains = rng.uniform(0.5, 2.0, panda.nv)
    trajectory = simulate(
        panda,
        panda.neutral_configuration() + 0.2,
        np.zeros(panda.nv),
        0.3,
        1e-3,
        controller=lambda t, q, v: gains * np.sin(7 * t + q),
        joint_friction=False,  # rigid body: RNEA gives the applied torque back
    )
    trajectory.a[-1] = panda.forward_dynamics(
        trajectory.q[-1], trajectory.v[-1], trajectory.tau[-1]
    )  # simulate repeats the last a
    return trajectory


@pytest.mark.parametrize("suffix", [".csv", ".npz", ".parquet"])
@pytest.mark.parametrize("out_suffix", [".csv", ".npz", ".parquet"])
def test_torques_give_back_the_applied_torques(tmp_path, panda, driven, suffix, out_suffix):
    """An independent check: forward dynamics (ABA) made the motion, inverse dynamics (RNEA) recovers tau."""
    if ".parquet" in (suffix, out_suffix):
        pytest.importorskip("pyarrow")
    source = tmp_path / f"in{suffix}"
    _save(driven, source)
    out = tmp_path / f"out{out_suffix}"
    summary = torques_file(panda, source, out, rows=64, gravity=True, mass_matrix=True)
    assert summary["samples"] == len(driven) and summary["chunks"] == 5
    result = Trajectory.load(out)
    np.testing.assert_allclose(result.tau, driven.tau, atol=1e-9)
    assert np.abs(driven.tau).max() > 0.5  # not trivially zero
    np.testing.assert_array_equal(result.q, driven.q)
    if out_suffix == ".npz":
        with np.load(out) as data:
            np.testing.assert_allclose(data["M"], panda.mass_matrix(driven.q), rtol=0, atol=1e-14)
            np.testing.assert_allclose(data["G"], panda.gravity(driven.q), rtol=0, atol=1e-14)


def _save(trajectory, path):
    if path.suffix == ".parquet":
        from robodyn.scale.datasets import write_parquet

        write_parquet(path, trajectory)
    else:
        trajectory.save(path)


@pytest.fixture(params=["arrow", "numpy"])
def csv_reader(request, monkeypatch):
    """Both CSV paths: pyarrow's reader/writer and the numpy fallback."""
    from robodyn.scale import csvio

    if request.param == "arrow":
        pytest.importorskip("pyarrow")
    monkeypatch.setattr(csvio, "USE_ARROW", request.param == "arrow")
    return request.param


def test_chunked_derivatives_equal_the_whole_file(tmp_path, panda, driven, csv_reader):
    """A file with only t and q: each chunk is differentiated with its neighbours' rows, so chunks change nothing."""
    t = np.concatenate([[0.0], np.cumsum(np.random.default_rng(0).uniform(0.5e-3, 1.5e-3, len(driven) - 1))])  # non-uniform steps
    path = tmp_path / "q.csv"
    path.write_text(
        "t,"
        + ",".join(f"q[{j}]" for j in panda.joint_names)
        + "\n"
        + "".join(",".join(map(repr, [ti, *qi])) + "\n" for ti, qi in zip(t.tolist(), driven.q.tolist(), strict=True))
    )
    whole = Trajectory.load(path)
    for rows in (3, 7, 64, 1000):
        parts = list(Dataset(path, rows=rows).chunks())
        np.testing.assert_array_equal(np.concatenate([c.trajectory.v for c in parts]), whole.v)
        np.testing.assert_array_equal(np.concatenate([c.trajectory.a for c in parts]), whole.a)
        assert [c.first_row for c in parts] == list(range(1, len(whole) + 1, rows))


def test_blank_lines_and_crlf_in_csv(tmp_path, panda, driven):
    driven.save(tmp_path / "m.csv")
    text = (tmp_path / "m.csv").read_text().replace("\n", "\r\n") + "\r\n\r\n"
    (tmp_path / "w.csv").write_bytes(text.encode())
    torques_file(panda, tmp_path / "w.csv", tmp_path / "o.npz", rows=100)
    with np.load(tmp_path / "o.npz") as data:
        np.testing.assert_allclose(data["tau"], driven.tau, atol=1e-9)


def test_cli_writes_tau_columns_and_json(tmp_path, panda, driven, capsys):
    driven.save(tmp_path / "m.csv")
    assert (
        main(["torques", "panda", str(tmp_path / "m.csv"), "--out", str(tmp_path / "tau.csv"), "--json", "--chunk-rows", "50"])
        == 0
    )
    summary = json.loads(capsys.readouterr().out)
    assert summary["samples"] == len(driven) and summary["out"].endswith("tau.csv")
    header = (tmp_path / "tau.csv").read_text().splitlines()[1].split(",")
    assert [h for h in header if h.startswith("tau[")] == [f"tau[{j}]" for j in panda.joint_names]
    np.testing.assert_allclose(summary["peak_abs_torque"]["panda_joint2"], np.abs(driven.tau[:, 1]).max(), atol=1e-9)


def test_cli_progress_on_stderr_and_same_file_refused(tmp_path, driven, capsys, monkeypatch):
    from robodyn.cli.common import Progress

    driven.save(tmp_path / "m.npz")
    monkeypatch.setattr(Progress, "DELAY", 0.0)
    monkeypatch.setattr("robodyn.cli.common._is_terminal", lambda stream: True)  # progress only on a terminal
    assert main(["torques", "panda", str(tmp_path / "m.npz"), "--chunk-rows", "100"]) == 0
    captured = capsys.readouterr()
    assert "torques: inverse dynamics" in captured.err and "301/301" in captured.err
    assert "panda_joint4:" in captured.out and "samples: 301 (4 chunks)" in captured.out
    assert main(["torques", "panda", str(tmp_path / "m.npz"), "--out", str(tmp_path / "m.npz")]) == 2
    assert "--out must be a file other than the trajectory read" in capsys.readouterr().err


def test_cli_another_robot_is_one_line(tmp_path, driven, capsys):
    driven.save(tmp_path / "m.csv")
    assert main(["torques", "ur5", str(tmp_path / "m.csv"), "--out", str(tmp_path / "x.csv")]) == 2
    error = capsys.readouterr().err
    assert error.count("\n") == 1 and "does not fit robot 'ur5'" in error
    assert not (tmp_path / "x.csv").exists()


@pytest.mark.parametrize("suffix", [".csv", ".npz"])
def test_bad_rows_name_file_and_row_and_leave_no_output(tmp_path, solo_trajectory, suffix):
    robot, trajectory = solo_trajectory
    bad = Trajectory(
        trajectory.t, trajectory.q.copy(), trajectory.v, trajectory.a, trajectory.tau, trajectory.joint_names, "solo12"
    )
    bad.q[37, 3:7] = [0.5, 0.5, 0.5, 0.9]  # not a unit quaternion (finite: only the robot can refuse it)
    source = tmp_path / f"bad{suffix}"
    bad.save(source)
    out = tmp_path / "out.npz"
    out.write_bytes(b"the user's file")
    with pytest.raises(TrajectoryError, match=rf"bad{suffix}, row 38: q\[3:7\] must be a unit quaternion"):
        torques_file(robot, source, out, rows=16)
    assert out.read_bytes() == b"the user's file"
    assert {p.name for p in tmp_path.iterdir()} == {source.name, "out.npz"}  # no temporary left


def test_csv_writers_agree_to_the_bit(tmp_path, panda, driven, csv_reader):
    driven.save(tmp_path / "m.csv")
    torques_file(panda, tmp_path / "m.csv", tmp_path / "o.csv", rows=50, mass_matrix=True)
    back = Trajectory.load(tmp_path / "o.csv")
    np.testing.assert_array_equal(back.tau, panda.inverse_dynamics(driven.q, driven.v, driven.a))


def test_csv_row_that_is_not_numbers(tmp_path, panda, driven, csv_reader):
    driven.save(tmp_path / "m.csv")
    lines = (tmp_path / "m.csv").read_text().splitlines()
    lines[1 + 120] = lines[1 + 120].replace(",", ",x", 1)
    (tmp_path / "m.csv").write_text("\n".join(lines) + "\n")
    with pytest.raises(TrajectoryError, match=r"m\.csv, rows? [\d-]+: a row is not 33 numbers") as error:
        torques_file(panda, tmp_path / "m.csv", tmp_path / "o.csv", rows=64)
    assert error.value.rows[0] <= 120 <= error.value.rows[1]
    assert not (tmp_path / "o.csv").exists()


def test_nan_in_a_later_chunk_leaves_no_output(tmp_path, panda, driven, csv_reader):
    driven.save(tmp_path / "m.csv")
    lines = (tmp_path / "m.csv").read_text().splitlines()
    cells = lines[1 + 251].split(",")  # comment, header, then data row 1
    cells[1] = "nan"
    lines[1 + 251] = ",".join(cells)
    (tmp_path / "m.csv").write_text("\n".join(lines) + "\n")
    with pytest.raises(TrajectoryError, match=r"m\.csv, row 251: q\[panda_joint1\] is nan"):
        torques_file(panda, tmp_path / "m.csv", tmp_path / "o.csv", rows=64)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.csv"]


@pytest.fixture(scope="module")
def solo_trajectory():
    robot = robodyn.load("solo12")
    rng = np.random.default_rng(5)
    q0 = robot.floating_configuration([0, 0, 0.3], [0.1, 0.2, 0.3], rng.uniform(-0.5, 0.5, 12))
    return robot, simulate(robot, q0, rng.normal(size=robot.nv), 0.1, 1e-3)


def test_floating_base_and_q_only_files(tmp_path, solo_trajectory):
    """solo12 from t and q only: v, a derived (base frame), torques close to the simulated ones (zero: passive)."""
    robot, trajectory = solo_trajectory
    np.savez(
        tmp_path / "q.npz",
        t=trajectory.t,
        q=trajectory.q,
        q_names=np.array(
            Trajectory(trajectory.t, trajectory.q, trajectory.v, trajectory.a, None, trajectory.joint_names).coordinate_names[0]
        ),
    )
    summary = torques_file(robot, tmp_path / "q.npz", tmp_path / "tau.npz", rows=25)
    with np.load(tmp_path / "tau.npz") as data:
        tau, v = data["tau"], data["v"]
    np.testing.assert_allclose(v[2:-2], trajectory.v[2:-2], atol=2e-3 * np.abs(trajectory.v).max())
    scale = np.abs(robot.inverse_dynamics(trajectory.q, np.zeros_like(trajectory.v), np.zeros_like(trajectory.v))).max()
    assert np.abs(tau[2:-2]).max() < 1e-2 * scale  # passive motion: tau ≈ 0, to the differentiation error
    assert summary["chunks"] == 5


@pytest.mark.slow
def test_memory_stays_bounded_on_a_file_larger_than_the_limit(tmp_path):
    """A 600 MB NPZ through `robodyn torques` in a process limited to 450 MB of address space."""
    script = textwrap.dedent(
        f"""
        import resource, sys, numpy as np, robodyn
        from robodyn.scale.datasets import DatasetWriter
        robot = robodyn.load("panda")
        rows, chunk = 3_000_000, 200_000
        names = [f"q[{{j}}]" for j in robot.joint_names]
        header = ["t", *names, *(n.replace("q[", k + "[") for k in ("v", "a") for n in names)]
        arrays = {{"t": (np.array([0]), ()), "q": (np.arange(1, 9), (8,)), "v": (np.arange(9, 17), (8,)), "a": (np.arange(17, 25), (8,))}}
        writer = DatasetWriter({str(tmp_path / "big.npz")!r}, header, length=rows, arrays=arrays)
        rng = np.random.default_rng(0)
        for start in range(0, rows, chunk):
            q = robot.random_configuration(rng, chunk)
            writer.write(np.column_stack([(start + np.arange(chunk)) * 1e-3, q, rng.normal(size=(chunk, 16))]))
        writer.close(small={{"q_names": np.array(robot.joint_names), "v_names": np.array(robot.joint_names)}})
        """
    )
    subprocess.run([sys.executable, "-c", script], check=True)
    size = (tmp_path / "big.npz").stat().st_size
    limit = 450 * 2**20
    assert size > limit * 1.25
    run = textwrap.dedent(
        f"""
        import resource, sys
        resource.setrlimit(resource.RLIMIT_AS, ({limit}, {limit}))
        from robodyn.cli import main
        code = main(["torques", "panda", {str(tmp_path / "big.npz")!r}, "--out", {str(tmp_path / "tau.npz")!r}, "--json"])
        # VmHWM, not ru_maxrss: Linux keeps ru_maxrss across exec, so it would include the
        # RSS of the pytest process this one was forked from.
        peak = next(line for line in open("/proc/self/status") if line.startswith("VmHWM:")).split()[1]
        print("peak_rss_kb", peak, file=sys.stderr)
        sys.exit(code)
        """
    )
    done = subprocess.run([sys.executable, "-c", run], capture_output=True, text=True, env={**os.environ, "OMP_NUM_THREADS": "1"})
    assert done.returncode == 0, done.stderr[-2000:]
    peak = int(done.stderr.split("peak_rss_kb")[1].split()[0]) * 1024
    assert peak < limit
    assert json.loads(done.stdout)["samples"] == 3_000_000
    with np.load(tmp_path / "tau.npz", mmap_mode=None) as data:
        assert data["tau"].shape == (3_000_000, 8)


@pytest.mark.parametrize("layout", ["compressed", "columns", "fortran"])
def test_npz_variants_stream_like_a_whole_load(tmp_path, panda, driven, layout):
    path = tmp_path / "m.npz"
    names = np.array(panda.joint_names)
    if layout == "compressed":
        np.savez_compressed(path, t=driven.t, q=driven.q, v=driven.v, a=driven.a, q_names=names, v_names=names)
    elif layout == "columns":
        columns = {
            f"{kind}[{j}]": getattr(driven, kind)[:, i] for kind in ("q", "v", "a") for i, j in enumerate(panda.joint_names)
        }
        np.savez(path, t=driven.t, **columns)
    else:
        np.savez(path, t=driven.t, q=np.asfortranarray(driven.q), v=driven.v, a=driven.a, q_names=names, v_names=names)
    parts = list(Dataset(path, rows=40).chunks())
    whole = Trajectory.load(path)
    for kind in ("t", "q", "v", "a"):
        np.testing.assert_array_equal(np.concatenate([getattr(c.trajectory, kind) for c in parts]), getattr(whole, kind))
    np.testing.assert_array_equal(whole.q, driven.q)
