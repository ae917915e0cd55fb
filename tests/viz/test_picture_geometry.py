"""The README's poster and filmstrip, checked by what their recording draws.

The PNGs are Chromium's screenshots of the demo's recording (``scripts/make_pictures.py``);
``tests/integration/test_pictures.py``'s hash of the drawing code only reminds to make them
again. Here the recording itself is checked against the robot: every link's animated pose
at every frame is where Pinocchio puts it at the trajectory interpolated to that frame's
time; the red target marker sits at the demo's target; the orange path is the end
effector's positions, from the first to the last, revealed in frame order.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import robodyn
from robodyn.sim.experiment import run_simulation
from robodyn.viz.recording import motion_commands

FPS = 30.0


@pytest.fixture(scope="module")
def demo():
    robot = robodyn.load("rp_arm")
    trajectory, summary = run_simulation(
        robot, controller="task-space", target=[0.7, 0.7], frame="end_effector", q0=[0.0, 0.1], duration=1.0
    )
    commands, _, _ = motion_commands(robot, trajectory, fps=FPS, target=summary["target_m"])
    clips = {entry["path"]: entry["clip"] for entry in commands[-1]["animations"]}
    return robot, trajectory, summary, commands, clips


def track(clip: dict, name: str) -> np.ndarray:
    (found,) = [t for t in clip["tracks"] if t["name"] == name]
    assert [key["time"] for key in found["keys"]] == list(range(len(found["keys"])))
    return np.array([key["value"] for key in found["keys"]], dtype=float)


def placements_at(robot: robodyn.Robot, trajectory, frames: int) -> list[dict[str, pin.SE3]]:
    """Each link's world placement at each frame's time (joint values interpolated linearly)."""
    times = trajectory.t[0] + np.arange(frames) / FPS
    q = np.column_stack([np.interp(times, trajectory.t, trajectory.q[:, i]) for i in range(robot.nq)])
    model, data = robot.model, robot.model.createData()
    out = []
    for row in q:
        pin.framesForwardKinematics(model, data, row)
        out.append({link: data.oMf[model.getFrameId(link)].copy() for link in robot.spec.links if model.existFrame(link)})
    return out


def test_every_link_is_drawn_where_the_robot_is_at_every_frame(demo):
    robot, trajectory, _, _, clips = demo
    links = [link for link in robot.spec.links if f"/robodyn/{link}" in clips]
    assert len(links) == len(robot.spec.links)
    frames = len(track(clips[f"/robodyn/{links[0]}"], ".position"))
    assert frames == int(np.floor((trajectory.t[-1] - trajectory.t[0]) * FPS + 1e-9)) + 1
    expected = placements_at(robot, trajectory, frames)
    moved = 0.0
    for link in links:
        positions = track(clips[f"/robodyn/{link}"], ".position")
        quaternions = track(clips[f"/robodyn/{link}"], ".quaternion")  # x, y, z, w
        for frame, placement in enumerate(expected):
            assert np.abs(positions[frame] - placement[link].translation).max() < 1e-9
            x, y, z, w = quaternions[frame]
            drawn = pin.Quaternion(w, x, y, z).toRotationMatrix()
            assert abs(np.linalg.norm(quaternions[frame]) - 1) < 1e-12
            assert np.abs(drawn - placement[link].rotation).max() < 1e-9
        moved = max(moved, float(np.ptp(positions, axis=0).max()))
    assert moved > 0.1  # the arm moves in the picture: a still robot would pass the loop above
    # Negative control: the poses one frame late are not the drawn ones.
    end = track(clips["/robodyn/end_effector"], ".position")
    assert np.abs(end[1:] - np.array([p["end_effector"].translation for p in expected[:-1]])).max() > 1e-3


def test_the_target_marker_sits_at_the_demos_target(demo):
    _, _, summary, commands, _ = demo
    (marker,) = [c for c in commands if c["type"] == "set_transform" and c["path"] == "/task/target"]
    matrix = np.array(marker["matrix"], dtype=float).reshape(4, 4).T  # column-major, as three.js reads it
    np.testing.assert_allclose(matrix[:3, 3], summary["target_m"], atol=1e-12)
    np.testing.assert_allclose(matrix[:3, :3], np.eye(3), atol=1e-12)


def path_points(command: dict) -> np.ndarray:
    position = command["object"]["geometries"][0]["data"]["attributes"]["position"]
    return np.frombuffer(position["array"].data, dtype=np.float32).reshape(-1, 3).astype(float)


def test_the_path_is_the_end_effectors_revealed_in_order(demo):
    robot, trajectory, _, commands, clips = demo
    effector = robot.frame_position(trajectory.q, "end_effector")
    segments = sorted(c["path"] for c in commands if c["type"] == "set_object" and c["path"].endswith("/dots"))
    assert len(segments) > 5
    drawn = [path_points(next(c for c in commands if c.get("path") == path and c["type"] == "set_object")) for path in segments]
    for points in drawn:  # float32 vertices: within 1e-6 m of a sample's end effector
        distance = np.linalg.norm(points[:, None, :] - effector[None, :, :], axis=2).min(axis=1)
        assert distance.max() < 1e-6
    np.testing.assert_allclose(drawn[0][0], effector[0], atol=1e-6)
    np.testing.assert_allclose(drawn[-1][-1], effector[-1], atol=1e-6)
    on_times = [  # the frame each later segment turns visible: in order, within the motion
        int(next(key["time"] for key in t["keys"] if key["value"]))
        for path in segments[1:]
        for t in clips[path.removesuffix("/dots")]["tracks"]
    ]
    assert len(on_times) == len(segments) - 1 and on_times == sorted(on_times) and on_times[0] > 0
    assert on_times[-1] <= (trajectory.t[-1] - trajectory.t[0]) * FPS + 1
