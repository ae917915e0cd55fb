"""The corpus of bad URDFs: each gives a robodyn error naming its problem, in load and lint."""

from __future__ import annotations

import json

import pytest

import robodyn
from robodyn import reference
from robodyn.cli.app import main
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
