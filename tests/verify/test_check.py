"""CheckReport: the result of ``robodyn check``, its JSON and its text (issue 23).

Also here:

- Negative controls: every checker is shown a wrong answer and must say so.

  ``check_robot`` builds the robot from a URDF perturbed in one way (a mass, a centre of
  mass, an inertia's orientation, the joints' order, an axis, a mimic relation) and the
  reference from the true URDF: the check must fail, naming the quantity and the joint.
  ``robodyn check`` must exit 1 on the same models, ``robodyn lint`` on every bad file, and
  the ``Ṁ − 2C`` skew test must fail on a matrix that is not skew.

- Property: on random valid kinematic trees, Pinocchio and the reference agree.
"""

from __future__ import annotations

import json
import time
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings

import robodyn
from robodyn.cli import main
from robodyn.exceptions import InputError
from robodyn.verify.check import check_robot, report_text, skewness
from tests.random_robots import random_urdfs


def test_to_dict_is_the_json_the_cli_prints(capsys):
    assert main(["check", "rp_arm", "--samples", "5", "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    report = check_robot(robodyn.load("rp_arm"), samples=5)
    assert printed == json.loads(json.dumps(report.to_dict()))
    assert printed["passed"] and set(printed["comparisons"]) == {"tau", "M", "Cv", "G", "C", "skew_pinocchio", "skew_reference"}


def test_the_text_is_what_the_cli_prints(capsys):
    assert main(["check", "rp_arm", "--samples", "5"]) == 0
    assert capsys.readouterr().out.rstrip("\n") == check_robot(robodyn.load("rp_arm"), samples=5).text()


def test_a_floating_base_is_compared_on_tau_m_cv_and_g(capsys):
    report = check_robot(robodyn.load("rp_arm", floating_base=True), samples=3)
    assert set(report.comparisons) == {"tau", "M", "Cv", "G"}
    assert report.passed, report.failures


def test_a_robot_whose_joints_differ_from_the_reference_fails_one_joints_comparison(tmp_path):
    robot = robodyn.load("rp_arm")
    renamed = robot.urdf.replace('name="joint2"', 'name="slider2"').replace("joint2", "slider2")
    path = tmp_path / "renamed.urdf"
    path.write_text(renamed)
    report = check_robot(robot, samples=2, reference_source=path)
    assert not report.passed and list(report.comparisons) == ["joints"]
    assert "'joint2' only in the robot" in report.comparisons["joints"].where


ROBOTS = Path(__file__).parents[1] / "data" / "robots"
BAD = Path(__file__).parents[1] / "data" / "bad"
OBLIQUE = ROBOTS / "oblique.urdf"
MIMIC = ROBOTS / "mimic_tree.urdf"
SAMPLES = 6


def perturbed(path: Path, edit) -> str:
    """The URDF text of ``path`` after ``edit(root)`` changed its XML tree."""
    root = ET.fromstring(path.read_text())
    edit(root)
    return ET.tostring(root, encoding="unicode")


def _link(root: ET.Element, name: str) -> ET.Element:
    return next(node for node in root.findall("link") if node.get("name") == name)


def _joint(root: ET.Element, name: str) -> ET.Element:
    return next(node for node in root.findall("joint") if node.get("name") == name)


def _shift(node: ET.Element, attribute: str, delta) -> None:
    values = np.array([float(x) for x in node.get(attribute).split()]) + np.asarray(delta, float)
    node.set(attribute, " ".join(repr(float(x)) for x in values))


def change_mass(root):
    mass = _link(root, "arm").find("inertial/mass")
    mass.set("value", repr(float(mass.get("value")) * 1.02))


def move_centre_of_mass(root):
    _shift(_link(root, "ram").find("inertial/origin"), "xyz", (0.01, 0, 0))


def rotate_inertia(root):
    _shift(_link(root, "end_effector").find("inertial/origin"), "rpy", (0, 0, 0.3))


def swap_joint_order(root):
    """The first two joints of the chain swap names (each joint's physics under the other's name)."""
    _joint(root, "j_yaw").set("name", "tmp")
    _joint(root, "j_twist").set("name", "j_yaw")
    _joint(root, "tmp").set("name", "j_twist")


def flip_prismatic_axis(root):
    _shift(_joint(root, "j_extend").find("axis"), "xyz", (-4, 0, 2))  # "2 0 -1" -> "-2 0 1"


def flip_revolute_axis(root):
    _shift(_joint(root, "j_twist").find("axis"), "xyz", (-2, 4, -4))  # "1 -2 2" -> "-1 2 -2"


#: (perturbation, a quantity that must fail, joints the error may be worst at).
OBLIQUE_CONTROLS = {
    "changed mass": (change_mass, "M", {"j_yaw", "j_twist"}),
    "moved centre of mass": (move_centre_of_mass, "G", {"j_yaw", "j_twist", "j_extend"}),
    "rotated inertia": (rotate_inertia, "M", {"j_yaw", "j_twist", "j_tool"}),
    "swapped joint order": (swap_joint_order, "M", {"j_yaw", "j_twist", "j_extend", "j_tool"}),
    "flipped prismatic axis": (flip_prismatic_axis, "G", {"j_extend"}),
    "flipped revolute axis": (flip_revolute_axis, "M", {"j_yaw", "j_twist", "j_extend", "j_tool"}),
}


def _named_joints(where: str) -> set[str]:
    return {
        name for name in ("j_yaw", "j_twist", "j_extend", "j_tool", "j_shoulder", "j_wrist", "j_slide") if repr(name) in where
    }


def test_the_true_model_passes():
    """The positive control: without a perturbation the same check passes."""
    report = check_robot(robodyn.load(OBLIQUE), samples=SAMPLES, reference_source=OBLIQUE)
    assert report.passed, report_text(report)
    assert report.failures == []


@pytest.mark.parametrize("case", list(OBLIQUE_CONTROLS))
def test_check_fails_on_a_wrong_model(case):
    edit, quantity, joints = OBLIQUE_CONTROLS[case]
    wrong = robodyn.load(perturbed(OBLIQUE, edit))
    report = check_robot(wrong, samples=SAMPLES, reference_source=OBLIQUE)
    assert not report.passed
    comparison = report.comparisons[quantity]
    assert not comparison.passed, report_text(report)
    named = _named_joints(comparison.where)
    assert named and named <= joints, comparison.where
    assert any(line.startswith(f"{quantity}: ") and comparison.where in line for line in report.failures)


def test_check_names_the_joint_of_a_single_joint_error():
    """A flipped prismatic axis changes G of that joint only: the report says which."""
    report = check_robot(robodyn.load(perturbed(OBLIQUE, flip_prismatic_axis)), samples=SAMPLES, reference_source=OBLIQUE)
    assert report.comparisons["G"].where == "joint 'j_extend'"
    assert "j_extend" in report_text(report)


def test_check_fails_on_a_dropped_mimic_relation():
    def drop(root):
        elbow = _joint(root, "j_elbow")
        elbow.remove(elbow.find("mimic"))

    report = check_robot(robodyn.load(perturbed(MIMIC, drop)), samples=SAMPLES, reference_source=MIMIC)
    assert not report.passed
    assert report.comparisons["joints"].where == "joint 'j_elbow' only in the robot"
    assert report.failures == ["joints: relative error 1.000e+00 > 0e+00 at joint 'j_elbow' only in the robot"]


@pytest.mark.parametrize(("attribute", "value"), [("multiplier", "0.5"), ("offset", "0.2"), ("multiplier", "1"), ("offset", "0")])
def test_check_fails_on_a_wrong_mimic_multiplier_or_offset(attribute, value):
    """Every mimic of the true model has a multiplier != 1 and an offset != 0."""

    def edit(root):
        _joint(root, "j_finger").find("mimic").set(attribute, value)

    report = check_robot(robodyn.load(perturbed(MIMIC, edit)), samples=SAMPLES, reference_source=MIMIC)
    assert not report.comparisons["tau"].passed and not report.comparisons["G"].passed
    assert report.comparisons["G"].where in ("joint 'j_shoulder'", "joint 'j_slide'", "joint 'j_wrist'")


def test_mimic_model_passes_the_quantities_the_perturbations_fail():
    """The positive control of the mimic cases (M is a known bug: see test_nondegenerate)."""
    report = check_robot(robodyn.load(MIMIC), samples=SAMPLES, reference_source=MIMIC)
    for name in ("tau", "Cv", "G", "C", "skew_reference"):
        assert report.comparisons[name].passed, report_text(report)


def test_cli_check_exits_1_naming_quantity_and_joint(tmp_path, monkeypatch, capsys):
    wrong = tmp_path / "wrong.urdf"
    wrong.write_text(perturbed(OBLIQUE, flip_prismatic_axis))
    reference = ["--reference", str(OBLIQUE)]
    assert main(["check", str(wrong), "--samples", str(SAMPLES), *reference]) == 1
    out = capsys.readouterr().out
    assert "FAILED" in out and "G: relative error" in out and "joint 'j_extend'" in out
    assert main(["check", str(wrong), "--samples", str(SAMPLES), "--json", *reference]) == 1
    data = json.loads(capsys.readouterr().out)
    assert data["passed"] is False and data["comparisons"]["G"]["where"] == "joint 'j_extend'"


def test_cli_check_exits_0_on_the_true_model(capsys):
    assert main(["check", str(OBLIQUE), "--samples", str(SAMPLES)]) == 0
    assert "PASSED" in capsys.readouterr().out


@pytest.mark.parametrize(
    "path",
    sorted(BAD.glob("*.urdf")),
    ids=lambda p: p.stem,
)
def test_lint_fails_on_each_bad_file(path, capsys):
    assert main(["lint", str(path)]) == 1
    assert "error" in capsys.readouterr().out


def test_skewness_fails_on_a_non_skew_matrix():
    rng = np.random.default_rng(3)
    a = rng.normal(size=(4, 4))
    skew = a - a.T
    assert skewness(skew, 1.0, 1e-12).passed
    assert skewness(np.stack([skew, skew]), 1.0, 1e-12).passed
    names = ["a", "b", "c", "d"]
    not_skew = skew.copy()
    not_skew[1, 2] += 1e-6  # S + Sᵀ has 1e-6 at (1, 2) and (2, 1)
    result = skewness(np.stack([skew, not_skew]), 1.0, 1e-9, names)
    assert not result.passed and result.max_abs == pytest.approx(1e-6)
    assert result.where in ("joints ('b', 'c')", "joints ('c', 'b')")
    assert not skewness(np.eye(3), 1.0, 1e-9).passed  # symmetric
    assert not skewness(rng.normal(size=(3, 3)), 1.0, 1e-9).passed


def test_check_skew_test_fails_when_coriolis_is_not_skew_compatible(monkeypatch):
    """A C with the right C v but Ṁ − 2C not skew: the passivity test must notice."""
    robot = robodyn.load(OBLIQUE)
    original = robot.coriolis_matrix

    def wrong_coriolis(q, v):
        c = original(q, v)
        # Add N with N v = 0 (so C v is unchanged) and N + Nᵀ != 0.
        p = np.roll(v, 1, axis=-1)
        p = p - (np.sum(p * v, axis=-1) / np.sum(v * v, axis=-1))[..., None] * v
        return c + np.einsum("...i,...j->...ij", np.ones_like(v), p)

    monkeypatch.setattr(robot, "coriolis_matrix", wrong_coriolis)
    report = check_robot(robot, samples=SAMPLES)
    assert report.comparisons["Cv"].passed and report.comparisons["tau"].passed
    assert not report.comparisons["skew_pinocchio"].passed
    assert not report.comparisons["C"].passed


def test_check_reference_skew_test_fails_on_a_wrong_mass_matrix_derivative(monkeypatch):
    from robodyn.reference.numeric import ReferenceRobot

    original = ReferenceRobot.terms

    def wrong_derivative(self, q, v, a):
        terms = original(self, q, v, a)
        return terms | {"Mdot": 1.5 * terms["Mdot"]}

    monkeypatch.setattr(ReferenceRobot, "terms", wrong_derivative)
    report = check_robot(robodyn.load(OBLIQUE), samples=SAMPLES)
    assert not report.comparisons["skew_reference"].passed
    assert report.comparisons["skew_pinocchio"].passed


def assert_agree(urdf: str) -> None:
    report = check_robot(urdf, samples=4, seed=0)
    assert report.passed, {name: c.max_rel for name, c in report.comparisons.items()}


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(random_urdfs)
def test_random_trees_agree(urdf):
    assert_agree(urdf)


@pytest.mark.slow
@settings(max_examples=1000, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(random_urdfs)
def test_many_random_trees_agree(urdf):
    assert_agree(urdf)


HOLLOW_ARM = """<robot name="hollow">
  <link name="base"><inertial><mass value="3"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="a" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <link name="l1"/>
  <joint name="b" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0.3 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <link name="l2">TIP</link>
</robot>"""


def test_a_robot_with_no_moving_mass_is_refused_in_one_line(capsys):
    with pytest.raises(InputError, match=r"some moving mass.*'hollow', whose 2 joints move no mass and no inertia"):
        check_robot(HOLLOW_ARM.replace("TIP", ""), samples=3)
    assert main(["check", HOLLOW_ARM.replace("TIP", "")]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err.count("\n") == 1 and "nothing to compare" in captured.err
    # Slack: a gram at the tip is something to compare, and it agrees
    tip = '<inertial><origin xyz="0.1 0 0"/><mass value="0.001"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial>'
    assert check_robot(HOLLOW_ARM.replace("TIP", tip), samples=3).passed


def test_progress_is_reported_as_the_reference_evaluates_and_shown_only_on_a_terminal(capsys, monkeypatch):
    calls = []
    check_robot(robodyn.load("rp_arm"), samples=45, progress=lambda stage, done, total: calls.append((stage, done, total)))
    assert calls[-1] == ("reference", 45, 45) and [done for _, done, _ in calls] == sorted({done for _, done, _ in calls})
    assert 10 <= len(calls) <= 23
    assert main(["check", "rp_arm", "--samples", "5"]) == 0
    assert capsys.readouterr().err == ""  # not a terminal: nothing on stderr
    import robodyn.cli.common as common

    monkeypatch.setattr(common, "_is_terminal", lambda stream: True)
    monkeypatch.setattr(common.Progress, "DELAY", 0.0)
    assert main(["check", "rp_arm", "--samples", "5"]) == 0
    assert "\rchecking rp_arm: reference" in capsys.readouterr().err


def chain_urdf(joints: int, seed: int = 1) -> str:
    """A serial chain of ``joints`` revolute joints on oblique axes, with offset centres of mass."""
    rng = np.random.default_rng(seed)
    parts = [f'<robot name="chain{joints}"><link name="l0"/>']
    for i in range(1, joints + 1):
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        x, y, z = rng.uniform(-0.1, 0.1, 3)
        parts.append(
            f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/><child link="l{i}"/>'
            f'<origin xyz="{x:.4f} {y:.4f} {z:.4f}" rpy="0.1 0.2 0.3"/><axis xyz="{axis[0]:.6f} {axis[1]:.6f} {axis[2]:.6f}"/>'
            f'<limit lower="-1" upper="1" effort="10" velocity="5"/></joint><link name="l{i}"><inertial>'
            f'<origin xyz="0.02 0.01 0.03"/><mass value="{rng.uniform(0.1, 2.0):.3f}"/>'
            '<inertia ixx="0.01" ixy="0.001" ixz="0" iyy="0.012" iyz="0" izz="0.008"/></inertial></link>'
        )
    return "".join([*parts, "</robot>"])


@pytest.mark.slow
def test_a_62_joint_chain_checks_in_under_a_minute():
    robot = robodyn.load(chain_urdf(62))
    began = time.perf_counter()
    report = check_robot(robot, samples=100)
    elapsed = time.perf_counter() - began
    assert report.passed and elapsed < 60.0, elapsed
    print(f"62-joint chain, 100 samples: {elapsed:.1f} s, worst relative error {report.worst_relative_error:.2e}")
