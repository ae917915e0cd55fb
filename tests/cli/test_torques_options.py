"""Every option of `robodyn torques` alone, reading back what it wrote, and crossed pairwise.

Options tested together only hide a crossed wire (``--gravity-torques`` writing M, a chunk
size that changes a value, a gravity lost on a floating base). Each option here is first
run alone against the run with no option (what it adds or changes, and nothing else), then
a pairwise-covering set of runs (every pair of values of every two options appears in some
run; generated below, not all-together) is checked column by column against the Robot
loaded with the same options, the files read back without robodyn.

The robots: the oblique test robot (3-D, oblique non-unit axes, a prismatic joint, a fixed
joint between moving ones) and the xacro test arm (a mimic joint, read through
``--xacro-arg`` and ``--package``), both also floating.
"""

from __future__ import annotations

import contextlib
import io
import itertools
import json
import math

import numpy as np
import pytest

import robodyn
from robodyn.cli.app import main
from tests.cli.option_runs import GRAVITY, OBLIQUE, PACKAGE, XACRO, XACRO_ARGS
from tests.differential.cases import random_state_batch
from tests.differential.pairs import expected_header, written_columns
from tests.pairwise import pairwise, uncovered_pairs

ROWS = 23

#: Each option's values; the first is the default (the option left out).
FACTORS: dict[str, tuple] = {
    "model": ("oblique", "xacro"),
    "out": (".csv", ".npz", ".parquet", None),
    "gravity_torques": (False, True),
    "mass_matrix": (False, True),
    "chunk_rows": (None, 7),
    "gravity": (None, GRAVITY),
    "base": (None, "floating", "fixed"),
    "json": (False, True),
    "inertia": (None, "strict", "no-check"),
    "max_dof": (None, 12),
}
DEFAULT = {name: values[0] for name, values in FACTORS.items()}


RUNS = pairwise(FACTORS)


def test_the_runs_cover_every_pair_and_are_few():
    assert uncovered_pairs(RUNS, FACTORS) == []
    assert len(RUNS) <= 16  # not the 2304 of all combinations


def robot_of(options: dict) -> robodyn.Robot:
    """The robot as the Python API loads it with the run's options."""
    keywords: dict = {"floating_base": options["base"] == "floating" if options["base"] else None}
    if options["gravity"]:
        keywords["gravity"] = options["gravity"]
    if options["model"] == "xacro":
        return robodyn.load(XACRO, xacro_args=XACRO_ARGS, packages={"robodyn_test_arm": str(PACKAGE)}, **keywords)
    return robodyn.load(OBLIQUE, **keywords)


def arguments_of(options: dict, source, out) -> list[str]:
    model = [str(OBLIQUE)]
    if options["model"] == "xacro":
        model = [str(XACRO), *(f"--xacro-arg={k}:={v}" for k, v in XACRO_ARGS.items()), f"--package=robodyn_test_arm={PACKAGE}"]
    flags = {
        "gravity_torques": ["--gravity-torques"],
        "mass_matrix": ["--mass-matrix"],
        "json": ["--json"],
        "chunk_rows": ["--chunk-rows", str(options["chunk_rows"])],
        "gravity": ["--gravity=" + ",".join(map(str, options["gravity"] or ()))],
        "base": [f"--{options['base']}-base"],
        "inertia": ["--strict" if options["inertia"] == "strict" else "--no-check-inertia"],
        "max_dof": ["--max-dof", str(options["max_dof"])],
    }
    chosen = [flag for name, flag in flags.items() if options[name]]
    return ["torques", *model, str(source), *(["--out", str(out)] if out else []), *itertools.chain(*chosen)]


def run_cli(options: dict, tmp_path) -> tuple[robodyn.Robot, robodyn.Trajectory, dict | None, str]:
    """Write a trajectory of the run's robot (q, v, a only), run the command, and read back
    what it wrote (the file's columns, without robodyn) and printed."""
    robot = robot_of(options)
    q, v, a = random_state_batch(robot, np.random.default_rng(39), ROWS)
    trajectory = robodyn.Trajectory(np.arange(ROWS) * 0.01, q, v, a, None, list(robot.joint_names), robot.name)
    source = trajectory.save(tmp_path / "in.csv")
    out = tmp_path / f"out{options['out']}" if options["out"] else None
    stdout = io.StringIO()
    with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(io.StringIO()) as stderr:
        code = main(arguments_of(options, source, out))
    assert code == 0, stderr.getvalue()
    return robot, trajectory, (written_columns(out) if out else None), stdout.getvalue()


def check_run(options: dict, tmp_path) -> None:
    robot, trajectory, columns, printed = run_cli(options, tmp_path)
    dofs = [dof.name for dof in robot.dofs]
    upper = list(zip(*np.triu_indices(robot.nv), strict=True))
    tau = robot.inverse_dynamics(trajectory.q, trajectory.v, trajectory.a)
    if columns is not None:
        header = expected_header(robot)
        header += [f"G[{d}]" for d in dofs] if options["gravity_torques"] else []
        header += [f"M[{dofs[i]},{dofs[j]}]" for i, j in upper] if options["mass_matrix"] else []
        if options["out"] == ".npz":
            assert sorted(columns) == sorted(header)  # NPZ: named arrays, no column order
        else:
            assert list(columns) == header
        expected = {f"tau[{d}]": tau[:, k] for k, d in enumerate(dofs)}
        expected |= {f"q[{n}]": trajectory.q[:, k] for k, n in enumerate(robot.configuration_names)}
        if options["gravity_torques"]:
            expected |= {f"G[{d}]": robot.gravity(trajectory.q)[:, k] for k, d in enumerate(dofs)}
        if options["mass_matrix"]:
            mass = robot.mass_matrix(trajectory.q)
            expected |= {f"M[{dofs[i]},{dofs[j]}]": mass[:, i, j] for i, j in upper}
        for name, values in expected.items():
            np.testing.assert_allclose(columns[name], values, rtol=1e-12, atol=1e-12 * np.abs(tau).max(), err_msg=name)
    chunks = math.ceil(ROWS / (options["chunk_rows"] or ROWS))
    if options["json"]:
        summary = json.loads(printed)
        assert summary["samples"] == ROWS and summary["chunks"] == chunks
        assert list(summary["peak_abs_torque"]) == dofs
        np.testing.assert_allclose(list(summary["peak_abs_torque"].values()), np.abs(tau).max(axis=0), rtol=1e-12)
        assert ("out" in summary) == (columns is not None)
    else:
        assert f"samples: {ROWS} ({chunks} chunks)" in printed
        assert ("wrote " in printed) == (columns is not None)


ALONE = [(name, value) for name, values in FACTORS.items() for value in values[1:]]


@pytest.mark.parametrize(("option", "value"), ALONE, ids=[f"{name}={value}" for name, value in ALONE])
def test_each_option_alone_writes_what_it_says_and_nothing_else(option, value, tmp_path):
    options = DEFAULT | {option: value}
    if options["out"] is None and option != "out":
        options["out"] = ".csv"  # read back a file (the default writes none)
    check_run(options, tmp_path)


@pytest.mark.parametrize("run", RUNS, ids=[str(k) for k in range(len(RUNS))])
def test_the_options_crossed_pairwise_write_the_robots_numbers(run, tmp_path):
    check_run(run, tmp_path)


def test_gravity_torques_alone_and_mass_matrix_alone_write_different_columns(tmp_path):
    """The crossed wire itself: each flag alone adds its own columns, and only those."""
    header = set(expected_header(robot_of(DEFAULT)))
    (tmp_path / "g").mkdir()
    (tmp_path / "m").mkdir()
    _, _, g_columns, _ = run_cli(DEFAULT | {"out": ".csv", "gravity_torques": True}, tmp_path / "g")
    _, _, m_columns, _ = run_cli(DEFAULT | {"out": ".csv", "mass_matrix": True}, tmp_path / "m")
    assert g_columns is not None and m_columns is not None
    assert {name[:2] for name in set(g_columns) - header} == {"G["}
    assert {name[:2] for name in set(m_columns) - header} == {"M["}


def test_a_xacro_model_without_its_package_or_with_too_few_dofs_is_one_line(tmp_path, capsys, monkeypatch):
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    robot = robot_of(DEFAULT)
    q, v, a = random_state_batch(robot, np.random.default_rng(1), 5)
    source = robodyn.Trajectory(np.arange(5.0), q, v, a, None, list(robot.joint_names), robot.name).save(tmp_path / "in.csv")
    assert main(["torques", str(OBLIQUE), str(source), "--max-dof", "2"]) == 2
    error = capsys.readouterr().err
    assert error.count("\n") == 1 and "2" in error
    assert main(["torques", str(XACRO), str(source)]) == 2
    assert capsys.readouterr().err.count("\n") == 1
