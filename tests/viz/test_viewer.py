"""Recordings and the live viewer; the recording tested in a real (headless) browser."""

from __future__ import annotations

import base64
import os
import re
import signal
import socket
import subprocess
import sys
import time
import urllib.request

import numpy as np
import pytest
import umsgpack

import robodyn
from robodyn import RobodynError
from robodyn.cli.app import main
from robodyn.sim.simulation import simulate
from robodyn.trajectory import Trajectory
from robodyn.viz.viewer import capture, chromium, record, screenshot
from tests.conftest import ROOT


def commands_of(html: str) -> list[dict]:
    blobs = re.search(r"var commands = \[(.*?)\];", html, re.S).group(1)
    return [umsgpack.unpackb(base64.b64decode(blob.strip().strip('"'))) for blob in blobs.split(",") if blob.strip()]


@pytest.fixture(scope="module")
def swinging():
    robot = robodyn.load("pendulum")
    return robot, simulate(robot, np.array([1.2, -0.5]), np.zeros(2), 3.0, 2e-3)


def test_recording_is_self_contained_and_sends_each_shape_once(swinging, tmp_path):
    robot, trajectory = swinging
    short = Trajectory(
        trajectory.t[:250],
        trajectory.q[:250],
        trajectory.v[:250],
        trajectory.a[:250],
        trajectory.tau[:250],
        trajectory.joint_names,
        "pendulum",
    )
    counts = []
    for name, motion in (("long", trajectory), ("short", short)):
        html = record(robot, motion, tmp_path / f"{name}.html").read_text()
        assert "MeshCat.Viewer" in html and "http://" not in html.split("<script>")[0]
        commands = commands_of(html)
        counts.append(sum(c["type"] == "set_object" and c["path"].startswith("/robodyn/") for c in commands))
        animation = [c for c in commands if c["type"] == "set_animation"]
        assert len(animation) == 1 and animation[0]["options"]["play"] is True
        keys = animation[0]["animations"][0]["clip"]["tracks"][0]["keys"]
        assert len(keys) == int(np.floor(motion.t[-1] * 30 + 1e-9)) + 1
    assert counts[0] == counts[1] == 2  # the two rods, whatever the number of frames


def test_zoo_meshes_are_embedded(tmp_path):
    robot = robodyn.load("ur5")
    trajectory = Trajectory(
        np.array([0.0, 0.1]), np.zeros((2, 6)), np.zeros((2, 6)), np.zeros((2, 6)), np.zeros((2, 6)), robot.joint_names, "ur5"
    )
    commands = commands_of(record(robot, trajectory, tmp_path / "ur5.html").read_text())
    meshes = [c for c in commands if c["type"] == "set_object" and c["path"].startswith("/robodyn/")]
    assert len(meshes) == 7 and all(c["object"]["geometries"][0]["type"] == "_meshfile" for c in meshes)


def test_failed_recording_leaves_the_old_file(tmp_path, swinging):
    robot, trajectory = swinging
    target = tmp_path / "motion.html"
    target.write_text("old")
    empty = Trajectory(np.zeros(0), np.zeros((0, 2)), np.zeros((0, 2)), np.zeros((0, 2)), np.zeros((0, 2)))
    with pytest.raises(RobodynError, match="empty"):
        record(robot, empty, target)
    wrong = Trajectory(trajectory.t, trajectory.q[:, :1], trajectory.v, trajectory.a, trajectory.tau)
    with pytest.raises(RobodynError, match="needs 2"):
        record(robot, wrong, target)
    assert target.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["motion.html"]  # no temporary left behind


def test_record_command(tmp_path, swinging, capsys):
    _robot, trajectory = swinging
    trajectory.save(tmp_path / "swing.npz")
    assert main(["record", "pendulum", "--trajectory", str(tmp_path / "swing.npz"), "--out", str(tmp_path / "swing.html")]) == 0
    assert "wrote" in capsys.readouterr().out and (tmp_path / "swing.html").stat().st_size > 100_000


def _port_open(url: str) -> bool:
    host, port = re.search(r"//([\d.]+):(\d+)/", url).groups()
    with socket.socket() as probe:
        probe.settimeout(1)
        return probe.connect_ex((host, int(port))) == 0


@pytest.mark.parametrize("stop", [signal.SIGTERM, signal.SIGINT])
def test_live_viewer_listens_on_localhost_and_leaves_no_server(stop):
    process = subprocess.Popen(
        [sys.executable, "-m", "robodyn.cli.app", "view", "rp_arm", "--seconds", "60"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=ROOT,
    )
    try:
        line = process.stdout.readline()
        url = re.search(r"(http://\S+)", line).group(1)
        assert url.startswith("http://127.0.0.1:")
        with urllib.request.urlopen(url, timeout=10) as page:
            assert page.status == 200 and b"meshcat" in page.read().lower()
        process.send_signal(stop)
        assert process.wait(timeout=20) == 0
        deadline = time.monotonic() + 10
        while _port_open(url) and time.monotonic() < deadline:
            time.sleep(0.2)
        assert not _port_open(url), "the meshcat server outlived robodyn"
    finally:
        if process.poll() is None:
            process.kill()


def _need_chromium():
    if chromium() is None:
        if os.environ.get("CI"):
            pytest.fail("Chromium is missing on CI: the Makefile's test target installs Debian's chromium")
        pytest.skip("no Chromium here (make test installs it)")


def _drawn_pixels(png_or_image) -> np.ndarray:
    import matplotlib.image

    image = png_or_image / 255.0 if isinstance(png_or_image, np.ndarray) else matplotlib.image.imread(png_or_image)[..., :3]
    # The background is a vertical blue gradient: compare each pixel with its row's mode.
    background = np.median(image, axis=1, keepdims=True)
    return np.abs(image - background).sum(axis=2) > 0.15


@pytest.mark.slow  # tests/viz/test_stills.py keeps a browser test in the fast tier
def test_recording_plays_in_a_real_browser(swinging, tmp_path):
    _need_chromium()
    robot, trajectory = swinging
    html = record(robot, trajectory, tmp_path / "swing.html", png=tmp_path / "poster.png")
    early, late = capture(html, [0.3, 1.3], size=(800, 600))
    drawn_early, drawn_late = _drawn_pixels(early), _drawn_pixels(late)
    assert drawn_early.sum() > 500 and drawn_late.sum() > 500  # the robot is drawn
    assert (drawn_early ^ drawn_late).sum() > 300  # and it moved
    assert _drawn_pixels(tmp_path / "poster.png").sum() > 500
    screenshot(html, tmp_path / "again.png", at_seconds=0.3)  # the file-based still is the same frame
    assert np.array_equal(_drawn_pixels(tmp_path / "again.png"), drawn_early)
