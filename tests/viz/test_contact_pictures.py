"""Issue 42's pictures, checked by what is drawn: the wall's force arrow (its length the
scaled measured force, along the normal, at the tip), the force panel (its curves the
commanded and measured force), the standing robot's support polygon (its corners the
feet's positions) and centre of mass (where the robot's centre of mass is at each frame)."""

from __future__ import annotations

import csv

import numpy as np
import pinocchio as pin
import pytest

import robodyn
from robodyn.sim.experiment import run_simulation
from robodyn.sim.ground import Ground
from robodyn.sim.hybrid_run import run_hybrid
from robodyn.sim.surface_run import SurfaceRun

pytest.importorskip("meshcat")

BENT = [0, 0, 0.3, 0, 0, 0, 1, 0, 0.8, -1.6, 0, 0.8, -1.6, 0, -0.8, 1.6, 0, -0.8, 1.6]
FEET = ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")


@pytest.fixture(scope="module")
def wall():
    robot = robodyn.load("rp_arm")
    trajectory, summary = run_hybrid(
        robot, force=10.0, surface=((1.0, 0, 0), (-1.0, 0, 0)), along=(0, 0, 0.1), duration=0.2, dt=0.01
    )
    return robot, trajectory, summary


@pytest.fixture(scope="module")
def stand():
    robot = robodyn.load("solo12")
    trajectory, summary = run_simulation(
        robot, controller="stand", ground=Ground(), q0=BENT, target=[0, 0.01, 0], duration=0.05, dt=1e-3
    )
    return robot, trajectory, summary


def test_the_stand_csv_has_the_qp_forces_beside_the_simulated_ones(stand, tmp_path):
    robot, trajectory, summary = stand
    path = summary.contact.save(tmp_path / "stand.csv")
    with path.open() as file:
        rows = [row for row in csv.reader(file) if row and not row[0].startswith("#")]
    columns = {name: np.array([float(row[k]) for row in rows[1:]]) for k, name in enumerate(rows[0])}
    names = summary.contact.contacts
    commanded = np.stack([[columns[f"f_cmd[{name}].{axis}"] for axis in "xyz"] for name in names], axis=1).T
    measured = np.stack([[columns[f"f[{name}].{axis}"] for axis in "xyz"] for name in names], axis=1).T
    weight = robot.total_mass * 9.81
    np.testing.assert_allclose(commanded[:, :, 2].sum(axis=1)[-1], weight, rtol=1e-3)  # the QP carries m g at rest
    assert np.abs(commanded - measured).max() <= 1e-4 * weight
    assert np.abs(commanded - measured[::-1]).max() > 1e-3 * weight or len(measured) < 3  # negative control
    assert robodyn.Trajectory.load(path).q.shape == trajectory.q.shape  # a trajectory reader skips them


def _arrows(robot, run: SurfaceRun):
    """The arrow's (position, direction, length) at every animation frame, and the scale."""
    from robodyn.viz.scene import motion
    from robodyn.viz.task import FORCE_LENGTH, _scene_size, force_commands

    moved, _ = motion(robot, run.trajectory, 50.0)
    points = np.vstack([robot.frame_position(q, run.frame) for q in moved.configurations] + [[0.0, 0.0, 0.0]])
    _, clips = force_commands(robot, moved.times, moved.configurations, run.force_arrows(), points, 50.0)
    ((_, clip),) = clips.items()
    tracks = {track["name"]: [key["value"] for key in track["keys"]] for track in clip.lower()["tracks"]}
    directions = [pin.Quaternion(w, x, y, z).matrix() @ [0.0, 1.0, 0.0] for x, y, z, w in tracks[".quaternion"]]
    lengths = np.array([scale[0] for scale in tracks[".scale"]])
    return moved, np.array(tracks[".position"]), np.array(directions), lengths, FORCE_LENGTH * _scene_size(points)


def _held(run: SurfaceRun, times: np.ndarray, values: np.ndarray) -> np.ndarray:
    return values[np.clip(np.searchsorted(run.trajectory.t, times, side="right") - 1, 0, len(values) - 1)]


def test_the_wall_force_arrow_is_the_measured_force_scaled_along_the_normal_at_the_tip(wall):
    robot, _, summary = wall
    run = summary.contact
    moved, positions, directions, lengths, full = _arrows(robot, run)
    np.testing.assert_allclose(positions, robot.frame_position(moved.configurations, "end_effector"), atol=1e-12)
    np.testing.assert_allclose(directions, np.tile([-1.0, 0.0, 0.0], (len(directions), 1)), atol=1e-9)
    measured = _held(run, moved.times, run.measured)
    np.testing.assert_allclose(lengths, full * measured / measured.max(), rtol=1e-12)


def test_the_surface_is_drawn_in_its_plane_about_the_motions_middle(wall):
    robot, trajectory, summary = wall
    (patch,) = summary.drawings
    np.testing.assert_allclose(patch.vertices[:, 0], 1.0, atol=1e-15)  # the wall x = 1
    start = robot.frame_position(trajectory.q[0], "end_effector")
    np.testing.assert_allclose(patch.vertices.mean(axis=0), start, atol=1e-12)  # the middle: the tip's start
    sides = np.linalg.norm(np.roll(patch.vertices, -1, axis=0) - patch.vertices, axis=1)
    np.testing.assert_allclose(sides, 2 * (0.1 + 0.1), rtol=1e-12)  # 0.1 m beyond the 0.1 m amplitude


def test_the_arrow_check_tells_the_measured_force_from_the_commanded():  # negative control
    robot = robodyn.load("rp_arm")
    trajectory, summary = run_hybrid(robot, force=10.0, surface=((1.0, 0, 0), (-1.0, 0, 0)), duration=0.1, dt=0.01)
    ramp = np.linspace(5.0, 15.0, len(trajectory))  # a measured force that is not the command
    run = SurfaceRun(trajectory, "surface", "end_effector", np.array([-1.0, 0, 0]), ramp, summary.contact.commanded)
    moved, _, _, lengths, full = _arrows(robot, run)
    np.testing.assert_allclose(lengths, full * _held(run, moved.times, ramp) / ramp.max(), rtol=1e-12)
    commanded = _held(run, moved.times, run.commanded)
    assert np.abs(lengths - full * commanded / ramp.max()).max() > 0.1 * full


def test_the_force_panel_draws_the_commanded_and_the_measured_force(wall):
    from robodyn.viz.plots import simulation_figure

    robot, trajectory, summary = wall
    figure = simulation_figure(robot, trajectory, panels=summary.panels)
    (axis,) = [axis for axis in figure.axes if axis.get_ylabel() == "normal force [N]"]
    drawn = {line.get_label(): line.get_ydata() for line in axis.lines}
    assert set(drawn) == {"commanded force", "measured force"}
    np.testing.assert_array_equal(drawn["measured force"], summary.contact.measured)
    np.testing.assert_array_equal(drawn["commanded force"], np.full(len(trajectory), 10.0))
    plain = simulation_figure(robot, trajectory)
    assert "normal force [N]" not in [axis.get_ylabel() for axis in plain.axes]  # negative control


def test_the_support_polygon_has_the_feet_as_corners_and_the_centre_of_mass_moves_with_the_robot(stand):
    from robodyn.viz.drawings import drawing_commands
    from robodyn.viz.scene import motion

    robot, trajectory, summary = stand
    polygon, _, shadow, target = summary.drawings
    feet = np.array([robot.frame_position(trajectory.q[0], foot) for foot in FEET])
    assert len(polygon.vertices) == 4
    assert all(np.linalg.norm(feet - vertex, axis=1).min() <= 1e-12 for vertex in polygon.vertices)
    assert np.abs(polygon.vertices[:, 2]).max() <= 1e-9  # on the ground
    moved, _ = motion(robot, trajectory, 200.0)
    commands, clips = drawing_commands(summary.drawings, moved.times, 200.0)
    loop = next(c for c in commands if c["path"].endswith("support_polygon"))
    assert loop["object"]["object"]["type"] == "LineLoop"
    track = next(t for t in clips[("task", "com")].lower()["tracks"] if t["name"] == ".position")
    drawn = np.array([key["value"] for key in track["keys"]])
    np.testing.assert_allclose(drawn, robot.center_of_mass(moved.configurations), atol=2e-4)  # between samples: linear
    np.testing.assert_allclose(target.positions[0], robot.center_of_mass(trajectory.q[0]) + np.array([0, 0.01, 0]), atol=1e-15)
    assert np.abs(drawn - shadow.at(moved.times)).max() > 0.1  # negative control: the shadow is on the ground


def test_the_stand_panels_are_the_centre_of_mass_error_and_the_support_margin(stand):
    robot, trajectory, summary = stand
    errors, margin, forces = summary.panels
    (_, t, commanded, _), (_, _, measured, _) = forces.curves
    np.testing.assert_array_equal(t, trajectory.t)
    weight = robot.total_mass * 9.81
    assert abs(commanded[-1] - weight) <= 1e-3 * weight and np.abs(commanded - measured).max() <= 1e-4 * weight
    target = robot.center_of_mass(trajectory.q[0]) + np.array([0, 0.01, 0])
    expected = robot.center_of_mass(trajectory.q) - target
    for k, (_, t, values, _) in enumerate(errors.curves):
        np.testing.assert_array_equal(t, trajectory.t)
        np.testing.assert_allclose(values, expected[:, k], atol=1e-15)
    ((_, t, values, _),) = margin.curves
    for time, value in zip(t, values, strict=True):  # the feet's rectangle, axis-aligned: the distance to its sides
        q = trajectory.q[np.searchsorted(trajectory.t, time)]
        feet, centre = np.array([robot.frame_position(q, foot) for foot in FEET]), robot.center_of_mass(q)
        sides = np.concatenate([centre[:2] - feet[:, :2].min(axis=0), feet[:, :2].max(axis=0) - centre[:2]])
        assert abs(value - sides.min()) <= 1e-9


@pytest.mark.slow
def test_the_hybrid_and_stand_figures_have_no_colliding_text(wall, stand):
    from robodyn.viz.plots import simulation_figure, text_overlaps

    for robot, trajectory, summary in (wall, stand):
        assert text_overlaps(simulation_figure(robot, trajectory, panels=summary.panels)) == []
