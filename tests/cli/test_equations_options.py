"""Every option of `robodyn equations` at one state (tau, M, C, G) alone, read back, and crossed pairwise.

Each option alone against the run with none: what it changes in the printed JSON and
nothing else. Then a pairwise-covering set of runs (tests/pairwise.py), each read back
(``json``, or the text split by hand) and compared with the Robot loaded with the same
options: ``inverse_dynamics``, ``mass_matrix``, ``coriolis_matrix`` and ``gravity`` at the
state given. The options this output does not read (the symbolic ones) are refused, one
line each (tests/cli/test_equations_symbolic_options.py has the symbolic equations).
"""

from __future__ import annotations

import contextlib
import json
from pathlib import Path

import numpy as np
import pytest

from tests.cli.option_runs import GRAVITY, model_arguments, ok, refused, robot_of, run, shared_flags
from tests.pairwise import pairwise, uncovered_pairs

#: A joint of each robot to lock (the xacro arm's names carry its prefix argument).
LOCKED = {"oblique": {"j_twist": 0.3}, "xacro": {"r_slide": 0.05}}
#: Each option's values; the first is the default (the option left out).
FACTORS: dict[str, tuple | list] = {
    "model": ("oblique", "xacro"),
    "state": (None, "given"),
    "gravity": (None, GRAVITY),
    "base": (None, "floating", "fixed"),
    "lock": (None, "one"),
    "json": (False, True),
    "precision": (None, 3),
    "out": (None, "file"),
    "inertia": (None, "strict", "no-check"),
    "max_dof": (None, 12),
}
DEFAULT = {name: values[0] for name, values in FACTORS.items()}


def valid(run: dict) -> bool:
    """Digits only for text (JSON carries every digit)."""
    return not (run.get("json") and run.get("precision"))


RUNS = pairwise(FACTORS, valid)


def test_the_runs_cover_every_pair_and_are_few():
    assert uncovered_pairs(RUNS, FACTORS, valid) == [] and all(valid(run) for run in RUNS)
    assert len(RUNS) <= 12  # not the 2304 of all combinations


def library_options(options: dict) -> dict:
    return options | {"lock": LOCKED[options["model"]] if options["lock"] else None}


def state_of(options: dict, robot) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The run's q, v, a: random (a floating base's tilted), or the command's defaults."""
    if not options["state"]:
        return robot.default_configuration(), np.zeros(robot.nv), np.zeros(robot.nv)
    rng = np.random.default_rng(39)
    q = robot.random_configuration(rng)
    if robot.floating_base:
        q = robot.floating_configuration(rng.uniform(-1, 1, 3), rng.uniform(-np.pi, np.pi, 3), q[7:])
    return q, rng.normal(size=robot.nv), rng.normal(size=robot.nv)


def arguments_of(options: dict, robot, out: Path | None) -> list[str]:
    flags = shared_flags(library_options(options))
    if options["state"]:
        flags += [
            f"--{name}={','.join(repr(float(x)) for x in value)}"
            for name, value in zip("qva", state_of(options, robot), strict=True)
        ]
    flags += ["--precision", str(options["precision"])] if options["precision"] else []
    flags += ["--out", str(out)] if out else []
    return ["equations", *model_arguments(options["model"]), *flags]


def read_text(text: str, nv: int) -> dict:
    """tau, G (the last two numbers of each degree of freedom's row) and the M and C blocks, split by hand."""
    lines = text.splitlines()
    start = next(k for k, line in enumerate(lines) if line.startswith("joint ")) + 1

    def numbers(line: str) -> list[float]:
        found = []
        for token in line.replace("[", " ").replace("]", " ").split():
            with contextlib.suppress(ValueError):
                found.append(float(token))
        return found

    rows = [numbers(line)[-2:] for line in lines[start : start + nv]]
    blocks = [numbers(line) for line in lines if line.startswith("  [")]
    return {
        "joint_names": [line.split()[0] for line in lines[start : start + nv]],
        "tau": np.array(rows)[:, 0], "G": np.array(rows)[:, 1],
        "M": np.array(blocks[:nv]), "C": np.array(blocks[nv : 2 * nv]),
    }  # fmt: skip


def check_run(options: dict, folder: Path) -> dict:
    """Run the command; what it printed (or wrote) is the Robot's tau, M, C, G at the state."""
    robot = robot_of(library_options(options))
    out = folder / ("terms.json" if options["json"] else "terms.txt") if options["out"] else None
    code, printed, err = run(arguments_of(options, robot, out))
    assert code == 0, err
    if out is not None:
        assert printed == "" and f"wrote {out}" in err
        printed = out.read_text()
    q, v, a = state_of(options, robot)
    expected = {
        "tau": robot.inverse_dynamics(q, v, a), "M": robot.mass_matrix(q), "C": robot.coriolis_matrix(q, v),
        "G": robot.gravity(q),
    }  # fmt: skip
    if options["json"]:
        document = json.loads(printed)
        assert document["joint_names"] == list(robot.joint_names)
        np.testing.assert_allclose(document["q"], q, rtol=1e-15)
        digits = 1e-12
    else:
        document = read_text(printed, robot.nv)
        assert document["joint_names"] == [dof.name for dof in robot.dofs]
        digits = 10.0 ** (1 - (options["precision"] or 6))
    for name, value in expected.items():
        scale = max(1.0, np.abs(value).max())
        np.testing.assert_allclose(np.array(document[name]), value, rtol=digits, atol=digits * scale, err_msg=name)
    return document


#: Each option alone against the run with none: the JSON keys it changes.
EVERYTHING = {"joint_names", "units", "q", "v", "a", "tau", "M", "C", "G"}
ALONE: dict[tuple[str, object], set[str]] = {
    ("model", "xacro"): EVERYTHING | {"robot"},
    ("state", "given"): {"q", "v", "a", "tau", "M", "C", "G"},
    ("gravity", GRAVITY): {"tau", "G"},
    ("base", "floating"): EVERYTHING,
    ("base", "fixed"): set(),
    ("lock", "one"): EVERYTHING,
    ("out", "file"): set(),
    ("inertia", "strict"): set(),
    ("inertia", "no-check"): set(),
    ("max_dof", 12): set(),
}
BASE = DEFAULT | {"json": True}


@pytest.mark.parametrize(("option", "value"), list(ALONE), ids=[f"{name}={value}" for name, value in ALONE])
def test_each_option_alone_changes_what_it_says_and_nothing_else(option, value, tmp_path):
    base = check_run(BASE, tmp_path)
    document = check_run(BASE | {option: value}, tmp_path)
    assert {key for key in document if document[key] != base[key]} == ALONE[(option, value)]


def test_digits_alone_round_the_text_and_nothing_else(tmp_path):
    options = DEFAULT | {"state": "given"}
    full, short = check_run(options, tmp_path), check_run(options | {"precision": 3}, tmp_path)
    assert not np.array_equal(full["M"], short["M"])  # negative control: the digits are dropped
    np.testing.assert_allclose(short["M"], full["M"], rtol=1e-2)


#: What the numbers at one state refuse: the symbolic options, digits with JSON; one stderr line each.
REFUSED = [
    ["--precision", "3", "--json"], ["--format", "python"], ["--keep-params"], ["--form", "compact"],
    ["--kinematics", "end_effector"], ["--christoffel"], ["--constraints", "loop.yaml"],
]  # fmt: skip


@pytest.mark.parametrize("flags", REFUSED, ids=[flags[0] for flags in REFUSED])
def test_each_option_the_numbers_do_not_read_is_one_stderr_line(flags):
    error = refused(["equations", *model_arguments("oblique"), *flags])
    assert flags[0] in error


#: Options the other outputs do not read (each refused before any derivation): (the output's flags, the option).
UNREAD = [
    (["--derivation"], ["--floating-base"]), (["--lecture"], ["--gravity=0,0,-1.62"]), (["--base-parameters"], ["--q=0.1,0.2"]),
    (["--symbolic", "--kinematics", "link2"], ["--christoffel"]), (["--symbolic", "--kinematics", "link2"], ["--keep-params"]),
    (["--symbolic"], ["--json"]), (["--symbolic"], ["--no-check-inertia"]), (["--symbolic", "--format", "c"], ["--precision=3"]),
    (["--format", "casadi"], ["--precision=3"]), (["--lecture"], ["--derivation"]),
]  # fmt: skip


@pytest.mark.parametrize(("output", "option"), UNREAD, ids=[" ".join(o + f) for o, f in UNREAD])
def test_an_option_another_output_does_not_read_is_one_stderr_line_naming_it(output, option):
    error = refused(["equations", "rp_arm", *output, *option])
    assert option[0].split("=")[0] in error and "left out with" in error


def test_the_written_file_is_what_the_terminal_shows(tmp_path):
    shown = ok(["equations", *model_arguments("xacro"), "--json"])
    check_run(BASE | {"model": "xacro", "out": "file"}, tmp_path)
    assert (tmp_path / "terms.json").read_text() == shown


@pytest.mark.slow
@pytest.mark.parametrize("options", RUNS, ids=[str(k) for k in range(len(RUNS))])
def test_the_options_crossed_pairwise_print_the_robots_terms(options, tmp_path):
    check_run(options, tmp_path)
