"""Issue 13, item 3: joint limits are reported loudly, or enforced; defaults lie inside them.

Reproductions: a passive rp_arm's slider left its 0.3 m limit far behind with nothing
said; the default panda task-space run needed 474 N m of an 87 N m joint; panda's default
q0 broke joint 4's limits; ``whatif`` printed torques above the effort limit silently.
"""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

import robodyn
from robodyn import exceptions
from robodyn.cli.app import main
from robodyn.exceptions import InputError, SingularMassMatrixError
from robodyn.sim.control import PDGravity
from robodyn.sim.experiment import controller_model, run_simulation
from robodyn.sim.simulation import simulate
from robodyn.sim.whatif import sweep


def test_passive_slider_leaving_its_limit_is_reported():
    robot = robodyn.load("rp_arm")
    q0 = np.array([-1.2, 0.1])  # hanging down-ish: the slider slides out under gravity
    with pytest.warns(exceptions.JointLimitWarning, match="joint2 position") as record:
        trajectory = simulate(robot, q0, np.zeros(2), 1.0, 1e-3)
    upper = robot.joints[1].upper
    violations = record[0].message.violations
    slider = next(v for v in violations if v.joint == "joint2" and v.quantity == "position")
    assert slider.side == "upper" and slider.limit == upper
    assert slider.worst == pytest.approx(trajectory.q[:, 1].max())
    first = np.argmax(trajectory.q[:, 1] > upper)
    assert slider.first_time == pytest.approx(trajectory.t[first])
    assert "\n" not in str(record[0].message)


def test_enforce_stops_the_slider_at_its_limit_and_keeps_it_there():
    robot = robodyn.load("rp_arm")
    q0 = np.array([-1.2, 0.1])
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always", exceptions.JointLimitWarning)
        trajectory = simulate(robot, q0, np.zeros(2), 1.0, 1e-3, limits="enforce")
    reported = [v for w in record for v in w.message.violations]
    assert reported and {v.quantity for v in reported} == {"velocity"}  # velocity limits: reported only
    lower, upper = robot.joints[1].lower, robot.joints[1].upper
    assert trajectory.q[:, 1].max() <= upper and trajectory.q[:, 1].min() >= lower
    at_stop = trajectory.q[:, 1] == upper
    assert at_stop[-100:].all()  # it arrived and stayed
    assert np.all(trajectory.v[at_stop, 1] <= 0.0)  # no velocity into the stop


def test_enforce_saturates_torques_at_the_effort_limits():
    robot = robodyn.load("panda")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", exceptions.JointLimitWarning)  # velocity limits are only reported
        trajectory, summary = run_simulation(robot, controller="task-space", target=[0.4, 0.2, 0.5], limits="enforce")
    effort = np.array([joint.effort for joint in robot.joints])
    assert np.all(np.abs(trajectory.tau) <= effort + 1e-12)
    assert np.isclose(np.abs(trajectory.tau[:, 1]).max(), effort[1])  # it needed the saturation
    lower, upper = robot.physical_limits()
    assert np.all(trajectory.q >= lower - 1e-12) and np.all(trajectory.q <= upper + 1e-12)
    assert {v["quantity"] for v in summary["limit_violations"]} <= {"velocity"}
    assert summary["target_reached"]


def test_warn_mode_summary_lists_every_violation_with_its_worst_value():
    robot = robodyn.load("panda")
    trajectory, summary = run_simulation(robot, controller="task-space", target=[0.4, 0.2, 0.5])
    effort = {(v["joint"], v["quantity"]): v for v in summary["limit_violations"]}
    joint2 = effort[("panda_joint2", "effort")]
    assert abs(joint2["worst"]) == pytest.approx(np.abs(trajectory.tau[:, 1]).max())
    assert abs(joint2["limit"]) == robot.joints[1].effort and joint2["unit"] == "N m"
    # Negative control: within every limit nothing is reported.
    still = simulate(robot, robot.default_configuration(), np.zeros(8), 0.2, 1e-3, limits="ignore")
    quiet = PDGravity(controller_model(robot), robot.default_configuration())
    with warnings.catch_warnings():
        warnings.simplefilter("error", exceptions.JointLimitWarning)
        held = simulate(robot, robot.default_configuration(), np.zeros(8), 0.2, 1e-3, controller=quiet)
    from robodyn.sim.limits import limit_violations

    assert limit_violations(robot, held) == []
    assert len(still) == 201


def test_ignore_mode_says_nothing():
    robot = robodyn.load("rp_arm")
    with warnings.catch_warnings():
        warnings.simplefilter("error", exceptions.JointLimitWarning)
        simulate(robot, np.array([-1.2, 0.1]), np.zeros(2), 1.0, 1e-3, limits="ignore")
    with pytest.raises(InputError, match="limits"):
        simulate(robot, np.zeros(2), np.zeros(2), 0.1, 1e-3, limits="clamp")


@pytest.mark.parametrize("name", ["panda", "ur5", "z1", "kinova", "solo12", "rp_arm"])
def test_default_configuration_lies_within_the_limits(name):
    robot = robodyn.load(name)
    q = robot.default_configuration()
    lower, upper = robot.physical_limits()
    joints = q[robot.nq - lower.size :]
    assert np.all(joints >= lower) and np.all(joints <= upper)
    if name == "panda":  # the neutral configuration does not
        neutral = robot.neutral_configuration()
        assert not np.all(neutral <= upper)


def test_simulate_command_warns_on_one_line_and_reports_in_json(capsys):
    status = main(["simulate", "rp_arm", "--q0", "-1.2,0.1", "--duration", "1", "--json"])
    captured = capsys.readouterr()
    assert status == 0
    warning_lines = [line for line in captured.err.splitlines() if "warning" in line]
    assert len(warning_lines) == 1 and "joint2 position" in warning_lines[0]
    summary = json.loads(captured.out)
    assert any(v["joint"] == "joint2" and v["quantity"] == "position" for v in summary["limit_violations"])
    assert main(["simulate", "rp_arm", "--q0", "-1.2,0.1", "--duration", "1", "--limits", "enforce", "--json"]) == 0
    captured = capsys.readouterr()
    assert "joint2 position" not in captured.err
    assert json.loads(captured.out)["final_q"][1] == pytest.approx(0.3)


def test_whatif_marks_peaks_above_the_effort_limit(capsys):
    rows = sweep("rp_arm", materials=("abs", "steel"), payloads=(0.0, 2.0))
    effort = robodyn.load("rp_arm").joints[0].effort
    over = [bool(row.over_limit[0]) for row in rows]
    assert over == [row.peak[0] > effort for row in rows] and any(over) and not all(over)
    assert main(["whatif", "--materials", "abs,steel", "--payloads", "0,2"]) == 0
    out = capsys.readouterr().out
    assert "!" in out and "above the effort limit of joint1 (100 N m)" in out


def test_whatif_default_motion_stays_within_the_limits():
    robot = robodyn.load("panda")
    from robodyn.sim.whatif import _half_radian_away

    start = robot.default_configuration()
    end = _half_radian_away(robot, start)
    lower, upper = robot.physical_limits()
    assert np.all(end >= lower) and np.all(end <= upper)
    assert np.abs(end - start)[:7].min() == pytest.approx(0.5)


MASSLESS_TIP = """<robot name="massless_tip">
  <link name="base"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="10" velocity="3"/></joint>
  <link name="l1"><inertial><origin xyz="0.2 0 0"/><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0.4 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="10" velocity="3"/></joint>
  <link name="l2"/>
</robot>"""


def test_simulating_a_singular_mass_matrix_says_so():
    robot = robodyn.load(MASSLESS_TIP)
    with pytest.raises(SingularMassMatrixError, match="j2"):
        simulate(robot, np.zeros(2), np.zeros(2), 0.1, 1e-3)
    assert main(["simulate", MASSLESS_TIP, "--duration", "0.1"]) == 2
