"""Every option of `robodyn observe` alone, reading back what it wrote, and crossed pairwise.

The input is a motion of the options' robot (constant velocity, so every sample is exact)
whose motor torques leave out a known external wrench at the end effector from 0.1 s on
(``tau = RNEA(q, v, 0) − Jᵀ w``). Each run is checked three ways: the estimate settles on
``Jᵀ w`` (and, for a negative control, the robot of the default gravity does not where the
run gives another); what it
wrote (read back with the csv module) and printed equal
:func:`robodyn.sim.observer.observe_file` given the same options; and each option alone
changes what it says and nothing else against the run with none (a frame adds the wrench
columns, a threshold a collision line, ``--torque sampled`` the estimate, ...).

The robots: the oblique test robot and the xacro test arm (mimic joint, ``--xacro-arg``,
``--package``), fixed or floating, locked or not, under the default or an oblique gravity.
The runs take about 0.2 s of CPU each: the slow tier.
"""

from __future__ import annotations

import csv
import json
from dataclasses import replace

import numpy as np
import pytest

from robodyn.sim.observer import WRENCH_COLUMNS, observe_file
from robodyn.trajectory import Trajectory
from robodyn.trajectory.io import write_with_extras
from tests.cli.model_options import GRAVITY, model_arguments, refused_in_one_line, robot_of, run_command
from tests.differential.cases import random_state_batch
from tests.pairwise import pairwise, uncovered_pairs

SAMPLES, DT, PUSHED_AT, SETTLED_AT = 61, 0.005, 0.1, 0.2
#: The end effector of each model, where the external wrench acts (world axes: N, N m).
FRAMES = {"oblique": "end_effector", "xacro": "r_wrist"}
WRENCH = np.array([3.0, -2.0, 4.0, 0.3, 0.2, -0.1])

#: Each option's values; the first is the default (the option left out; ``--gain`` is required).
FACTORS: dict[str, tuple | list] = {
    "model": ("oblique", "xacro"),
    "base": (None, "floating"),
    "gravity": (None, GRAVITY),
    "lock": (None, "locked"),
    "gain": (100.0, 60.0),
    "torque": ("held", "sampled"),
    "frame": (None, "end effector"),
    "threshold": (None, 1.0),
    "out": (None, ".csv"),
    "json": (False, True),
}
DEFAULT = {name: values[0] for name, values in FACTORS.items()}
RUNS = pairwise(FACTORS)


def test_the_runs_cover_every_pair_and_are_few():
    assert uncovered_pairs(RUNS, FACTORS) == []
    assert len(RUNS) <= 12  # not the 1024 of all combinations


def recorded_motion(robot, model: str, path) -> np.ndarray:
    """Write a motion of ``robot`` pushed by :data:`WRENCH` from :data:`PUSHED_AT` on (with its
    ``tau_env`` columns); return the external torques ``Jᵀ w``, shape (N, nv)."""
    rng = np.random.default_rng(39)
    (q0,), _, _ = random_state_batch(robot, rng, 1)
    t = np.arange(SAMPLES) * DT
    v = np.tile(rng.uniform(-0.4, 0.4, robot.nv), (SAMPLES, 1))
    q = robot.integrate(np.tile(q0, (SAMPLES, 1)), v * t[:, None])
    a = np.zeros_like(v)
    external = np.array([robot.wrench_torques(row, FRAMES[model], WRENCH) for row in q]) * (t >= PUSHED_AT)[:, None]
    tau = robot.inverse_dynamics(q, v, a) - external
    write_with_extras(path, Trajectory(t, q, v, a, tau, list(robot.joint_names), robot.name), {"tau_env": external})
    return external


def run_cli(options: dict, tmp_path):
    """Record the options' robot's motion, run the command; what it wrote (csv module) and printed."""
    robot = robot_of(options)
    source = tmp_path / "pushed.csv"
    external = recorded_motion(robot, options["model"], source)
    out = tmp_path / "estimate.csv" if options["out"] else None
    argv = ["observe", *model_arguments(options), str(source), "--gain", str(options["gain"])]
    argv += ["--torque", options["torque"]] if options["torque"] != "held" else []
    argv += ["--frame", FRAMES[options["model"]]] if options["frame"] else []
    argv += ["--threshold", str(options["threshold"])] if options["threshold"] else []
    argv += (["--out", str(out)] if out else []) + (["--json"] if options["json"] else [])
    code, printed, error = run_command(argv)
    assert code == 0, error
    columns = None
    if out:
        rows = [row for row in csv.reader(out.read_text().splitlines()) if row and not row[0].startswith("#")]
        columns = dict(zip(rows[0], np.array(rows[1:], dtype=float).T, strict=True))
    return robot, source, external, columns, printed


def check_run(options: dict, tmp_path) -> tuple[dict | None, str]:
    robot, source, external, columns, printed = run_cli(options, tmp_path)
    keywords = {name: options[name] for name in ("gain", "torque", "threshold")}
    keywords["frame"] = FRAMES[options["model"]] if options["frame"] else None
    expected = observe_file(robot, source, **keywords)
    # The estimate finds the push; the robot under the other gravity does not (negative control).
    settled = expected.t >= SETTLED_AT
    tolerance = 0.03 * np.abs(external).max()
    assert np.abs(expected.residual[settled] - external[settled]).max() <= tolerance
    if options["gravity"]:
        other = robot_of(options | {"gravity": None})
        assert np.abs(observe_file(other, source, **keywords).residual[settled] - external[settled]).max() > 5 * tolerance
    dofs = [dof.name for dof in robot.dofs]
    if columns is not None:  # the file: t, the estimate, with a frame its wrench
        header = ["t", *(f"tau_ext[{d}]" for d in dofs), *(WRENCH_COLUMNS if options["frame"] else ())]
        assert list(columns) == header
        np.testing.assert_array_equal(columns["t"], expected.t)
        estimate = np.column_stack([columns[f"tau_ext[{d}]"] for d in dofs])
        np.testing.assert_array_equal(estimate, expected.residual)
        if options["frame"]:
            wrench = np.column_stack([columns[name] for name in WRENCH_COLUMNS])
            np.testing.assert_array_equal(wrench, expected.wrench)
            if not robot.floating_base:  # fewer than six joints: the wrench explains the estimate exactly
                jacobian = robot.frame_jacobian(_q(source, robot), FRAMES[options["model"]])
                np.testing.assert_allclose(np.einsum("nji,nj->ni", jacobian, wrench), estimate, atol=1e-9)
    summary = expected.to_dict() | {"out": None if columns is None else str(tmp_path / "estimate.csv")}
    if options["json"]:
        assert json.loads(printed) == json.loads(json.dumps(summary))
    else:
        assert printed == replace(expected, out=summary["out"]).text() + "\n"
    if options["threshold"]:  # the push is found after it began, within a few time constants
        assert expected.collision is not None and PUSHED_AT <= expected.collision.time <= PUSHED_AT + 3.0 / options["gain"]
    return columns, printed.replace(str(tmp_path), "<dir>")


def _q(source, robot) -> np.ndarray:
    return Trajectory.load(source).for_robot(robot).q


ALONE = [(name, value) for name, values in FACTORS.items() for value in values[1:]]


@pytest.fixture(scope="module")
def default_run(tmp_path_factory):
    return check_run(DEFAULT | {"out": ".csv"}, tmp_path_factory.mktemp("default"))


@pytest.mark.slow
@pytest.mark.parametrize(("option", "value"), ALONE, ids=[f"{name}={value}" for name, value in ALONE])
def test_each_option_alone_changes_what_it_says_and_nothing_else(option, value, tmp_path, default_run):
    options = DEFAULT | {"out": ".csv"} | {option: value}
    columns, printed = check_run(options, tmp_path)
    default_columns, default_printed = default_run
    assert columns is not None and default_columns is not None
    if option in ("frame", "threshold", "json", "out"):  # the estimate is the same
        for name, values in default_columns.items():
            np.testing.assert_array_equal(columns[name], values, err_msg=name)
    if option == "frame":
        assert list(columns) == [*default_columns, *WRENCH_COLUMNS]
        assert printed.replace(next(line for line in printed.splitlines() if "wrench" in line) + "\n", "") == default_printed
    elif option == "threshold":
        assert "collision: at 0.1" in printed and "collision" not in default_printed
    elif option in ("gain", "torque", "gravity", "model", "base", "lock"):  # the estimate changes
        common = set(columns) & set(default_columns) - {"t"}
        assert not common or max(np.abs(columns[n] - default_columns[n]).max() for n in common) > 1e-9
        assert (set(columns) == set(default_columns)) == (option in ("gain", "torque", "gravity"))


@pytest.mark.slow
@pytest.mark.parametrize("run", RUNS, ids=[str(k) for k in range(len(RUNS))])
def test_the_options_crossed_pairwise_estimate_the_push_as_the_library_does(run, tmp_path):
    check_run(run, tmp_path)


def test_what_observe_cannot_do_is_one_line(tmp_path):
    robot = robot_of(DEFAULT)
    source = tmp_path / "pushed.csv"
    recorded_motion(robot, "oblique", source)
    oblique = [*model_arguments(DEFAULT), str(source)]
    refused_in_one_line(["observe", *oblique, "--gain", "0"], "gain")
    refused_in_one_line(["observe", *oblique, "--gain", "50", "--out", str(tmp_path / "e.npz")], "--out", ".csv")
    refused_in_one_line(["observe", *oblique, "--gain", "50", "--threshold", "-1"], "threshold")
    refused_in_one_line(["observe", *oblique, "--gain", "50", "--frame", "base"], "base")
    refused_in_one_line(["observe", *oblique, "--gain", "50", "--floating-base"], "does not fit")  # a fixed robot's file


@pytest.mark.slow
def test_plot_alone_draws_a_png_and_says_so(tmp_path):
    """``--plot`` (matplotlib: left out of the crossed runs) writes a PNG of the estimate
    against the file's applied torques and adds its line, nothing else."""
    robot = robot_of(DEFAULT)
    source = tmp_path / "pushed.csv"
    recorded_motion(robot, "oblique", source)
    plot = tmp_path / "estimate.png"
    argv = ["observe", *model_arguments(DEFAULT), str(source), "--gain", "100"]
    code, printed, error = run_command([*argv, "--plot", str(plot)])
    assert code == 0, error
    width, height = int.from_bytes(plot.read_bytes()[16:20], "big"), int.from_bytes(plot.read_bytes()[20:24], "big")
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and width > 200 and height > 200
    _, without, _ = run_command(argv)
    assert printed == without + f"plot: {plot}\n"
