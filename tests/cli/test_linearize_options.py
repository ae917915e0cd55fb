"""Every option of `robodyn linearize` alone, reading back what it printed, and crossed pairwise.

Each option is first run alone against a base run (a given state: the robots' joints with
Coulomb friction must move to be linearised with their friction): what it changes in the
printed JSON, and nothing else. Then a pairwise-covering set of runs (tests/pairwise.py) is
checked against the library's ``linearization`` of the robot loaded with the same options,
and against central differences of forward dynamics (continuous time) or of one integrator
step written here (discrete time, fixed base), with the files' damping and friction applied
here from the values in the files. The output is read back with ``json`` or by splitting
the text, never with robodyn.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from robodyn import Robot
from robodyn.sim.linearize import actuation_matrix, linearization
from tests.cli.option_runs import FRICTION, GRAVITY, model_arguments, ok, refused, robot_of, shared_flags
from tests.pairwise import pairwise, uncovered_pairs

DT = 0.01
#: Each option's values; the first is the default (the option left out).
FACTORS: dict[str, tuple | list] = {
    "model": ("oblique", "xacro"),
    "state": (None, "given"),
    "tau": (None, "given"),
    "dt": (None, DT),
    "integrator": (None, "semi-implicit-euler", "rk4"),
    "actuated": (None, "ends"),
    "friction": (True, False),
    "gravity": (None, GRAVITY),
    "base": (None, "floating", "fixed"),
    "json": (False, True),
    "precision": (None, 3),
    "inertia": (None, "strict", "no-check"),
    "max_dof": (None, 12),
}
DEFAULT = {name: values[0] for name, values in FACTORS.items()}
#: What the command refuses, each one stderr line (exit 2).
REFUSED = {
    "an integrator without a step": {"integrator": "rk4"},
    "friction at rest (stiction)": {"state": None, "tau": None},
    "digits with JSON": {"json": True, "precision": 3, "state": "given"},
}


def valid(run: dict) -> bool:
    """Whether the command takes the (partial) run: an integrator only with a step, a
    joint with Coulomb friction only moving, digits only for text."""
    if run.get("integrator") and run.get("dt", DT) is None:
        return False
    if run.get("friction", False) and run.get("state", "given") is None:
        return False
    return not (run.get("json") and run.get("precision"))


RUNS = pairwise(FACTORS, valid)


def test_the_runs_cover_every_pair_and_are_few():
    assert uncovered_pairs(RUNS, FACTORS, valid) == []
    assert all(valid(run) for run in RUNS) and len(RUNS) <= 20  # not the 27648 of all combinations


def given(options: dict, robot):
    """q, v and tau as the run gives them (None: left out)."""
    rng = np.random.default_rng(39)
    q = robot.random_configuration(rng)
    v = rng.choice([-1.0, 1.0], robot.nv) * rng.uniform(0.3, 1.0, robot.nv)
    tau = rng.normal(size=robot.nv)
    return (q if options["state"] else None), (v if options["state"] else None), (tau if options["tau"] else None)


def actuated_of(robot) -> list[str]:
    """The first and last joints (not a floating base's root): B's columns with ``--actuated``."""
    joints = [name for name in robot.joint_names if name != "root_joint"]
    return [joints[0], joints[-1]]


def arguments_of(options: dict, robot) -> list[str]:
    q, v, tau = given(options, robot)
    vectors = [
        f"--{name}={','.join(repr(float(x)) for x in value)}"
        for name, value in (("q", q), ("v", v), ("tau", tau))
        if value is not None
    ]
    flags = vectors + shared_flags(options)
    flags += ["--dt", str(options["dt"])] if options["dt"] else []
    flags += ["--integrator", options["integrator"]] if options["integrator"] else []
    flags += ["--actuated", ",".join(actuated_of(robot))] if options["actuated"] else []
    flags += [] if options["friction"] else ["--no-joint-friction"]
    flags += ["--precision", str(options["precision"])] if options["precision"] else []
    return ["linearize", *model_arguments(options["model"]), *flags]


def read_text(text: str) -> dict:
    """A and B of the printed text, split by hand: rows ``name [ numbers ]`` under ``A:`` and ``B ...:``."""
    matrices: dict[str, list] = {}
    current = None
    for line in text.splitlines():
        if line in ("A:",) or line.startswith("B (columns"):
            current = matrices.setdefault(line[0], [])
        elif current is not None and "[" in line:
            current.append([float(x) for x in line.split("[", 2)[-1].rstrip(" ]").split()])
    return {name: np.array(rows) for name, rows in matrices.items()}


def printed(options: dict) -> tuple[dict, Robot]:
    """The run's A and B (and the whole JSON document, if any) read back, and the robot."""
    robot = robot_of(options)
    out = ok(arguments_of(options, robot))
    if options["json"]:
        document = json.loads(out)
        return {"A": np.array(document["A"]), "B": np.array(document["B"]), "document": document}, robot
    return read_text(out) | {"text": out}, robot


def forces(options: dict, robot, v: np.ndarray) -> np.ndarray:
    """The joints' damping and Coulomb friction torques −b v − f sign(v) (zero without friction)."""
    torque = np.zeros(robot.nv)
    for joint, (b, f) in FRICTION[options["model"]].items() if options["friction"] else ():
        k = [dof.name for dof in robot.dofs].index(joint)
        torque[k] = -b * v[k] - f * np.sign(v[k])
    return torque


def step(options: dict, robot, q, v, torque):
    """One step of ``dt`` of a fixed base, written here: semi-implicit Euler or classic RK4."""

    def accel(q, v):
        return robot.forward_dynamics(q, v, torque + forces(options, robot, v))

    if options["integrator"] == "semi-implicit-euler":
        v_next = v + DT * accel(q, v)
        return np.concatenate([q + DT * v_next, v_next])
    k1q, k1v = v, accel(q, v)
    k2q, k2v = v + DT / 2 * k1v, accel(q + DT / 2 * k1q, v + DT / 2 * k1v)
    k3q, k3v = v + DT / 2 * k2v, accel(q + DT / 2 * k2q, v + DT / 2 * k2v)
    k4q, k4v = v + DT * k3v, accel(q + DT * k3q, v + DT * k3v)
    return np.concatenate([q + DT / 6 * (k1q + 2 * k2q + 2 * k3q + k4q), v + DT / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)])


def central_differences(options: dict, robot, q, v, tau, selection) -> tuple[np.ndarray, np.ndarray]:
    """∂f/∂x and ∂f/∂u by central differences (q perturbed along robot.integrate):
    f = (v, q̈) in continuous time (the q̇ rows left as zeros), one step of fixed base otherwise."""
    nv, h = robot.nv, 1e-6

    def f(dq, dv, du):
        x_q, x_v, torque = robot.integrate(q, dq), v + dv, tau + selection @ du
        if options["dt"]:
            return step(options, robot, x_q, x_v, torque)
        return np.concatenate([np.zeros(nv), robot.forward_dynamics(x_q, x_v, torque + forces(options, robot, x_v))])

    columns = []
    for k in range(2 * nv + selection.shape[1]):
        e = np.zeros(2 * nv + selection.shape[1])
        e[k] = h
        plus, minus = f(e[:nv], e[nv : 2 * nv], e[2 * nv :]), f(-e[:nv], -e[nv : 2 * nv], -e[2 * nv :])
        columns.append((plus - minus) / (2 * h))
    jacobian = np.array(columns).T
    return jacobian[:, : 2 * nv], jacobian[:, 2 * nv :]


def check_run(options: dict) -> dict:
    """The run's A and B are the library's for the same options, and central differences'."""
    matrices, robot = printed(options)
    q, v, tau = given(options, robot)
    q = robot.neutral_configuration() if q is None else q
    v = np.zeros(robot.nv) if v is None else v
    selection = actuation_matrix(robot, actuated_of(robot) if options["actuated"] else None)
    expected = linearization(
        robot, q, v, tau, dt=options["dt"], integrator=options["integrator"] or "rk4", actuation=selection,
        joint_friction=options["friction"],
    )  # fmt: skip
    digits = 1e-12 if options["json"] else 10.0 ** -((options["precision"] or 6) - 1)
    for name, value in (("A", expected.A), ("B", expected.B)):
        assert matrices[name].shape == value.shape, name
        np.testing.assert_allclose(matrices[name], value, rtol=digits, atol=digits * np.abs(value).max(), err_msg=name)
    if options["dt"] and robot.floating_base:
        return matrices
    A, B = central_differences(options, robot, q, v, expected.tau, selection)
    rows = slice(None) if options["dt"] else slice(robot.nv, None)
    np.testing.assert_allclose(expected.A[rows], A[rows], atol=1e-6 * max(1.0, np.abs(A).max()))
    np.testing.assert_allclose(expected.B[rows], B[rows], atol=1e-6 * max(1.0, np.abs(B).max()))
    if not options["dt"]:
        assert np.array_equal(expected.A[: robot.nv, robot.nv :], np.eye(robot.nv)) and not expected.B[: robot.nv].any()
    return matrices


#: Each option alone against the base run: the JSON keys it changes (none: it changes nothing).
ALONE: dict[tuple[str, object], set[str]] = {
    ("model", "xacro"): {"robot", "state", "inputs", "units", "q", "v", "tau", "A", "B"},
    ("state", None): {"q", "v", "tau", "A", "B"},  # the neutral state at rest: both without friction
    ("tau", "given"): {"tau", "A"},
    ("dt", DT): {"time", "dt", "integrator", "units", "A", "B"},
    ("actuated", "ends"): {"inputs", "units", "B"},
    ("friction", False): {"A"},
    ("gravity", GRAVITY): {"tau", "A"},
    ("base", "floating"): {"state", "inputs", "units", "q", "v", "tau", "A", "B"},
    ("base", "fixed"): set(),
    ("inertia", "strict"): set(),
    ("inertia", "no-check"): set(),
    ("max_dof", 12): set(),
}
BASE = DEFAULT | {"state": "given", "json": True}


@pytest.mark.parametrize(("option", "value"), list(ALONE), ids=[f"{name}={value}" for name, value in ALONE])
def test_each_option_alone_changes_what_it_says_and_nothing_else(option, value):
    options = BASE | {option: value} | ({"friction": False} if option == "state" else {})
    base = printed(BASE | ({"friction": False} if option == "state" else {}))[0]["document"]
    document = check_run(options)["document"]
    changed = {key for key in document if document[key] != base[key]}
    assert changed == ALONE[(option, value)]


@pytest.mark.parametrize("integrator", ["semi-implicit-euler", "rk4"])
def test_the_integrator_alone_is_the_step_it_names(integrator):
    """With --dt: rk4 given is the default; semi-implicit Euler another step (its A and B)."""
    options = BASE | {"dt": DT}
    base = check_run(options)["document"]
    document = check_run(options | {"integrator": integrator})["document"]
    changed = {key for key in document if document[key] != base[key]}
    assert changed == (set() if integrator == "rk4" else {"integrator", "A", "B"})


def test_digits_alone_round_the_text_and_change_nothing_else():
    options = DEFAULT | {"state": "given"}
    full, short = check_run(options), check_run(options | {"precision": 3})
    assert full["text"] != short["text"]
    for name in ("A", "B"):
        np.testing.assert_allclose(short[name], full[name], rtol=1e-2, atol=1e-2 * np.abs(full[name]).max())


@pytest.mark.parametrize("reason", list(REFUSED))
def test_each_refused_combination_is_one_stderr_line(reason):
    options = DEFAULT | {"state": "given"} | REFUSED[reason]
    assert not valid(options)
    refused(arguments_of(options, robot_of(options)))


@pytest.mark.slow
@pytest.mark.parametrize("run", RUNS, ids=[str(k) for k in range(len(RUNS))])
def test_the_options_crossed_pairwise_print_the_librarys_and_the_differences_matrices(run):
    check_run(run)
