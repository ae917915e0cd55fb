"""Pictures of the sequel: the target pose as a triad, pushes as arrows, and the observer's
estimate against the applied external torques."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn.sim.experiment import applied_torques, push_wrenches, run_simulation
from robodyn.viz.plots import external_torques_figure, text_overlaps

pytest.importorskip("meshcat")


@pytest.fixture(scope="module")
def pushed():
    robot = robodyn.load("rp_arm")
    trajectory, summary = run_simulation(
        robot, controller="impedance", target=[0.9, 0.0, 0.5, 0.0, 0.3, 0.0], q0=[0.5, 0.13], force_at=["0.2:5,0,-4"],
        stiffness=[300.0, 300.0, 200.0, 20.0, 20.0, 20.0], observer_gain=50.0, duration=0.5, limits="ignore",
    )  # fmt: skip
    return robot, trajectory, summary


def test_a_push_is_an_arrow_shown_only_while_it_acts_and_pointing_along_the_force(pushed):
    from robodyn.viz.scene import motion
    from robodyn.viz.task import force_commands

    robot, trajectory, summary = pushed
    moved, _ = motion(robot, trajectory, 20.0)
    _, forces = push_wrenches(robot, summary.pushes, robot.end_effector)
    points = np.vstack([robot.frame_position(q, robot.end_effector) for q in moved.configurations])
    commands, clips = force_commands(robot, moved.times, moved.configurations, forces, points, 20.0)
    assert [c["path"].split("/")[-1] for c in commands if c["type"] == "set_object"] == ["shaft", "tip"]
    (clip,) = clips.values()
    lowered = clip.lower()["tracks"]
    visible = [key["value"] for key in next(track for track in lowered if track["name"] == ".visible")["keys"]]
    assert visible == [bool(t >= 0.2) for t in moved.times] and any(visible) and not all(visible)
    quaternions = next(track for track in lowered if track["name"] == ".quaternion")["keys"]
    last = np.array(quaternions[-1]["value"])  # x, y, z, w
    import pinocchio as pin

    direction = pin.Quaternion(last[3], *last[:3]).matrix() @ [0.0, 1.0, 0.0]
    assert np.allclose(direction, np.array([5.0, 0.0, -4.0]) / np.hypot(5.0, 4.0), atol=1e-9)
    _, none = force_commands(robot, moved.times, moved.configurations, [], points, 20.0)
    assert none == {}  # negative control: no push, no arrow


def test_the_recording_draws_the_target_pose_and_the_push(pushed, tmp_path):
    from robodyn.viz.experiment import run_experiment

    robot, trajectory, _ = pushed
    options = {"controller": "impedance", "target": [0.9, 0.0, 0.5, 0.0, 0.3, 0.0], "q0": [0.5, 0.13], "duration": 0.3}
    html = tmp_path / "r.html"
    run_experiment(robot, record=html, force_at=["0.1:5,0,-4"], limits="ignore", **options)
    text = html.read_text(encoding="utf-8")
    plain = tmp_path / "plain.html"
    run_experiment(robot, record=plain, limits="ignore", **{**options, "target": [0.9, 0.0, 0.5]})
    assert len(text) > len(plain.read_text(encoding="utf-8"))  # the triad and the arrow are extra commands

    from robodyn.viz.recording import motion_commands
    from robodyn.viz.task import target_pose_commands

    paths = [c.get("path", "") for c in motion_commands(robot, trajectory, target=[0.9, 0.0, 0.5])[0]]
    assert not any("target_pose" in p for p in paths)  # negative control: no attitude, no triad
    triad = target_pose_commands(np.array([0.9, 0.0, 0.5]), np.eye(3), np.array([[0.0, 0, 0], [1, 1, 1]]))
    assert triad[0]["path"].endswith("target_pose") and triad[1]["matrix"][12:15] == pytest.approx([0.9, 0.0, 0.5])


def test_the_estimate_against_the_applied_torques_is_one_panel_a_unit_without_overlaps(pushed):
    robot, trajectory, summary = pushed
    names, units = [d.name for d in robot.dofs], [d.effort_unit for d in robot.dofs]
    applied = applied_torques(robot, trajectory, push_wrenches(robot, summary.pushes)[1])
    assert np.array_equal(applied, summary.observer.applied)
    figure = external_torques_figure(trajectory.t, summary.observer.residual, applied, names, units, gain=50.0)
    assert len(figure.axes) == 2 and text_overlaps(figure) == []
    assert [len(axis.lines) for axis in figure.axes] == [2, 2]  # estimated and applied for each joint
    alone = external_torques_figure(trajectory.t, summary.observer.residual, None, names, units)
    assert [len(axis.lines) for axis in alone.axes] == [1, 1]
