"""Every option of `robodyn simulate` alone, reading back what it wrote (issue 39).

Each option's value (tests/cli/simulate_options.py's ``FACTORS``) is run on its own (with the
partner it needs, e.g. ``--kp`` with ``--controller pd``), its file read back without robodyn
and compared column by column with the Python API given the same options; then against the
run without it: an option that changes the motion must change it (the effect visible, each
in the way it says: the push from its time on, the held torque, the start, the step), one
that only adds columns must add exactly those and leave the motion bit for bit. A limit is
also run where it binds. What the command refuses is one stderr line naming what conflicts.
The crossed pairs: tests/cli/test_simulate_options_pairwise.py.
"""

from __future__ import annotations

import contextlib
import io
import json
from collections.abc import Callable

import numpy as np
import pytest

from robodyn.cli.app import main
from tests.cli import simulate_options
from tests.cli.simulate_options import (
    DEFAULT,
    FACTORS,
    MODELS,
    PUSH_TIME,
    REFUSED,
    arguments_of,
    check_run,
    library_run,
    start_of,
    valid,
)

#: What an option needs beside it to be run (the command refuses it alone) or to show its effect.
PARTNERS: dict[tuple, dict] = {
    ("target", "given"): {"controller": "pd"},
    ("gains", "given"): {"controller": "pd", "target": "given"},
    ("control_period", 0.002): {"controller": "pd", "target": "given"},
    ("controller", "computed-torque"): {"target": "given"},
    ("ground", "given"): {"q0": "given"},  # the end effector touches it there
    ("friction", 0.0): {"ground": "given", "q0": "given"},
}
#: Options that leave the motion as it is (a file's columns added at most); every other one changes it.
SAME_MOTION = {"inertia", "max_dof", "engine", "limits", "observer_gain", "out", "json", ("base", "fixed"), ("integrator", "rk4")}
ALONE = [(name, value) for name, values in FACTORS.items() for value in values[1:]]


def _partners(name: str, value) -> dict:
    return PARTNERS.get((name, value), {})


@pytest.fixture(scope="module")
def baselines(tmp_path_factory) -> Callable[[dict], tuple]:
    """The run without the option, of a set of partners: (written, trajectory), each run once."""
    made: dict = {}

    def baseline(partners: dict):
        key = tuple(sorted(partners.items()))
        if key not in made:
            made[key] = check_run(DEFAULT | partners | {"out": ".csv"}, tmp_path_factory.mktemp("base"))
        return made[key]

    return baseline


def _motion(written) -> dict:
    return {name: values for name, values in written.columns.items() if name.split("[")[0] in ("t", "q", "v", "a", "tau")}


@pytest.mark.parametrize(("option", "value"), ALONE, ids=[f"{name}={value}" for name, value in ALONE])
def test_each_option_alone_writes_the_librarys_run_and_changes_only_what_it_says(option, value, baselines, tmp_path):
    partners = _partners(option, value)
    run = DEFAULT | partners | {"out": ".csv"} | {option: value}
    written, trajectory = check_run(run, tmp_path)  # the file and summary are the Python API's run with the same options
    base, _ = baselines(partners if valid(DEFAULT | partners) else {})  # computed torque's target: passive refuses it
    if option == "json":
        assert json.loads(written.printed)["controller"] == run["controller"]
    if option in SAME_MOTION or (option, value) in SAME_MOTION:
        assert {name: list(v) for name, v in _motion(written).items()} == {name: list(v) for name, v in _motion(base).items()}
        added = set(written.columns) - set(base.columns)
        assert {name.split("[")[0] for name in added} == ({"tau_ext"} if option == "observer_gain" else set())
        return
    moved = _motion(written).keys() != _motion(base).keys() or any(
        values.shape != base.columns[name].shape or np.abs(values - base.columns[name]).max() > 1e-9
        for name, values in _motion(written).items()
    )
    assert moved, f"{option}={value} left the motion as it was"
    _its_own_effect(option, value, run, written, base, trajectory)


def _its_own_effect(option: str, value, run: dict, written, base, trajectory) -> None:
    """What the option does, read back from the file."""
    columns, frame = written.columns, MODELS[run["model"]].frame
    if option == "q0":
        np.testing.assert_array_equal([columns[f"q[{n}]"][0] for n in ("j_yaw", "j_twist", "j_extend", "j_tool")], start_of(run))
    elif option == "dt":
        np.testing.assert_allclose(np.diff(columns["t"]), value, rtol=1e-9)
    elif option == "push":  # nothing before its time; from then on, the torque it applies
        before = columns["t"] < PUSH_TIME - 1e-12
        assert np.abs(columns["tau_env[j_yaw]"][before]).max() == 0 and np.abs(columns["tau_env[j_yaw]"][~before]).min() > 0
        assert np.array_equal(columns["q[j_yaw]"][before], base.columns["q[j_yaw]"][before])
    elif option == "control_period":  # the torque held two steps of 1 ms
        tau = columns["tau[j_yaw]"]
        assert np.array_equal(tau[0:-1:2], tau[1::2]) and np.abs(np.diff(tau[:-1:2])).min() > 0
    elif option == "ground":  # the end effector pressed on it: a normal force
        assert columns[f"contact[{frame}]"][0] == 1 and columns[f"f[{frame}].z"].max() > 0
        assert np.abs(columns[f"f[{frame}].x"]).max() > 0  # friction holds it sideways (mu 1)
    elif option == "friction":  # mu 0: no tangential force
        assert columns[f"f[{frame}].z"].max() > 0 and np.abs(columns[f"f[{frame}].x"]).max() == 0
        assert np.abs(columns[f"f[{frame}].y"]).max() == 0 and np.abs(base.columns[f"f[{frame}].y"]).max() > 0
    elif option == "base":
        assert "q[base.qw]" in columns and columns["q[base.qw]"][0] == 1.0


def test_the_run_with_no_option_writes_no_file_and_says_so(tmp_path):
    check_run(dict(DEFAULT), tmp_path)
    assert list(tmp_path.iterdir()) == []


def _summary(argv: list[str]) -> dict:
    stdout = io.StringIO()
    with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(io.StringIO()):
        assert main(argv) == 0
    return json.loads(stdout.getvalue())


def test_each_limits_mode_where_the_effort_limits_bind(tmp_path):
    """A stiff PD to a far target asks for far more than the file's effort limits: enforce
    saturates at them exactly, warn reports every joint beyond, ignore reports none."""
    run = DEFAULT | {"controller": "pd", "out": ".csv", "json": True}
    argv = [*arguments_of(run, None), "--target=1.0,-1.0,0.2,1.0", "--kp=2000,2000,5000,1", "--kd=20,20,20,0.05"]
    runs = {
        mode: _summary([*argv, "--limits", mode, "--out", str(tmp_path / f"{mode}.csv")])
        for mode in ("warn", "enforce", "ignore")
    }
    effort = MODELS["oblique"].effort
    peak = {mode: dict(zip(summary["dof_names"], summary["peak_abs_torque"], strict=True)) for mode, summary in runs.items()}
    assert all(peak["warn"][joint] > limit for joint, limit in effort.items())
    assert {joint: peak["enforce"][joint] for joint in effort} == effort  # on the limit, not beyond
    assert {v["joint"] for v in runs["warn"]["limit_violations"] if v["quantity"] == "effort"} == set(effort)
    assert runs["enforce"]["limit_violations"] == [] or all(
        v["quantity"] != "effort" for v in runs["enforce"]["limit_violations"]
    )
    assert runs["ignore"]["limit_violations"] == [] and runs["ignore"]["final_q"] == runs["warn"]["final_q"]
    assert runs["enforce"]["final_q"] != runs["warn"]["final_q"]


def test_the_comparison_sees_a_lost_xacro_argument(tmp_path, monkeypatch):
    """Negative control of the comparison: the library's run of the arm at its default upper
    mass differs from the command's with ``--xacro-arg upper_mass:=2.1``."""
    run = DEFAULT | {"model": "xacro", "out": ".csv"}
    _, trajectory = check_run(run, tmp_path)
    monkeypatch.setattr(simulate_options, "XACRO_ARGS", {"prefix": "r_"})
    _, other, _ = library_run(run)
    assert np.abs(other.q - trajectory.q).max() > 1e-9


@pytest.mark.parametrize(("pair", "named"), REFUSED, ids=["+".join(f"{k}={v}" for k, v in pair.items()) for pair, _ in REFUSED])
def test_each_refused_combination_is_one_stderr_line_naming_what_conflicts(pair, named, tmp_path, capsys):
    run = DEFAULT | {"out": ".csv", "controller": "pd"} | pair  # pd: a controller for --control-period
    assert main(arguments_of(run, tmp_path / f"run{run['out']}")) == 2
    error = capsys.readouterr().err
    assert error.count("\n") == 1 and error.startswith("robodyn: error: ") and "Traceback" not in error
    assert all(word in error for word in named), error
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("friction", [[], ["--no-joint-friction"]], ids=["joint-friction", "rigid"])
def test_a_run_that_diverges_under_a_held_controller_says_so_not_that_v_is_not_finite(friction, capsys):
    """Found crossing ``--control-period`` with a floating base: a divergence inside a step of a
    held controller reached the base's integration as ``v must be finite`` (an input error
    naming a parameter nobody gave); the joints' stick-slip event search bisected a blown-up
    margin into a NaN step. Now, as without ``--control-period``: the simulation diverged, when, which joint."""
    argv = arguments_of(DEFAULT | {"model": "xacro", "base": "floating", "controller": "computed-torque"}, None)
    held = [*argv, "--target=0.1,0.03,0.2", "--control-period", "0.002", "--engine", "pinocchio", *friction]
    assert main([*held, "--kp", "4e6", "--kd", "4e3"] if friction else held) == 2
    error = capsys.readouterr().err.strip().splitlines()[-1]
    assert error.startswith("robodyn: error: simulation diverged at t = ") and "is no longer finite" in error, error
