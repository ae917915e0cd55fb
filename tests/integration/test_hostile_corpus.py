"""The hostile corpus (tests/data/hostile, issue #14 families 1-3 and #13 item 9) through
load, the reference and the CLI."""

from __future__ import annotations

import json
import re
import warnings
from collections import Counter

import pytest

import robodyn
from robodyn import reference
from robodyn.cli.app import main
from robodyn.common.text import is_printable
from robodyn.exceptions import RobodynError, RobodynWarning
from robodyn.urdf.sources import lint_source
from tests.conftest import ROOT

HOSTILE = ROOT / "tests" / "data" / "hostile"
EXPECTED: dict[str, dict] = json.loads((HOSTILE / "expected.json").read_text(encoding="utf-8"))
#: What must never reach the terminal raw (the final newline of a line excepted).
RAW = re.compile("[\x00-\x09\x0b-\x1f\x7f-\x9f\u061c\u200b-\u200f\u2028-\u202e\u2060-\u2069\ufeff]")


def _cases(outcome: str) -> list[str]:
    return sorted(name for name, case in EXPECTED.items() if case["outcome"] == outcome)


def test_corpus_is_complete_and_covers_every_family():
    assert {path.name for path in HOSTILE.glob("*.urdf")} == set(EXPECTED)
    families = Counter(case["family"] for case in EXPECTED.values())
    assert families["terminal"] >= 10 and families["numbers"] >= 15 and families["resources"] >= 4
    assert families["peers"] >= 6


@pytest.mark.parametrize("name", _cases("error"))
def test_errors_are_one_printable_line_in_load_and_reference(name):
    case = EXPECTED[name]
    with pytest.raises(RobodynError) as raised:
        robodyn.load(HOSTILE / name)
    message = str(raised.value)
    assert case["fragment"] in message
    assert is_printable(message) and "\n" not in message
    if case["reference"]:
        with pytest.raises(RobodynError) as raised:
            reference.load(HOSTILE / name)
        assert case["fragment"] in str(raised.value)


@pytest.mark.parametrize("name", _cases("error"))
def test_cli_prints_exactly_one_stderr_line_without_control_characters(name, capsys):
    assert main(["info", str(HOSTILE / name)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("robodyn: error: ")
    assert not RAW.search(err), repr(err)
    assert EXPECTED[name]["fragment"] in err


@pytest.mark.parametrize("name", _cases("error"))
def test_lint_lines_are_printable(name, capsys):
    assert main(["lint", str(HOSTILE / name)]) in (0, 1, 2)  # max_dof is a load limit, not lint
    captured = capsys.readouterr()
    for line in (captured.out + captured.err).splitlines():
        assert not RAW.search(line), repr(line)


@pytest.mark.parametrize("name", _cases("warning"))
def test_warnings_load_and_strict_refuses(name):
    fragment = EXPECTED[name]["fragment"]
    with pytest.warns(RobodynWarning) as caught:
        robot = robodyn.load(HOSTILE / name)
    assert robot.nv >= 1
    messages = [str(warning.message) for warning in caught if issubclass(warning.category, RobodynWarning)]
    assert any(fragment in message for message in messages)
    assert all(is_printable(message) for message in messages)
    with pytest.raises(robodyn.URDFError, match=re.escape(fragment)):
        robodyn.load(HOSTILE / name, strict=True)
    with pytest.warns(RobodynWarning):
        reference.load(HOSTILE / name)
    assert any(p.severity == "error" and fragment in p.rule for p in lint_source(HOSTILE / name))


@pytest.mark.parametrize("name", _cases("warning"))
def test_cli_shows_each_warning_as_one_line(name, capsys):
    assert main(["info", str(HOSTILE / name)]) == 0
    lines = capsys.readouterr().err.splitlines()
    assert lines and all(line.startswith("robodyn: warning: ") for line in lines)
    assert any(EXPECTED[name]["fragment"] in line for line in lines)
    assert not any(RAW.search(line) for line in lines)
    assert main(["lint", str(HOSTILE / name)]) == 1


@pytest.mark.parametrize("name", _cases("ok"))
def test_accepted_files_load_quietly_everywhere(name):
    with warnings.catch_warnings():
        warnings.simplefilter("error", RobodynWarning)
        robot = robodyn.load(HOSTILE / name)
        twin = reference.load(HOSTILE / name)
    assert robot.nv == twin.nv
    fragment = EXPECTED[name]["fragment"]
    if fragment:
        assert any(p.severity == "warning" and fragment in p.rule for p in lint_source(HOSTILE / name))


def test_mimic_of_a_missing_joint_leaves_the_joint_independent():
    with pytest.warns(RobodynWarning):
        robot = robodyn.load(HOSTILE / "mimic_missing_joint.urdf")
    assert robot.mimic is None and robot.nv == 2


def test_the_numbers_pinocchio_reads_are_the_validators():
    robot = robodyn.load(HOSTILE / "mass_leading_plus_and_dot.urdf")
    assert robot.model.inertias[robot.model.getJointId("joint2")].mass == 5.0  # "+.5e+1", not 0
    robot = robodyn.load(HOSTILE / "mass_padded.urdf")
    assert robot.model.inertias[robot.model.getJointId("joint2")].mass == 1.0  # " 1.0 ", not 0
