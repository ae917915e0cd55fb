"""robot_html (for Robot._repr_html_) and Recording._repr_html_: escaped, complete."""

from __future__ import annotations

import html.parser

import numpy as np
import pytest

import robodyn
from robodyn.cli import main
from robodyn.dynamics.display import robot_html
from robodyn.exceptions import InputError
from robodyn.trajectory import Trajectory
from robodyn.viz.recording import MAX_FRAMES, frame_count, record, recording

HOSTILE = """<robot name="r&lt;script&gt;alert(1)&lt;/script&gt;">
  <link name="base"/>
  <link name="l&lt;b&gt;1"><inertial><mass value="1.5"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><box size="0.1 0.2 0.3"/></geometry></visual></link>
  <joint name="j&quot;&gt;&lt;img src=x onerror=alert(2)&gt;" type="prismatic"><parent link="base"/><child link="l&lt;b&gt;1"/>
    <axis xyz="0 0.6 0.8"/><limit lower="-0.25" upper="0.5" effort="40" velocity="1"/></joint>
</robot>"""


class _Tags(html.parser.HTMLParser):
    def __init__(self):
        super().__init__()
        self.tags, self.cells = [], []

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)

    def handle_data(self, data):
        self.cells.append(data)


def _parse(text: str) -> _Tags:
    parser = _Tags()
    parser.feed(text)
    return parser


def test_robot_html_escapes_names_and_lists_joints():
    robot = robodyn.load(HOSTILE)
    parsed = _parse(robot_html(robot))
    assert "script" not in parsed.tags and "img" not in parsed.tags
    text = "|".join(parsed.cells)
    assert "<img src=x onerror=alert(2)>" in text and "<script>" in text  # shown as text
    assert "prismatic" in text and "-0.25 m … 0.5 m" in text and "40 N" in text and "1.5 kg" in text


def test_robot_html_on_zoo_robots():
    for name in ("panda", "ur5"):
        robot = robodyn.load(name)
        parsed = _parse(robot_html(robot))
        assert parsed.tags.count("tr") == len(robot.joints) + 1
        assert "N m" in "".join(parsed.cells)
    solo = robodyn.load("solo12", floating_base=True)
    assert "floating" in robot_html(solo)


def test_recording_repr_html_is_one_sandboxed_iframe():
    robot = robodyn.load(HOSTILE)
    t = np.linspace(0, 0.5, 6)
    q = np.linspace(0, 0.3, 6)[:, None]
    made = recording(robot, Trajectory(t, q, 0 * q, 0 * q, 0 * q, robot.joint_names, robot.name))
    parsed = _parse(made._repr_html_())
    assert parsed.tags == ["iframe"]
    assert "<title>robodyn: r&lt;script&gt;" in made.html


def test_axes_ride_on_their_links():
    from robodyn import FrameError
    from tests.viz.test_viewer import commands_of

    robot = robodyn.load("rp_arm")
    t = np.linspace(0, 0.5, 6)
    q = np.column_stack([np.linspace(0, 0.3, 6), np.full(6, 0.1)])
    motion = Trajectory(t, q, 0 * q, 0 * q, 0 * q, robot.joint_names, robot.name)
    made = recording(robot, motion, axes=("end_effector",))
    paths = [c["path"] for c in commands_of(made.html) if c["type"] == "set_object"]
    assert "/robodyn/end_effector/axes" in paths
    import pytest

    with pytest.raises(FrameError, match="no frame named 'nowhere'"):
        recording(robot, motion, axes=("nowhere",))


# --------------------------------------------------------------------------------------
# Issue 29: Recordings bound their frames before allocating them (issue 29, item 7).
# --------------------------------------------------------------------------------------
def _motion(robot, end: float) -> Trajectory:
    t = np.array([0.0, 0.5, end])
    q = np.array([[0.0, 0.0], [0.3, 0.1], [0.5, 0.2]])
    return Trajectory(t, q, np.zeros_like(q), np.zeros_like(q), np.zeros_like(q), robot.joint_names, robot.name)


def test_the_frame_count_is_the_span_times_fps_and_bounded():
    robot = robodyn.load("rp_arm")
    assert frame_count(_motion(robot, 2.0), 30.0) == 61
    assert frame_count(_motion(robot, (MAX_FRAMES - 1) / 30.0), 30.0) == MAX_FRAMES
    with pytest.raises(InputError, match="trajectory") as raised:
        frame_count(_motion(robot, 1e9), 30.0)
    assert "3e+10 frames" in str(raised.value) and "\n" not in str(raised.value)
    assert raised.value.argument == "trajectory" and f"at most {MAX_FRAMES} animation frames" in str(raised.value)
    late = _motion(robot, 2.0)
    shifted = Trajectory(late.t + 100.0, late.q, late.v, late.a, late.tau, late.joint_names, late.robot)
    assert frame_count(shifted, 30.0) == 61  # the span, not the end time
    empty = Trajectory(np.zeros(0), *(np.zeros((0, 2)),) * 4, robot.joint_names, robot.name)
    assert frame_count(empty, 30.0) == 1
    with pytest.raises(robodyn.RobodynError, match="empty"):  # the one-line refusal, no IndexError
        recording(robot, empty)
    with pytest.raises(InputError, match="trajectory"):
        recording(robot, _motion(robot, MAX_FRAMES / 30.0), fps=30.0)


def test_record_of_a_trajectory_ending_at_1e9_s_is_one_line(tmp_path, capsys):
    robot = robodyn.load("rp_arm")
    _motion(robot, 1e9).save(tmp_path / "long.csv")
    code = main(["record", "rp_arm", "--trajectory", str(tmp_path / "long.csv"), "--out", str(tmp_path / "m.html")])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "frames" in err
    assert not (tmp_path / "m.html").exists()


def test_the_poster_is_the_motions_last_frame_with_its_path_unless_a_time_is_given(tmp_path, monkeypatch, capsys):
    """``--png`` shows the motion (the final pose, the whole path drawn), not the robot at
    rest before it; an explicit time still picks its frame."""
    from robodyn.viz.recording import Recording

    asked: list[float] = []
    monkeypatch.setattr(Recording, "still", lambda self, png, *, at=0.0, size=(800, 600): asked.append(at))
    argv = ["simulate", "rp_arm", "--controller", "task-space", "--q0", "0,0.1", "--target", "0.7,0.7", "--duration", "1.5"]
    assert main([*argv, "--record", str(tmp_path / "m.html"), "--png", str(tmp_path / "m.png")]) == 0
    assert asked == [pytest.approx(1.5)]
    robot = robodyn.load("rp_arm")
    t = np.linspace(0.0, 2.0, 21)
    trajectory = Trajectory(t, np.column_stack([t, 0.1 + 0 * t]), np.zeros((21, 2)), np.zeros((21, 2)))
    record(robot, trajectory, tmp_path / "r.html", png=tmp_path / "r.png", at=0.5)
    assert asked[-1] == 0.5
