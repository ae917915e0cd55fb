"""Every option of `robodyn info`, `robodyn lint` and `robodyn list` alone, read back, and crossed.

info: each option alone against the run with none (what it changes in the JSON, nothing
else), then a pairwise-covering set (tests/pairwise.py) compared with the library's
``info_dict`` of the Robot loaded with the same options and read back by hand (gravity,
degrees of freedom, the xacro argument's mass and prefix, the constraint). lint: every
combination of its three options (few) against ``lint_source`` with the same options, with
a root link whose inertia is impossible — an error only once the root moves (floating) —
and a xacro argument giving a negative mass. list: the text and the JSON name the same robots.
"""

from __future__ import annotations

import itertools
import json
from pathlib import Path

import numpy as np
import pytest

import robodyn
from robodyn.cli.report import info_dict
from robodyn.constraints.files import read_constraints
from robodyn.urdf.sources import lint_source
from tests.cli.option_runs import (
    GRAVITY,
    PACKAGE,
    XACRO,
    load_options,
    model_arguments,
    ok,
    run,
    shared_flags,
    source_of,
)
from tests.pairwise import pairwise, uncovered_pairs

ANCHORED = {"oblique": "end_effector", "xacro": "r_wrist"}
#: Each option's values; the first is the default (the option left out).
INFO: dict[str, tuple | list] = {
    "model": ("oblique", "xacro"),
    "gravity": (None, GRAVITY),
    "base": (None, "floating", "fixed"),
    "inertia": (None, "strict", "no-check"),
    "max_dof": (None, 12),
    "json": (False, True),
    "constraints": (None, "anchor"),
}
INFO_DEFAULT = {name: values[0] for name, values in INFO.items()}
INFO_RUNS = pairwise(INFO)


def test_the_info_runs_cover_every_pair_and_are_few():
    assert uncovered_pairs(INFO_RUNS, INFO) == [] and len(INFO_RUNS) <= 10  # not the 288 of all combinations


def check_info(options: dict, folder: Path) -> dict:
    """Run ``info``; what it printed is ``info_dict`` of the Robot with the same options, and says them."""
    flags = shared_flags(options)
    constraints = None
    if options["constraints"]:
        (folder / "anchor.yaml").write_text(
            f"anchor:\n  - name: tip\n    frame1: {ANCHORED[options['model']]}\n    point1: [0, 0, 0.05]\n"
        )
        constraints = read_constraints(folder / "anchor.yaml")
        flags += ["--constraints", str(folder / "anchor.yaml")]
    printed = ok(["info", *model_arguments(options["model"]), *flags])
    robot = robodyn.load(source_of(options), **load_options(options), constraints=constraints)
    nv = {"oblique": 4, "xacro": 3}[options["model"]] + (6 if options["base"] == "floating" else 0)
    gravity = list(options["gravity"] or (0.0, 0.0, -9.81))
    if not options["json"]:
        head = printed.splitlines()[0]
        assert f"{nv} degrees of freedom" in head and f"{'floating' if options['base'] == 'floating' else 'fixed'} base" in head
        assert f"gravity [{', '.join(f'{g:g}' for g in gravity)}] m/s²" in head
        assert ("'tip'" in printed) == bool(constraints)
        return {"text": printed}
    document = json.loads(printed)
    assert document == json.loads(json.dumps(info_dict(robot)))
    assert (document["nv"], document["gravity_m_s2"], document["floating_base"]) == (nv, gravity, options["base"] == "floating")
    if options["model"] == "xacro":  # the xacro arguments reached the file: the prefix and the mass
        assert document["link_masses_kg"]["r_upper"] == 2.1
    assert [c["name"] for c in document.get("constraints", [])] == (["tip"] if constraints else [])
    return document


#: Each option of info alone against the run with none: the JSON keys it changes.
INFO_ALONE: dict[tuple[str, object], set[str]] = {
    ("model", "xacro"): {"name", "robot_name", "file_format", "source", "nq", "nv", "end_effector", "end_effector_candidates",
                         "joints", "link_masses_kg", "total_mass_kg", "mimic_joints", "joint_dynamics", "package_paths"},
    ("gravity", GRAVITY): {"gravity_m_s2"},
    ("base", "floating"): {"nq", "nv", "floating_base", "joints"},
    ("base", "fixed"): set(),
    ("inertia", "strict"): set(),
    ("inertia", "no-check"): set(),
    ("max_dof", 12): set(),
    ("constraints", "anchor"): {"constraints", "constraint_rank_at_neutral"},
}  # fmt: skip


@pytest.mark.parametrize(("option", "value"), list(INFO_ALONE), ids=[f"{name}={value}" for name, value in INFO_ALONE])
def test_each_info_option_alone_changes_what_it_says_and_nothing_else(option, value, tmp_path):
    base = check_info(INFO_DEFAULT | {"json": True}, tmp_path)
    document = check_info(INFO_DEFAULT | {"json": True, option: value}, tmp_path)
    keys = set(base) | set(document)
    assert {key for key in keys if document.get(key) != base.get(key)} == INFO_ALONE[(option, value)]


@pytest.mark.slow
@pytest.mark.parametrize("options", INFO_RUNS, ids=[str(k) for k in range(len(INFO_RUNS))])
def test_the_info_options_crossed_pairwise_describe_the_robot(options, tmp_path):
    check_info(options, tmp_path)


# ----------------------------------------------------------------------------------------
# lint: few options, every combination
# ----------------------------------------------------------------------------------------
BAD_ROOT = """<robot name="bad_root">
  <link name="root"><inertial><mass value="1"/><inertia ixx="1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="arm"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j" type="revolute"><parent link="root"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>
"""
NEGATIVE = {"prefix": "r_", "upper_mass": "-2.1"}  # a xacro argument making a negative mass
LINT = list(itertools.product(("bad_root", "xacro"), (None, True), (False, True)))


def lint_run(model: str, floating: bool | None, as_json: bool, folder: Path) -> tuple[int, str, list]:
    path = folder / "bad_root.urdf"
    path.write_text(BAD_ROOT)
    source = str(path if model == "bad_root" else XACRO)
    xacro: dict = {"xacro_args": NEGATIVE, "packages": {"robodyn_test_arm": str(PACKAGE)}} if model == "xacro" else {}
    flags = [f"--xacro-arg={k}:={v}" for k, v in NEGATIVE.items()] + [f"--package=robodyn_test_arm={PACKAGE}"] if xacro else []
    flags += (["--floating-base"] if floating else []) + (["--json"] if as_json else [])
    code, out, _ = run(["lint", source, *flags])
    return code, out, lint_source(source, floating_base=floating, **xacro)


@pytest.mark.parametrize(("model", "floating", "as_json"), LINT, ids=[f"{m}-{f}-{j}" for m, f, j in LINT])
def test_lint_with_every_combination_of_its_options_reports_the_librarys_problems(model, floating, as_json, tmp_path):
    code, out, problems = lint_run(model, floating, as_json, tmp_path)
    errors = [p for p in problems if p.severity == "error"]
    # what must be found: the root's inertia only once the root moves; the negative mass, prefixed, always
    if model == "bad_root":
        assert bool(errors) == bool(floating) and all("root" in str(p) for p in errors)
    else:
        assert errors and any("r_upper" in str(p) for p in errors)
    assert code == (1 if errors else 0)
    if as_json:
        document = json.loads(out)
        assert (document["errors"], document["warnings"]) == (len(errors), len(problems) - len(errors))
        assert document["problems"] == [{"severity": p.severity, "element": p.element, "rule": p.rule} for p in problems]
    else:
        lines = out.splitlines()
        assert lines[:-1] == [f"{p.severity}: {p}" for p in problems]
        assert lines[-1].endswith(
            f": {len(errors)} error{'s' * (len(errors) != 1)}, {len(problems) - len(errors)} warning{'s' * (len(problems) - len(errors) != 1)}"
        )


def test_list_as_text_and_as_json_name_the_same_robots():
    rows = [line.split() for line in ok(["list"]).splitlines()]
    document = json.loads(ok(["list", "--json"]))
    assert [row[0] for row in rows] == [entry["name"] for entry in document] == list(robodyn.robot_names())
    assert [row[-2] == "floating" for row in rows] == [entry["floating_base"] for entry in document]
    assert [row[1] == "generated" for row in rows] == [entry["origin"] == "generated" for entry in document]
    assert np.sum([entry["floating_base"] for entry in document]) > 0  # not all one kind: the column can tell
