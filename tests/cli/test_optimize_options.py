"""Every option of `robodyn optimize` alone, reading back what it wrote, and crossed pairwise.

Each option is run alone against the run with no option (what it changes, and nothing
else), then a pairwise-covering set of runs is checked: the file read back without robodyn
holds a motion of the robot loaded with the same options (``RNEA(q, v, a) = tau − b v`` with
that robot's gravity, locks and damping, and not with the other value's: the negative
control), from start to goal at rest, within the position, velocity and effort limits, with
no torque on a joint left out of ``--actuated``; a minimum-time motion ends on a limit that
binds. The xacro arm's crossed runs are compared with :func:`robodyn.optimize.point_to_point`
called with the same options (the oblique robot's cost more CPU).

The robots: the oblique test robot without its Coulomb friction (which the optimizer
refuses; its damping stays) and the xacro test arm (a mimic joint, ``--xacro-arg``,
``--package``), which keeps its Coulomb friction and so plans only with
``--no-joint-friction``. Five shooting intervals keep a run under a second.
"""

from __future__ import annotations

import numpy as np
import pytest

from robodyn.optimize import point_to_point
from robodyn.sim.limits import JointLimits
from tests.cli.model_options import GRAVITY, OBLIQUE, model_arguments, refused_in_one_line, robot_of, run_command
from tests.differential.pairs import expected_header, written_columns
from tests.pairwise import pairwise, uncovered_pairs

pytestmark = pytest.mark.slow  # IPOPT: about half a second a run

INTERVALS, DURATION = 5, 1.0
#: The goal of each joint (the start: all zero); the last joint's goal is its start, so it
#: can be left out of ``--actuated`` (passive) and still arrive.
GOALS = {
    "oblique": {"j_yaw": 0.4, "j_twist": 0.25, "j_extend": 0.12, "j_tool": 0.0},
    "xacro": {"r_shoulder": 0.5, "r_slide": 0.1, "r_wrist_roll": 0.0},
}

#: Each option's values; the first is the default (the option left out), but for
#: ``joint_friction``: the reference run is the cheap xacro arm's, which plans only rigid
#: (``--no-joint-friction``, its Coulomb friction); True leaves the flag out (the oblique robot).
FACTORS: dict[str, tuple | list] = {
    "model": ("xacro", "oblique"),
    "cost": ("effort", "time"),
    "actuated": (None, "all but the last"),
    "joint_friction": (False, True),
    "gravity": (None, GRAVITY),
    "out": (".csv", ".npz"),
}
DEFAULT = {name: values[0] for name, values in FACTORS.items()}


def valid(run: dict) -> bool:
    """The xacro arm's shoulder has Coulomb friction: it plans only rigid (``--no-joint-friction``)."""
    return not (run.get("model") == "xacro" and run.get("joint_friction") is True)


def alone(option: str, value) -> dict:
    """The reference run with one option changed (planning with friction: the oblique robot's)."""
    return DEFAULT | {option: value} | ({"model": "oblique"} if option == "joint_friction" else {})


RUNS = pairwise(FACTORS, valid)
#: The runs beside the default one (which the options alone are compared with).
CROSSED = [run for run in RUNS if run != DEFAULT]


@pytest.fixture(scope="module")
def viscous_oblique(tmp_path_factory) -> str:
    """The oblique robot with its Coulomb friction removed (its damping kept)."""
    text = OBLIQUE.read_text()
    assert text.count('friction="0.05"') == 1
    path = tmp_path_factory.mktemp("robots") / "oblique_viscous.urdf"
    path.write_text(text.replace('friction="0.05"', 'friction="0"'))
    return str(path)


def _request(options: dict, robot) -> tuple[np.ndarray, np.ndarray, dict]:
    goal = np.array([GOALS[options["model"]][name] for name in robot.joint_names])
    keywords = {"intervals": INTERVALS, "cost": options["cost"], "joint_friction": options["joint_friction"]}
    keywords["actuated"] = list(robot.joint_names[:-1]) if options["actuated"] else None
    return np.zeros(robot.nq), goal, keywords


def run_cli(options: dict, tmp_path, oblique: str):
    """Run the command; the robot of its options, its request and what it wrote and printed."""
    robot = robot_of(options, oblique)
    start, goal, keywords = _request(options, robot)
    out = tmp_path / f"motion{options['out']}"
    argv = ["optimize", *model_arguments(options, oblique), "--start", ",".join(map(str, start))]
    argv += ["--goal", ",".join(map(str, goal)), "--duration", str(DURATION), "--intervals", str(INTERVALS)]
    argv += ["--out", str(out)] + (["--cost", "time"] if options["cost"] == "time" else [])
    argv += ["--actuated", ",".join(keywords["actuated"])] if options["actuated"] else []
    argv += [] if options["joint_friction"] else ["--no-joint-friction"]
    code, printed, error = run_command(argv)
    assert code == 0, error
    return robot, (start, goal, keywords), written_columns(out), printed


def _column(columns: dict, kind: str, names) -> np.ndarray:
    return np.column_stack([columns[f"{kind}[{name}]"] for name in names])


def check_run(options: dict, tmp_path, oblique: str) -> dict:
    """The written motion is one of the options' robot, within its limits; returns its columns."""
    robot, (start, goal, keywords), columns, printed = run_cli(options, tmp_path, oblique)
    names = list(robot.joint_names)
    assert sorted(columns) == sorted(expected_header(robot))
    t, (q, v, a, tau) = columns["t"], (_column(columns, kind, names) for kind in ["q", "v", "a", "tau"])
    np.testing.assert_allclose(t, np.linspace(0.0, t[-1], INTERVALS + 1), rtol=1e-12)
    assert t[-1] == DURATION if options["cost"] == "effort" else t[-1] < DURATION
    np.testing.assert_allclose(q[[0, -1]], [start, goal], atol=1e-6)
    np.testing.assert_allclose(v[[0, -1]], 0.0, atol=1e-6)
    # The dynamics of this robot (gravity, locks), damped unless --no-joint-friction.
    damping = robot.joint_damping if options["joint_friction"] else np.zeros(robot.nv)
    scale = 1e-9 * max(1.0, np.abs(tau).max())
    np.testing.assert_allclose(robot.inverse_dynamics(q, v, a), tau - v * damping, atol=scale)
    if robot.joint_damping.any():  # negative control: the other friction setting does not fit
        assert np.abs(v * robot.joint_damping).max() > 1e-4
    other = robot_of(options | {"gravity": None if options["gravity"] else GRAVITY}, oblique)
    assert np.abs(other.inverse_dynamics(q, v, a) - (tau - v * damping)).max() > 1e-3  # the gravity is seen
    # The limits hold at every sample; a minimum-time motion ends on one of them.
    limits = JointLimits(robot)
    assert np.all(q >= limits.lower - 1e-9) and np.all(q <= limits.upper + 1e-9)
    used = np.concatenate([np.abs(v).max(axis=0) / limits.velocity, np.abs(tau).max(axis=0) / limits.effort])
    assert used.max() <= 1.0 + 1e-7
    if options["cost"] == "time":
        assert used.max() >= 1.0 - 1e-5
    passive = [k for k, name in enumerate(names) if keywords["actuated"] is not None and name not in keywords["actuated"]]
    assert np.all(tau[:, passive] == 0.0) and (not passive or np.abs(tau).max() > 0.1)
    # What it printed: the cost asked for, the duration and each joint's peak effort.
    assert printed.startswith(f"Solve_Succeeded: {options['cost']} cost") and f"duration {t[-1]:.6g} s" in printed
    for name, peak in zip(names, np.abs(tau).max(axis=0), strict=True):
        assert f"{name} {peak:.4g} " in printed
    return columns


def test_the_runs_cover_every_valid_pair_and_are_few():
    assert uncovered_pairs(RUNS, FACTORS, valid) == []
    assert len(RUNS) <= 8 and all(valid(run) for run in RUNS)


ALONE = [(name, value) for name, values in FACTORS.items() for value in values[1:]]


@pytest.fixture(scope="module")
def default_run(tmp_path_factory, viscous_oblique) -> dict:
    return check_run(DEFAULT, tmp_path_factory.mktemp("default"), viscous_oblique)


@pytest.mark.parametrize(("option", "value"), ALONE, ids=[f"{name}={value}" for name, value in ALONE])
def test_each_option_alone_changes_what_it_says_and_nothing_else(option, value, tmp_path, viscous_oblique, default_run):
    columns = check_run(alone(option, value), tmp_path, viscous_oblique)
    if option == "out":  # the same motion in another format
        for name, values in default_run.items():
            np.testing.assert_array_equal(columns[name], values, err_msg=name)
    elif option not in ("model", "joint_friction"):  # the option changes the motion
        common = sorted(set(columns) & set(default_run) - {"t"})
        assert max(np.abs(columns[name] - default_run[name]).max() for name in common) > 1e-3


@pytest.mark.parametrize("run", CROSSED, ids=[str(k) for k in range(len(CROSSED))])
def test_the_options_crossed_pairwise_write_a_motion_of_the_same_robot(run, tmp_path, viscous_oblique):
    columns = check_run(run, tmp_path, viscous_oblique)
    if run["model"] == "xacro":  # the library with the same options writes the same motion
        robot = robot_of(run)
        start, goal, keywords = _request(run, robot)
        motion = point_to_point(robot, start, goal, DURATION, **keywords).trajectory
        for kind in ("q", "v", "a", "tau"):
            np.testing.assert_allclose(_column(columns, kind, robot.joint_names), getattr(motion, kind), rtol=1e-9, atol=1e-9)


def test_what_the_optimizer_cannot_plan_is_one_line(tmp_path):
    common = ["--start", "0,0,0", "--goal", "0.5,0.1,0", "--duration", "1", "--intervals", "5", "--out", str(tmp_path / "m.csv")]
    xacro = model_arguments({"model": "xacro"})
    refused_in_one_line(["optimize", *xacro, *common], "--no-joint-friction", "r_shoulder")
    refused_in_one_line(["optimize", *xacro, *common, "--no-joint-friction", "--floating-base"], "fixed-base")
    refused_in_one_line(["optimize", *xacro, *common, "--no-joint-friction", "--actuated", "r_elbow"], "r_elbow")
    assert not (tmp_path / "m.csv").exists()
