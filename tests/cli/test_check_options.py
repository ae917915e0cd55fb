"""Every option of `robodyn check` alone, reading back what it printed, and crossed pairwise.

Each option alone against the run with none: what it changes in the printed report and
nothing else. Then a pairwise-covering set of runs (tests/pairwise.py), each compared with
``check_robot`` of the Robot loaded with the same options, and with what must happen: a
reference heavier than the model, or a tolerance below round-off, fails (exit 1), anything
else passes — the reference given the model's gravity, base, xacro arguments and packages
(a reference built without them would not match). Output read back with ``json`` or by
splitting the text.
"""

from __future__ import annotations

import functools
import json
from pathlib import Path

import numpy as np
import pytest

import robodyn
from robodyn.constraints.files import read_constraints
from robodyn.verify.check import check_robot
from tests.cli.option_runs import (
    GRAVITY,
    OBLIQUE,
    XACRO,
    load_options,
    model_arguments,
    refused,
    robot_of,
    run,
    shared_flags,
    source_of,
)
from tests.pairwise import pairwise, uncovered_pairs

TIGHT = 1e-16  # below round-off: some quantity fails
#: Each option's values; the first is the default (the option left out).
FACTORS: dict[str, tuple | list] = {
    "model": ("oblique", "xacro"),
    "samples": (4, 7),  # always given: the default 100 states would make each run seconds
    "seed": (None, 5),
    "tolerance": (None, 1e-3, TIGHT),
    "reference": (None, "same", "heavier"),
    "constraints": (None, "anchor"),
    "gravity": (None, GRAVITY),
    "base": (None, "floating", "fixed"),
    "json": (False, True),
    "inertia": (None, "strict", "no-check"),
    "max_dof": (None, 12),
}
DEFAULT = {name: values[0] for name, values in FACTORS.items()}
RUNS = pairwise(FACTORS)
#: The link each robot's anchor holds (the xacro arm's names carry its prefix argument).
ANCHORED = {"oblique": "end_effector", "xacro": "r_wrist"}


def test_the_runs_cover_every_pair_and_are_few():
    assert uncovered_pairs(RUNS, FACTORS) == []
    assert len(RUNS) <= 14  # not the 10368 of all combinations


def files(options: dict, folder: Path) -> tuple[str | None, str | None]:
    """The run's --reference (the model's own file, or its URDF with one link 0.5 kg heavier)
    and --constraints files."""
    reference = None
    if options["reference"] == "same":
        reference = str(XACRO if options["model"] == "xacro" else OBLIQUE)
    elif options["reference"] == "heavier":
        text = robot_of(DEFAULT | {"model": options["model"]}).urdf
        mass = {"oblique": '<mass value="1.4"/>', "xacro": '<mass value="2.1"/>'}[options["model"]]
        assert text.count(mass) == 1
        (folder / "heavier.urdf").write_text(text.replace(mass, mass.replace("1.4", "1.9").replace("2.1", "2.6")))
        reference = str(folder / "heavier.urdf")
    constraints = None
    if options["constraints"]:
        (folder / "anchor.yaml").write_text(
            f"anchor:\n  - name: tip\n    frame1: {ANCHORED[options['model']]}\n    point1: [0.05, 0, 0]\n"
        )
        constraints = str(folder / "anchor.yaml")
    return reference, constraints


def arguments_of(options: dict, reference: str | None, constraints: str | None) -> list[str]:
    flags = shared_flags(options)
    flags += ["--samples", str(options["samples"])]
    flags += ["--seed", str(options["seed"])] if options["seed"] else []
    flags += ["--tolerance", str(options["tolerance"])] if options["tolerance"] else []
    flags += ["--reference", reference] if reference else []
    flags += ["--constraints", constraints] if constraints else []
    return ["check", *model_arguments(options["model"]), *flags]


def read_text(text: str) -> dict:
    """The printed table split by hand: header numbers, each row's errors and result, the verdict."""
    lines = text.splitlines()
    head = lines[0].split()
    rows = [line.split() for line in lines[3:] if line.endswith((" pass", " FAIL"))]
    return {
        "samples": int(head[head.index("random") - 1]),
        "seed": int(head[head.index("(seed") + 1].rstrip("),")),
        "joints": int(head[-2]),
        "max_abs": [float(row[-4]) for row in rows],
        "passed": [row[-1] == "pass" for row in rows],
        "verdict": "PASSED" in lines and "FAILED" not in lines,
    }


def check_run(options: dict, folder: Path) -> dict:
    """Run the command; the report must be the library's for the same options and pass
    exactly when the reference is the model's and the tolerance above round-off."""
    reference, constraints = files(options, folder)
    code, out, err = run(arguments_of(options, reference, constraints))
    robot = robodyn.load(
        source_of(options), **load_options(options), constraints=constraints and read_constraints(Path(constraints))
    )
    expected = check_robot(
        robot, samples=options["samples"], seed=options["seed"] or 0, tolerance=options["tolerance"] or 1e-9,
        reference_source=reference if options["reference"] == "heavier" else None,
    ).to_dict()  # fmt: skip
    must_pass = options["reference"] != "heavier" and options["tolerance"] != TIGHT
    assert (code, expected["passed"]) == (0 if must_pass else 1, must_pass), err
    if options["json"]:
        printed = json.loads(out)
        assert printed == expected
        return printed
    printed = read_text(out)
    comparisons = list(expected["comparisons"].values())
    assert (printed["samples"], printed["seed"], printed["joints"]) == (
        expected["samples"],
        expected["seed"],
        len(expected["joint_names"]),
    )
    assert printed["passed"] == [c["passed"] for c in comparisons] and printed["verdict"] == must_pass
    np.testing.assert_allclose(printed["max_abs"], [c["max_abs"] for c in comparisons], rtol=1e-3, atol=1e-300)
    return printed


#: Each option alone against the run with none: the report's keys it changes.
ALONE: dict[tuple[str, object], set[str]] = {
    ("model", "xacro"): {"robot", "joint_names", "comparisons"},
    ("samples", 7): {"samples", "comparisons"},
    ("seed", 5): {"seed", "comparisons"},
    ("tolerance", 1e-3): {"comparisons"},
    ("tolerance", TIGHT): {"passed", "comparisons"},
    ("reference", "same"): set(),
    ("reference", "heavier"): {"passed", "comparisons"},
    ("constraints", "anchor"): {"comparisons"},
    ("gravity", GRAVITY): {"comparisons"},
    ("base", "floating"): {"joint_names", "comparisons"},
    ("base", "fixed"): set(),
    ("inertia", "strict"): set(),
    ("inertia", "no-check"): set(),
    ("max_dof", 12): set(),
}
BASE = DEFAULT | {"json": True}


@functools.cache
def base_report() -> dict:
    """The run with no option (no file written: its folder unused), once for the module."""
    return check_run(BASE, Path("unused"))


@pytest.mark.slow
@pytest.mark.parametrize(("option", "value"), list(ALONE), ids=[f"{name}={value}" for name, value in ALONE])
def test_each_option_alone_changes_what_it_says_and_nothing_else(option, value, tmp_path):
    base = base_report()
    printed = check_run(BASE | {option: value}, tmp_path)
    assert {key for key in printed if printed[key] != base[key]} == ALONE[(option, value)]
    if option == "constraints":
        assert set(base["comparisons"]) < set(printed["comparisons"])  # the constraint's quantities added


def test_the_reference_reads_the_models_packages_and_xacro_arguments(tmp_path, monkeypatch):
    """The xacro arm as its own reference: read with --package and --xacro-arg, as the model
    is (before: 'package not found', the --package given ignored for the reference)."""
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    check_run(BASE | {"model": "xacro", "reference": "same"}, tmp_path)


def test_a_model_the_check_refuses_is_one_line(tmp_path):
    refused(["check", *model_arguments("oblique"), "--max-dof", "3"])
    refused(["check", *model_arguments("oblique"), "--reference", str(tmp_path / "none.urdf")])


@pytest.mark.slow
@pytest.mark.parametrize("options", RUNS, ids=[str(k) for k in range(len(RUNS))])
def test_the_options_crossed_pairwise_print_the_librarys_report(options, tmp_path):
    check_run(options, tmp_path)
