"""Every option of `robodyn record` and `robodyn view` alone, reading back what they drew, and
crossed pairwise.

``record``'s page is read back without robodyn's reader (the base64 msgpack commands it
embeds, decoded here): every link's animated position at each frame is that link's position
in the run's robot (fixed or floating) at that time, at ``--fps`` frames a second (a floating
base's orientation a unit quaternion); the path drawn is ``--frame``'s (else the end
effector's) positions; ``--target`` X,Y,Z (or X,Z: Y = 0) places the red sphere; ``--axes``
puts a triad on each link named; ``--max-mesh-mb`` turns the xacro arm's meshes into
placeholder boxes, one warning line each; ``--out -`` writes the page to standard output.
The title carries the robot's name escaped. Chromium is not needed: its options (``--png``,
``--filmstrip``, ``--mp4``, ``--gif``) are only refused here where they conflict.

``view`` is run with the live viewer replaced by one that records what it is asked to show:
the robot of the run's options, the trajectory file's motion, the target and the frame.

The robots: the oblique test robot given box visuals (it has none) and the xacro test arm
(meshes, a mimic joint, ``--xacro-arg``, ``--package``), fixed or floating (neither
command takes ``--lock``).
"""

from __future__ import annotations

import base64
import html
import re
from pathlib import Path
from typing import ClassVar

import numpy as np
import pytest
import umsgpack

import robodyn
from tests.cli.model_options import OBLIQUE, model_arguments, refused_in_one_line, robot_of, run_command
from tests.differential.cases import random_state_batch
from tests.pairwise import pairwise, uncovered_pairs

SAMPLES, RATE = 7, 30.0
#: Per model: an inner frame (``--frame``) and two links for ``--axes``.
INNER = {"oblique": "arm", "xacro": "r_upper"}
AXES = {"oblique": ("column", "ram"), "xacro": ("r_upper", "r_wrist")}

#: Each option's values; the first is the default (the option left out).
FACTORS: dict[str, tuple | list] = {
    "model": ("oblique", "xacro"),
    "base": (None, "floating"),
    "fps": (30.0, 10.0),
    "target": (None, (0.3, -0.2, 0.5), (0.4, 0.6)),
    "frame": (None, "inner"),
    "axes": (None, "two links"),
    "max_mesh_mb": (None, 1e-6),
    "out": (".html", "-"),
}
DEFAULT = {name: values[0] for name, values in FACTORS.items()}
RUNS = pairwise(FACTORS)


def test_the_runs_cover_every_pair_and_are_few():
    assert uncovered_pairs(RUNS, FACTORS) == []
    assert len(RUNS) <= 10  # not the 768 of all combinations


@pytest.fixture(scope="module")
def drawn_oblique(tmp_path_factory) -> str:
    """The oblique robot with a box visual on every link (offset from its frame)."""
    visual = '<visual><origin xyz="0.01 0.02 0.03"/><geometry><box size="0.04 0.05 0.06"/></geometry></visual></link>'
    path = tmp_path_factory.mktemp("robots") / "oblique.urdf"
    path.write_text(OBLIQUE.read_text().replace("</link>", visual))
    return str(path)


def motion_file(robot, path) -> robodyn.Trajectory:
    """A motion of ``robot`` sampled at :data:`RATE`, written to ``path``."""
    q, v, a = random_state_batch(robot, np.random.default_rng(39), SAMPLES)
    trajectory = robodyn.Trajectory(np.arange(SAMPLES) / RATE, q, v, a, v, list(robot.joint_names), robot.name)
    trajectory.save(path)
    return trajectory


def commands_of(page: str) -> list[dict]:
    """The meshcat commands a page embeds (base64 msgpack strings)."""
    found = re.search(r"var commands = \[(.*?)\];", page, re.S)
    assert found is not None
    blobs = [blob.strip().strip('"') for blob in found.group(1).split(",") if blob.strip()]
    return [umsgpack.unpackb(base64.b64decode(blob)) for blob in blobs]


def record_cli(options: dict, tmp_path, oblique: str):
    robot = robot_of(options, oblique)
    trajectory = motion_file(robot, tmp_path / "motion.csv")
    out = tmp_path / "motion.html" if options["out"] == ".html" else None
    argv = ["record", *model_arguments(options, oblique), "--trajectory", str(tmp_path / "motion.csv")]
    argv += ["--out", str(out) if out else "-"] + ([f"--fps={options['fps']:g}"] if options["fps"] != 30.0 else [])
    argv += ["--target=" + ",".join(map(str, options["target"]))] if options["target"] else []
    argv += ["--frame", INNER[options["model"]]] if options["frame"] else []
    argv += ["--axes", ",".join(AXES[options["model"]])] if options["axes"] else []
    argv += [f"--max-mesh-mb={options['max_mesh_mb']:g}"] if options["max_mesh_mb"] else []
    code, printed, error = run_command(argv)
    assert code == 0, error
    page = out.read_text() if out else printed
    return robot, trajectory, page, printed, error


def check_record(options: dict, tmp_path, oblique: str) -> list[dict]:
    robot, trajectory, page, printed, error = record_cli(options, tmp_path, oblique)
    title = re.search(r"<title>(.*)</title>", page)
    assert title is not None and title.group(1) == f"robodyn: {html.escape(robot.name)}"
    commands = commands_of(page)
    by_path: dict[str, list[dict]] = {}
    for command in commands:
        by_path.setdefault(command.get("path", ""), []).append(command)
    # Every link at every frame: at the run's robot's pose of that time.
    (animation,) = (c for c in commands if c["type"] == "set_animation")
    step = round(RATE / options["fps"])
    frames = (SAMPLES - 1) // step + 1
    links = 0
    for entry in animation["animations"]:
        name = entry["path"].removeprefix("/robodyn/")
        if entry["path"].startswith("/task/"):
            continue
        tracks = {track["name"]: track["keys"] for track in entry["clip"]["tracks"]}
        assert entry["clip"]["fps"] == options["fps"] and len(tracks[".position"]) == frames
        positions = np.array([key["value"] for key in tracks[".position"]])
        np.testing.assert_allclose(positions, robot.frame_position(trajectory.q[::step], name), atol=1e-9, err_msg=name)
        quaternions = np.array([key["value"] for key in tracks[".quaternion"]])
        np.testing.assert_allclose(np.linalg.norm(quaternions, axis=1), 1.0, atol=1e-12)
        links += 1
    assert links >= 4
    # The path of the frame asked for (else the end effector).
    frame = INNER[options["model"]] if options["frame"] else robot.end_effector
    drawn = [c for path, found in by_path.items() if path.endswith("/line") for c in found]
    points = np.vstack([_positions(c) for c in drawn])
    expected = robot.frame_position(trajectory.q, frame)
    assert max(np.abs(points - p).max(axis=1).min() for p in expected) <= 1e-6  # every sample is drawn
    assert max(np.abs(expected - p).max(axis=1).min() for p in points) <= 1e-6  # and nothing else
    # The target, the triads, the placeholders, where the page went.
    if options["target"]:
        x, *y, z = options["target"]
        (placed,) = (c for c in by_path["/task/target"] if c["type"] == "set_transform")
        np.testing.assert_allclose(placed["matrix"][12:15], [x, y[0] if y else 0.0, z])
    else:
        assert "/task/target" not in by_path
    triads = {path for path in by_path if path.endswith("/axes")}
    assert triads == ({f"/robodyn/{link}/axes" for link in AXES[options["model"]]} if options["axes"] else set())
    warnings = [line for line in error.splitlines() if "placeholder box" in line]
    meshes = options["model"] == "xacro" and options["max_mesh_mb"]
    assert len(warnings) == (4 if meshes else 0) and all(line.startswith("robodyn: warning: ") for line in warnings)
    headline = printed if options["out"] == ".html" else error
    duration = (frames - 1) * step / RATE
    assert f"s at {options['fps']:g} fps" in headline and f"MB, {duration:.3g} s" in headline
    assert ("wrote standard output" in headline) == (options["out"] == "-")
    return commands


def _positions(command: dict) -> np.ndarray:
    array = command["object"]["geometries"][0]["data"]["attributes"]["position"]["array"]
    return np.frombuffer(array.data, dtype=np.float32).reshape(-1, 3).astype(float)


ALONE = [(name, value) for name, values in FACTORS.items() for value in values[1:]]


@pytest.mark.parametrize(("option", "value"), ALONE, ids=[f"{name}={value}" for name, value in ALONE])
def test_each_record_option_alone_draws_what_it_says(option, value, tmp_path, drawn_oblique):
    check_record(DEFAULT | {option: value}, tmp_path, drawn_oblique)


@pytest.mark.slow
@pytest.mark.parametrize("run", RUNS[1:], ids=[str(k) for k in range(1, len(RUNS))])
def test_record_options_crossed_pairwise_draw_the_motion(run, tmp_path, drawn_oblique):
    check_record(run, tmp_path, drawn_oblique)


def test_the_title_carries_the_robots_name_escaped(tmp_path, drawn_oblique):
    hostile = tmp_path / 'o<b>&"x.urdf'
    hostile.write_text(Path(drawn_oblique).read_text())
    robot = robodyn.load(hostile)
    motion_file(robot, tmp_path / "m.csv")
    code, _, error = run_command(
        ["record", str(hostile), "--trajectory", str(tmp_path / "m.csv"), "--out", str(tmp_path / "m.html")]
    )
    assert code == 0, error
    page = (tmp_path / "m.html").read_text()
    assert "<title>robodyn: o&lt;b&gt;&amp;&quot;x</title>" in page and "<b>" not in page


def test_what_record_cannot_do_is_one_line(tmp_path, drawn_oblique):
    robot = robodyn.load(drawn_oblique)
    motion_file(robot, tmp_path / "m.csv")
    common = ["record", drawn_oblique, "--trajectory", str(tmp_path / "m.csv"), "--out", str(tmp_path / "m.html")]
    refused_in_one_line([*common, "--filmstrip", "4"], "--filmstrip", "--png")
    refused_in_one_line([*common, "--png", str(tmp_path / "s.png"), "--filmstrip", "4", "--at", "0.1"], "--at", "--filmstrip")
    refused_in_one_line([*common, "--max-mesh-mb", "0"], "--max-mesh-mb")
    refused_in_one_line([*common, "--axes", "nowhere"], "nowhere")
    refused_in_one_line([*common, "--target", "1,2,3,4"], "target")
    assert not (tmp_path / "m.html").exists()


# --------------------------------------------------------------------------------------
# robodyn view: the live viewer replaced by one that records what it is asked to show
# --------------------------------------------------------------------------------------
VIEW: dict[str, tuple | list] = {
    "model": ("oblique", "xacro"),
    "base": (None, "floating"),
    "trajectory": (False, True),
    "target": (None, (0.3, -0.2, 0.5)),
    "frame": (None, "inner"),
    "seconds": (None, 0.5),
}
VIEW_DEFAULT = {name: values[0] for name, values in VIEW.items()}
VIEW_RUNS = pairwise(VIEW)


class ShowingViewer:
    """What ``robodyn view`` asked the live viewer to show, and how long it waited."""

    shown: ClassVar[list] = []
    url = "http://127.0.0.1:7000/static/"

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False

    def show(self, robot, trajectory, *, target=None, frame=None):
        self.shown.append((robot, trajectory, target, frame))


def check_view(options: dict, tmp_path, monkeypatch) -> None:
    import robodyn.viz.live as live

    waited: list = []
    monkeypatch.setattr(ShowingViewer, "shown", [])
    monkeypatch.setattr(live, "LiveViewer", ShowingViewer)
    monkeypatch.setattr(live, "wait", waited.append)
    robot = robot_of(options)
    argv = ["view", *model_arguments(options)]
    if options["trajectory"]:
        trajectory = motion_file(robot, tmp_path / "m.csv")
        argv += ["--trajectory", str(tmp_path / "m.csv")]
    argv += ["--target=" + ",".join(map(str, options["target"]))] if options["target"] else []
    argv += ["--frame", INNER[options["model"]]] if options["frame"] else []
    argv += ["--seconds", str(options["seconds"])] if options["seconds"] else []
    code, printed, error = run_command(argv)
    assert code == 0, error
    ((shown, motion, target, frame),) = ShowingViewer.shown
    assert printed == f"meshcat viewer: {ShowingViewer.url}  (Ctrl-C to stop)\n" and waited == [options["seconds"]]
    assert shown.configuration_names == robot.configuration_names and shown.floating_base == robot.floating_base
    assert shown.total_mass == pytest.approx(robot.total_mass, rel=1e-12)  # the xacro arm's upper_mass:=2.1
    if options["trajectory"]:
        np.testing.assert_array_equal(motion.q, trajectory.q)
        np.testing.assert_array_equal(motion.t, trajectory.t)
    else:
        assert motion is None
    assert target == (list(options["target"]) if options["target"] else None)
    assert frame == (INNER[options["model"]] if options["frame"] else None)


def test_the_view_runs_cover_every_pair_and_are_few():
    assert uncovered_pairs(VIEW_RUNS, VIEW) == []
    assert len(VIEW_RUNS) <= 8


VIEW_ALONE = [(name, value) for name, values in VIEW.items() for value in values[1:]]


@pytest.mark.parametrize(("option", "value"), VIEW_ALONE, ids=[f"{n}={v}" for n, v in VIEW_ALONE])
def test_each_view_option_alone_reaches_the_viewer(option, value, tmp_path, monkeypatch):
    check_view(VIEW_DEFAULT | {option: value}, tmp_path, monkeypatch)


@pytest.mark.slow
@pytest.mark.parametrize("run", VIEW_RUNS, ids=[str(k) for k in range(len(VIEW_RUNS))])
def test_view_options_crossed_pairwise_reach_the_viewer(run, tmp_path, monkeypatch):
    check_view(run, tmp_path, monkeypatch)
