"""Warnings and messages are behaviour: distinct problems give distinct warning lines, the
same problem is never repeated, whatever the options and whichever door (the library's
RobodynWarning, the CLI's stderr)."""

from __future__ import annotations

import contextlib
import io
import warnings

import numpy as np
import pytest

import robodyn
from robodyn.cli.app import main
from tests.conftest import NONDEGENERATE

pytestmark = pytest.mark.differential

#: Four problems the loader warns about and loads anyway: a limit with lower > upper (j1), a
#: mimic of a joint that does not exist (j2), two moving links whose inertias break the
#: triangle inequality (a, b).
TROUBLED = """<robot name="troubled">
  <link name="base"><inertial><mass value="2"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/>
    <limit lower="1" upper="-1" effort="10" velocity="2"/></joint>
  <link name="a"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.05"/></inertial></link>
  <joint name="j2" type="revolute"><parent link="a"/><child link="b"/><origin xyz="0.3 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="10" velocity="2"/><mimic joint="ghost" multiplier="2"/></joint>
  <link name="b"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.03"/></inertial></link>
  <joint name="j3" type="prismatic"><parent link="b"/><child link="c"/><origin xyz="0.3 0 0"/><axis xyz="1 0 0"/>
    <limit lower="-0.1" upper="0.2" effort="10" velocity="2"/></joint>
  <link name="c"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
</robot>"""
#: What each problem's line names (one line each).
PROBLEMS = {
    "limit": 'joint "j1": lower limit',
    "mimic": "mimics joint 'ghost'",
    "inertia a": 'link "a": principal moments',
    "inertia b": 'link "b": principal moments',
}


def each_once(lines: list[str], problems: dict[str, str]) -> None:
    """Every problem on exactly one line, no line twice, no line without a problem."""
    assert len(lines) == len(set(lines)), f"a warning is repeated: {lines}"
    for name, marker in problems.items():
        hits = [line for line in lines if marker in line]
        assert len(hits) == 1, f"{name}: {len(hits)} lines in {lines}"
    stray = [line for line in lines if not any(marker in line for marker in problems.values())]
    assert not stray, f"lines naming no problem: {stray}"


def test_each_once_fails_on_a_repeated_or_merged_warning():
    """Negative controls of the checker itself."""
    good = [f"x: {marker} ..." for marker in PROBLEMS.values()]
    each_once(good, PROBLEMS)
    with pytest.raises(AssertionError, match="repeated"):
        each_once([*good, good[0]], PROBLEMS)
    with pytest.raises(AssertionError, match="inertia b"):
        each_once(good[:3], PROBLEMS)


def _load_warnings(source, **options) -> list[str]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        robodyn.load(source, **options)
    assert all(isinstance(w.message, robodyn.RobodynWarning) for w in caught), [str(w.message) for w in caught]
    return [str(w.message) for w in caught]


OPTIONS = {
    "default": {},
    "floating": {"floating_base": True},
    "gravity": {"gravity": (1.0, -2.0, -8.0)},
    "locked": {"lock": {"j3": 0.1}},
    "threads": {"threads": 3},
}


@pytest.mark.parametrize("options", list(OPTIONS.values()), ids=list(OPTIONS))
def test_each_problem_warns_once_whatever_the_options(options, tmp_path):
    path = tmp_path / "troubled.urdf"
    path.write_text(TROUBLED)
    lines = _load_warnings(path, **options)
    each_once(lines, PROBLEMS)
    assert all(line.startswith(str(path)) for line in lines), lines  # each names the file
    assert _load_warnings(path, **options) == lines  # a second load warns again, the same


def test_locking_the_mimic_leaves_the_other_problems(tmp_path):
    path = tmp_path / "troubled.urdf"
    path.write_text(TROUBLED)
    each_once(_load_warnings(path, lock={"j2": 0.5}), {k: v for k, v in PROBLEMS.items() if k != "mimic"})


@pytest.mark.parametrize("command", [["info"], ["equations"], ["check", "--samples", "2"], ["lint"]])
def test_the_cli_prints_each_problem_once_on_stderr(command, tmp_path):
    path = tmp_path / "troubled.urdf"
    path.write_text(TROUBLED)
    stderr = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()) as stdout, contextlib.redirect_stderr(stderr):
        code = main([command[0], str(path), *command[1:]])
    lines = [line for line in stderr.getvalue().splitlines() if line.strip()]
    if command[0] == "lint":  # lint reports problems on stdout, as its result
        lines = [line for line in stdout.getvalue().splitlines() if any(m in line for m in PROBLEMS.values())]
        assert len(lines) == len(set(lines)), lines
        return
    assert code == 0, stderr.getvalue()
    each_once(lines, PROBLEMS)
    assert all(line.startswith("robodyn: warning: ") for line in lines), lines


def test_a_simulation_breaking_limits_warns_once_naming_each_joint():
    robot = robodyn.load(NONDEGENERATE / "oblique.urdf")
    q0 = np.clip(robot.neutral_configuration(), robot.lower_limits, robot.upper_limits)
    v0 = np.full(robot.nv, 5.0)  # above every velocity limit (2, 2, 1, ...)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        robodyn.simulate(robot, q0, v0, 0.05, 1e-3)
    limit_warnings = [w for w in caught if isinstance(w.message, robodyn.JointLimitWarning)]
    assert len(limit_warnings) == 1, [str(w.message) for w in caught]
    message = limit_warnings[0].message
    text = str(message)
    keys = [(v.joint, v.quantity, v.side) for v in message.violations]
    assert len(keys) == len(set(keys)) >= 3, keys  # one violation a joint and quantity
    for joint, quantity, _ in keys:
        assert text.count(f"{joint} {quantity}") == 1, (joint, quantity, text)
    fast = {name for name, dof in zip(robot.joint_names, robot.dofs, strict=True) if dof.velocity_limit < 5.0}
    assert fast <= {joint for joint, quantity, _ in keys if quantity == "velocity"}, (fast, keys)
