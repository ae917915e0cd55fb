"""The corpus of bad URDFs: each gives a robodyn error naming its problem, in load and lint."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

import robodyn
from robodyn import reference
from robodyn.cli.app import main
from robodyn.exceptions import RobodynWarning, URDFError
from robodyn.urdf.sources import lint_source
from tests.conftest import ROOT

BAD = ROOT / "tests" / "data" / "bad"
EXPECTED: dict[str, str] = json.loads((BAD / "expected.json").read_text(encoding="utf-8"))


def test_corpus_is_large_and_complete():
    assert len(EXPECTED) >= 40
    assert {path.name for path in BAD.glob("*.urdf")} == set(EXPECTED)


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_load_refuses_with_the_reason(name):
    with pytest.raises(robodyn.URDFError) as raised:
        robodyn.load(BAD / name)
    message = str(raised.value)
    assert EXPECTED[name] in message
    assert message.startswith(str(BAD / name))  # names the file
    assert "\n" not in message


@pytest.mark.parametrize("name", sorted(set(EXPECTED) - {"no_moving_joint.urdf"}))
def test_reference_refuses_the_same_files(name):
    with pytest.raises(robodyn.URDFError) as raised:
        reference.load(BAD / name)
    assert EXPECTED[name] in str(raised.value)


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_cli_prints_one_line_and_exits_2(name, capsys):
    assert main(["info", str(BAD / name)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and EXPECTED[name] in err


def test_lint_reports_every_problem_at_once(capsys, tmp_path):
    broken = (
        robodyn.rp_arm_urdf()
        .replace('<mass value="1.0"/>', '<mass value="-1.0"/>')
        .replace('<axis xyz="1 0 0"/>', '<axis xyz="0 0 0"/>')
    )
    broken = broken.replace('effort="100.0" velocity="3.0"', 'effort="0" velocity="3.0"')
    path = tmp_path / "broken.urdf"
    path.write_text(broken)
    problems = lint_source(str(path))
    rules = [problem.rule for problem in problems]
    assert any("mass -1.0 kg" in rule for rule in rules) and any("axis must not be zero" in rule for rule in rules)
    assert any(p.severity == "warning" and "effort limit is zero" in p.rule for p in problems)
    assert main(["lint", str(path)]) == 1
    out = capsys.readouterr().out
    assert out.count("error:") == 2 and "warning:" in out


def test_lint_of_a_good_file_exits_0(capsys):
    assert main(["lint", str(ROOT / "urdf" / "rp_arm.urdf")]) == 0
    assert "0 errors, 0 warnings" in capsys.readouterr().out


def test_lint_warns_about_massless_leaves_and_missing_meshes(tmp_path):
    text = robodyn.rp_arm_urdf().replace(
        "</robot>",
        '<joint name="finger" type="revolute"><parent link="link2"/><child link="tip"/><axis xyz="0 0 1"/>'
        '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
        '<link name="tip"><visual><geometry><mesh filename="meshes/tip.stl"/></geometry></visual></link></robot>',
    )
    path = tmp_path / "arm.urdf"
    path.write_text(text)
    problems = lint_source(str(path))
    assert all(p.severity == "warning" for p in problems)
    assert any("massless leaf" in p.rule for p in problems) and any("not found" in p.rule for p in problems)
    robot = robodyn.load(path)  # still loads
    assert robot.massless_joints == ["finger"]
    with pytest.raises(robodyn.SingularMassMatrixError, match="'finger' move no mass"):
        robot.forward_dynamics([0, 0, 0], [0, 0, 0], [0, 0, 0])


# --------------------------------------------------------------------------------------
# Issue 29: Foreign encodings the validator reads as urdfdom and Pinocchio do (issue 29, ite
# --------------------------------------------------------------------------------------
# pybullet_data's cube_no_rotation.urdf writes an unlimited slider as lower 1, upper -1.
BULLET_SLIDER = """<?xml version="1.0"?>
<robot name="bullet_slider">
  <link name="base"/>
  <link name="cube">
    <inertial><origin xyz="0 0 0.1"/><mass value="1.0"/>
      <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>
  </link>
  <link name="arm">
    <inertial><origin xyz="0.2 0 0"/><mass value="0.5"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.02"/></inertial>
  </link>
  <joint name="slide" type="prismatic">
    <parent link="base"/><child link="cube"/><axis xyz="1 0 0"/>
    <limit lower="1" upper="-1" effort="50" velocity="2"/>
  </joint>
  <joint name="turn" type="revolute">
    <parent link="cube"/><child link="arm"/><origin xyz="0 0 0.2"/><axis xyz="0 1 0"/>
    <limit lower="0.5" upper="-0.5" effort="10" velocity="3"/>
  </joint>
</robot>
"""


@pytest.fixture
def bullet_urdf(tmp_path):
    path = tmp_path / "bullet_slider.urdf"
    path.write_text(BULLET_SLIDER)
    return path


def test_lower_above_upper_loads_as_unlimited_with_one_line_warning_per_joint(bullet_urdf):
    with pytest.warns(RobodynWarning) as caught:
        robot = robodyn.load(bullet_urdf)
    messages = [str(w.message) for w in caught if "Bullet" in str(w.message)]
    assert len(messages) == 2 and all("\n" not in m and "strict" in m for m in messages)
    assert any('"slide"' in m and "lower limit 1.0 is above upper limit -1.0" in m for m in messages)
    lower, upper = robot.physical_limits()
    assert np.all(np.isneginf(lower)) and np.all(np.isposinf(upper))
    q = np.array([3.0, 2.5])  # far outside [1, -1] either way: no limit to break
    v, a = np.array([0.2, -0.4]), np.array([0.1, 0.3])
    expected = reference.load(bullet_urdf).inverse_dynamics(q, v, a)
    np.testing.assert_allclose(robot.inverse_dynamics(q, v, a), expected, atol=1e-10)


def test_lower_above_upper_is_refused_under_strict(bullet_urdf, capsys):
    with pytest.raises(URDFError, match=r"lower limit 1\.0 is above upper limit -1\.0"):
        robodyn.load(bullet_urdf, strict=True)
    assert main(["info", str(bullet_urdf), "--strict"]) == 2
    assert capsys.readouterr().err.count("\n") == 1


@pytest.mark.parametrize("kind", ["floating", "locked", "mimic"])
def test_lower_above_upper_crosses_the_other_load_options(bullet_urdf, kind, tmp_path):
    text = BULLET_SLIDER
    options: dict = {}
    if kind == "floating":
        options["floating_base"] = True
    elif kind == "locked":
        options["lock"] = {"slide": 5.0}  # outside [1, -1]: no limit, so no refusal
    else:
        text = text.replace(
            '<limit lower="0.5" upper="-0.5" effort="10" velocity="3"/>',
            '<limit lower="0.5" upper="-0.5" effort="10" velocity="3"/><mimic joint="slide" multiplier="2"/>',
        ).replace('type="revolute"', 'type="prismatic"')
    path = tmp_path / "crossed.urdf"
    path.write_text(text)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RobodynWarning)
        robot = robodyn.load(path, **options)
    lower, upper = robot.physical_limits()
    assert lower.size and np.all(np.isneginf(lower)) and np.all(np.isposinf(upper))
    with pytest.raises(URDFError, match="above upper limit"):
        robodyn.load(path, strict=True, **options)


DYNAMICS_ARM = """<robot name="arm"><link name="base"/>
<link name="l1"><inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
<link name="l2"><inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
<joint name="shoulder" type="continuous"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>{shoulder}</joint>
<joint name="weld" type="fixed"><parent link="l1"/><child link="l2"/>{weld}</joint>
</robot>"""


def test_joint_dynamics_are_read_and_bad_values_refused_naming_the_joint():
    from robodyn.urdf.validation import lint_urdf, parse_urdf

    spec = parse_urdf(DYNAMICS_ARM.format(shoulder='<dynamics damping="0.25" friction="1e-1"/>', weld=""))
    assert (spec.joints["shoulder"].damping, spec.joints["shoulder"].friction) == (0.25, 0.1)
    assert parse_urdf(DYNAMICS_ARM.format(shoulder='<dynamics friction="2"/>', weld="")).joints["shoulder"].damping == 0.0
    for bad in ('damping="-0.5"', 'friction="-1e-3"', 'damping="nan"', 'friction="inf"', 'damping="fast"', 'damping="1e13"'):
        with pytest.raises(URDFError) as raised:
            parse_urdf(DYNAMICS_ARM.format(shoulder=f"<dynamics {bad}/>", weld=""), "arm.urdf")
        assert 'joint "shoulder"' in str(raised.value) and "\n" not in str(raised.value)
    _, problems = lint_urdf(DYNAMICS_ARM.format(shoulder="", weld='<dynamics damping="3"/>'))
    assert [(p.element, p.severity) for p in problems if "dynamics" in p.rule] == [('joint "weld"', "warning")]


ONE_JOINT = (
    '<robot name="d"><link name="a"/><joint name="j" type="TYPE"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>'
    '<limit lower="LO" upper="UP" effort="1" velocity="1"/></joint><link name="b"><inertial><mass value="1"/>'
    '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link></robot>'
)


def _one_joint(lower: str, upper: str, joint_type: str = "revolute") -> str:
    return ONE_JOINT.replace("TYPE", joint_type).replace("LO", lower).replace("UP", upper)


@pytest.mark.parametrize(("lower", "upper"), [("-180", "180"), ("-90", "45"), ("0", "360"), ("-30", "30")])
def test_revolute_limits_written_in_degrees_are_a_loud_warning_and_strict_refuses_them(lower, upper):
    with pytest.warns(RobodynWarning, match=r"limits \[.*\] look like degrees .* in radians they would be"):
        robot = robodyn.load(_one_joint(lower, upper))
    assert robot.dofs[0].upper == float(upper)  # kept as written: a warning, not a rewrite
    with pytest.raises(URDFError, match="look like degrees"):
        robodyn.load(_one_joint(lower, upper), strict=True)


@pytest.mark.parametrize(
    ("lower", "upper", "joint_type"),
    [
        ("-3.14159", "3.14159", "revolute"),
        ("-6.2832", "6.2832", "revolute"),  # one turn to four digits (UR's wrists)
        ("-10", "10", "revolute"),  # ODRI's placeholder (solo12): 1.6 turns
        ("-12.566", "12.566", "revolute"),  # two turns, cable-limited
        ("-180", "180", "prismatic"),  # metres: not an angle
    ],
)
def test_radian_limits_and_prismatic_ones_pass_silently(lower, upper, joint_type):
    with warnings.catch_warnings():
        warnings.simplefilter("error", RobodynWarning)
        robodyn.load(_one_joint(lower, upper, joint_type), strict=True)
