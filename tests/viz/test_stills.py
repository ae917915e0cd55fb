"""Recordings in a real headless browser: the task is visible, the robot stays in the frame, videos play back."""

from __future__ import annotations

import os

import numpy as np
import pytest

import robodyn
from robodyn.sim.experiment import run_simulation
from robodyn.trajectory import Trajectory
from robodyn.viz.recording import recording
from robodyn.viz.stills import capture, chromium

SIZE = (480, 360)


@pytest.fixture(autouse=True)
def _need_chromium():
    if chromium() is None:
        if os.environ.get("CI"):
            pytest.fail("Chromium is missing on CI: the Makefile's test target installs Debian's chromium")
        pytest.skip("no Chromium here (make chromium installs it)")


def red(image: np.ndarray) -> np.ndarray:  # the target marker (lit red sphere)
    r, g, b = (image[..., k].astype(int) for k in range(3))
    return (r > 110) & (g < 70) & (b < 70)


def orange(image: np.ndarray) -> np.ndarray:  # the end-effector path
    r, g, b = (image[..., k].astype(int) for k in range(3))
    return (r > 200) & (g > 120) & (g < 210) & (b < 60)


def robot_mask(image: np.ndarray) -> np.ndarray:  # RGBA with the background hidden
    return image[..., 3] > 0


@pytest.fixture(scope="module")
def demo():
    robot = robodyn.load("rp_arm")
    trajectory, summary = run_simulation(
        robot, controller="task-space", target=[0.7, 0.7], frame="end_effector", q0=[0.0, 0.1], duration=1.0, dt=2e-3
    )
    return recording(robot, trajectory, target=summary["target_m"])


@pytest.mark.slow
def test_demo_shows_robot_target_and_a_growing_path(demo):
    start, early, late = capture(demo.html, [0.0, 0.1, 0.6], size=SIZE, hide=("Axes",))
    masks = capture(demo.html, [0.1, 0.6], size=SIZE, hide=("Axes", "task", "Grid", "Background"))
    for image, mask in zip((early, late), masks, strict=True):
        assert robot_mask(mask).sum() > 800  # the robot
        # Since issue 29 the camera frames the whole motion looking at the world origin (as
        # meshcat does), so the picture is about 0.6 times as large: thresholds 80, 20, 100 -> 30, 5, 40
        assert red(image).sum() > 30  # the target marker
    assert not orange(start).any()  # the path is empty at the start,
    assert orange(early).sum() > 5
    assert orange(late).sum() > orange(early).sum() + 40  # and grew
    for mask in masks:  # negative control: the same frames with the task hidden
        assert red(mask).sum() == 0 and orange(mask).sum() == 0


def _panda_motion():
    robot = robodyn.load("panda")
    a = np.array([0.0, -0.6, 0.0, -2.2, 0.0, 1.6, 0.8, 0.01])
    b = np.array([1.2, 0.4, 0.3, -1.2, 0.5, 2.2, 0.0, 0.04])
    t = np.linspace(0.0, 2.0, 201)
    s = (1 - np.cos(np.pi * t / 2)) / 2
    q = a + s[:, None] * (b - a)
    zeros = np.zeros_like(q)
    return robot, Trajectory(t, q, zeros, zeros, zeros, robot.joint_names, "panda"), b


@pytest.mark.slow
def test_panda_whole_body_stays_in_the_frame():
    robot, trajectory, end = _panda_motion()
    made = recording(robot, trajectory, frame="panda_hand", target=robot.frame_position(end, "panda_hand"))
    frames = capture(made.html, list(np.linspace(0, made.duration, 5)), size=SIZE, hide=("Axes", "task", "Grid", "Background"))
    for frame in frames:
        mask = robot_mask(frame)
        assert mask.sum() > 2000  # the robot is drawn
        border = np.concatenate([mask[:3].ravel(), mask[-3:].ravel(), mask[:, :3].ravel(), mask[:, -3:].ravel()])
        assert not border.any(), "robot pixels touch the picture's edge"
        rows, columns = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
        assert rows.size and columns.size


@pytest.mark.slow
def test_border_check_fails_when_the_camera_is_too_close(monkeypatch):  # negative control
    import robodyn.viz.recording as module
    from robodyn.viz.scene import camera_commands

    robot, trajectory, _ = _panda_motion()

    def too_close(points):  # the camera moved to a third of its distance (it looks at the origin)
        commands = camera_commands(points)
        for command in commands:
            if command.get("property") == "position":
                command["value"] = [value / 3 for value in command["value"]]
        return commands

    monkeypatch.setattr(module, "camera_commands", too_close)
    close = recording(robot, trajectory)
    (frame,) = capture(close.html, [0.0], size=SIZE, hide=("Axes", "task", "Grid", "Background"))
    mask = robot_mask(frame)
    assert np.concatenate([mask[:3].ravel(), mask[-3:].ravel(), mask[:, :3].ravel(), mask[:, -3:].ravel()]).any()


@pytest.mark.slow
def test_mp4_and_gif_read_back(demo, tmp_path):
    import imageio.v3 as iio

    mp4 = demo.video(tmp_path / "demo.mp4", fps=10, size=(320, 240))
    frames = iio.imread(mp4, plugin="pyav") if _has_pyav() else _ffmpeg_frames(mp4)
    assert len(frames) == int(np.floor(demo.duration * 10 + 1e-9)) + 1
    assert frames[0].shape[:2] == (240, 320)
    assert np.abs(frames[0].astype(int) - frames[-1].astype(int)).mean() > 0.5  # it moves
    gif = demo.video(tmp_path / "demo.gif", fps=5, size=(160, 128))
    assert iio.imread(gif, index=None).shape[:3] == (int(np.floor(demo.duration * 5 + 1e-9)) + 1, 128, 160)


def _has_pyav() -> bool:
    try:
        import av  # noqa: F401
    except ImportError:
        return False
    return True


def _ffmpeg_frames(path) -> list[np.ndarray]:
    import imageio.v2 as imageio

    with imageio.get_reader(path, format="FFMPEG") as reader:
        return [frame for frame in reader]


@pytest.mark.slow
def test_record_command_writes_still_filmstrip_and_video(tmp_path, capsys):
    from PIL import Image

    from robodyn.cli.app import main

    robot = robodyn.load("rp_arm")
    trajectory, _ = run_simulation(
        robot, controller="task-space", target=[0.7, 0.7], frame="end_effector", q0=[0.0, 0.1], duration=1.0
    )
    trajectory.save(tmp_path / "m.npz")
    common = ["record", "rp_arm", "--trajectory", str(tmp_path / "m.npz"), "--target", "0.7,0.7"]
    assert main([*common, "--out", str(tmp_path / "a.html"), "--png", str(tmp_path / "at.png"), "--at", "0.5"]) == 0
    with Image.open(tmp_path / "at.png") as image:
        assert image.size == (800, 600)
    strip = ["--out", str(tmp_path / "b.html"), "--png", str(tmp_path / "strip.png"), "--filmstrip", "3"]
    assert main([*common, *strip, "--mp4", str(tmp_path / "m.mp4")]) == 0
    with Image.open(tmp_path / "strip.png") as image:
        assert image.size == (3 * 480, 360)
    assert (tmp_path / "m.mp4").stat().st_size > 1000
    assert "rendered 16/16 frames" in capsys.readouterr().err  # progress: 1 s at 15 fps


def test_no_working_browser_is_one_line(tmp_path, monkeypatch, capsys, demo):
    from robodyn.cli.app import main

    robot = robodyn.load("rp_arm")
    trajectory, _ = run_simulation(robot, duration=0.2)
    trajectory.save(tmp_path / "m.npz")
    command = ["record", "rp_arm", "--trajectory", str(tmp_path / "m.npz"), "--out", str(tmp_path / "m.html")]
    for browser, message in (("/nonexistent/chromium", "no Chromium found"), ("/bin/false", "did not render")):
        monkeypatch.setenv("ROBODYN_CHROMIUM", browser)
        assert main([*command, "--png", str(tmp_path / "m.png")]) == 2
        error = capsys.readouterr().err.strip()
        assert message in error and len(error.splitlines()) == 1
        assert not (tmp_path / "m.html").exists() and not (tmp_path / "m.png").exists()
    assert main([*command, "--filmstrip", "3"]) == 2
    assert "--filmstrip" in capsys.readouterr().err


# --------------------------------------------------------------------------------------
# Issue 29: Stills of a real browser: an upright arm's first frame is not cropped (issue 29,
# --------------------------------------------------------------------------------------
@pytest.mark.slow
def test_the_first_frame_of_an_upright_arm_shows_its_top():
    if chromium() is None:
        pytest.skip("no Chromium here (make chromium installs it)")
    robot = robodyn.load("ur5")
    upright = np.array([0.0, -np.pi / 2, 0.0, -np.pi / 2, 0.0, 0.0])
    t = np.linspace(0.0, 1.0, 11)
    q = upright + np.outer(t, [0.8, 0.3, 0.0, 0.0, 0.0, 0.0])
    zeros = np.zeros_like(q)
    made = recording(robot, Trajectory(t, q, zeros, zeros, zeros, robot.joint_names, robot.name))
    (frame,) = capture(made.html, [0.0], size=(480, 360), hide=("Axes", "task", "Grid", "Background"))
    mask = frame[..., 3] > 0
    assert mask.sum() > 1000  # the robot is drawn
    border = np.concatenate([mask[:3].ravel(), mask[-3:].ravel(), mask[:, :3].ravel(), mask[:, -3:].ravel()])
    assert not border.any(), "robot pixels touch the picture's edge"
