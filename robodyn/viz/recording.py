"""Self-contained HTML recordings of a motion, and the :class:`Recording` behind them.

A recording is one HTML file: meshcat's viewer inlined, the scene (robot, ground grid,
target, growing end-effector path) and the animation embedded as msgpack commands. It
plays once on open, offline, in any browser; meshcat's controls (top right, "Open
Controls" → Animations) play, pause and scrub it.

The page also answers a capture request in its URL fragment, which the stills and videos
of :mod:`robodyn.viz.stills` use: ``#size=WxH&hide=A,B&capture=T1,T2,...`` hides the named
top-level nodes (``task``, ``Axes``, ``Grid``, ``Background``: then the PNG is transparent
where nothing is drawn), pauses the animation, seeks each time, renders at W×H, and writes
the frames as PNG data URLs into ``<pre id="frames">``.
Each command runs in its own ``try``: a command the browser cannot handle is counted in
the title ("N commands failed") and the rest is still drawn.
"""

from __future__ import annotations

import base64
import html as html_escape
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import umsgpack

from robodyn.common.files import atomic_write_text
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import InputError, RobodynError, ViewerError
from robodyn.trajectory import Trajectory
from robodyn.viz.drawings import drawing_commands
from robodyn.viz.mesh_files import MAX_MESH_BYTES
from robodyn.viz.scene import build_scene, camera_commands, lower_animation, motion, pose_commands
from robodyn.viz.task import axis_commands, force_commands, target_pose_commands, task_commands

_PAGE = """<!DOCTYPE html>
<html>
<head><meta charset="utf-8"><title>{title}</title>
<style>body {{ margin: 0; }} #meshcat-pane {{ width: 100vw; height: 100vh; overflow: hidden; }}
#frames {{ display: none; }}</style></head>
<body>
<div id="meshcat-pane"></div>
<pre id="frames"></pre>
<script>{script}</script>
<script>
var viewer = new MeshCat.Viewer(document.getElementById("meshcat-pane"));
var commands = [{blobs}];
var failed = 0;
for (var i = 0; i < commands.length; ++i) {{
  try {{
    var bytes = Uint8Array.from(atob(commands[i]), function (c) {{ return c.charCodeAt(0); }});
    viewer.handle_command_bytearray(bytes);
  }} catch (error) {{ failed += 1; console.error("robodyn: command " + i + " failed: " + error); }}
}}
var request = /capture=([0-9.,e+-]+)/.exec(location.hash);
function robodyn_capture() {{
  var gui = document.querySelector(".dg.ac");
  if (gui) {{ gui.style.display = "none"; }}
  if (viewer.animator.actions.length) {{ viewer.animator.pause(); }}
  var hide = /hide=([A-Za-z,]+)/.exec(location.hash);
  if (hide) {{ hide[1].split(",").forEach(function (name) {{ viewer.set_property([name], "visible", false); }}); }}
  var size = /size=([0-9]+)x([0-9]+)/.exec(location.hash);
  if (size) {{ viewer.set_3d_pane_size(parseInt(size[1]), parseInt(size[2])); }}
  var frames = request[1].split(",").map(function (t) {{
    if (viewer.animator.actions.length) {{ viewer.animator.seek(parseFloat(t)); }}
    return viewer.capture_image();
  }});
  document.getElementById("frames").textContent = frames.join("\\n");
}}
if (request) {{ window.addEventListener("load", function () {{ setTimeout(robodyn_capture, 200); }}); }}
document.title = "{title} (" + (failed ? failed + " commands failed" : "ready") + ")";
</script>
</body>
</html>
"""


def page(commands: list[dict], *, title: str = "robodyn recording") -> str:
    """The HTML page of meshcat commands (meshcat's viewer inlined).

    Args:
        commands: Meshcat commands (lowered to dicts), played in order.
        title: The page's title.
    """
    import meshcat

    script = (Path(meshcat.__file__).parent / "viewer" / "dist" / "main.min.js").read_text(encoding="utf-8")
    blobs = ",\n".join(f'"{base64.b64encode(umsgpack.packb(command)).decode("ascii")}"' for command in commands)
    return _PAGE.format(title=html_escape.escape(title), script=script, blobs=blobs)


@dataclass
class Recording:
    """A motion drawn for the browser: the HTML page and what it shows.

    Attributes:
        html: The self-contained page.
        duration: Length of the animation in [s].
        fps: Frames per second of the animation.
        robot: The robot's name.
        placeholders: Meshes drawn as placeholder boxes (why), empty when all were drawn.
    """

    html: str
    duration: float
    fps: float
    robot: str
    placeholders: list[str]

    def save(self, path: str | os.PathLike) -> Path | None:
        """Write the page (atomically) and return its path (``None`` for standard output, ``-``).

        Args:
            path: The HTML file to write, or ``"-"`` for standard output.
        """
        return atomic_write_text(path, self.html)

    def _repr_html_(self) -> str:
        """The animation inline in a notebook (an ``iframe`` holding the page)."""
        return (
            f'<iframe srcdoc="{html_escape.escape(self.html, quote=True)}" '
            'style="width: 100%; height: 480px; border: 0;" sandbox="allow-scripts"></iframe>'
        )

    def still(self, png: str | os.PathLike, *, at: float = 0.0, size: tuple[int, int] = (800, 600)) -> Path | None:
        """A PNG of the frame at ``at`` seconds (headless Chromium); ``None`` for ``-``.

        Args:
            png: The PNG file to write, or ``"-"`` for standard output.
            at: Time into the motion in [s], from 0 to :attr:`duration`.
            size: Width and height in pixels.
        """
        from robodyn.viz.stills import still_of_page

        return still_of_page(self.html, png, at=self._time(at), size=size)

    def filmstrip(self, png: str | os.PathLike, count: int, *, size: tuple[int, int] = (480, 360)) -> Path | None:
        """``count`` frames evenly spread over the motion, side by side in one PNG; ``None`` for ``-``.

        Args:
            png: The PNG file to write, or ``"-"`` for standard output.
            count: Number of frames, 1 to 60.
            size: Width and height of each frame in pixels.
        """
        from robodyn.viz.stills import filmstrip_of_page

        return filmstrip_of_page(self.html, png, self.duration, count, size=size)

    def video(self, path: str | os.PathLike, *, fps: float = 15.0, size: tuple[int, int] = (640, 480)) -> Path:
        """An MP4 or GIF (by extension) of the motion at ``fps`` frames per second.

        Args:
            path: The ``.mp4`` or ``.gif`` file to write.
            fps: Frames per second of the video.
            size: Width and height in pixels.
        """
        from robodyn.viz.stills import video_of_page

        return video_of_page(self.html, path, self.duration, fps=fps, size=size)

    def _time(self, at: float) -> float:
        if not (np.isfinite(at) and 0.0 <= at <= self.duration + 1e-9):
            raise InputError("at", f"within the motion, 0 to {self.duration:g} s", f"{at:g}")
        return float(at)


def _target(target) -> np.ndarray | None:
    if target is None:
        return None
    from robodyn.sim.experiment import task_target

    return task_target(np.asarray(target, dtype=float))


def _path_points(robot: Robot, trajectory: Trajectory, frame: str, fps: float) -> tuple[np.ndarray, np.ndarray]:
    """End-effector positions at (at most 2000 of) the trajectory's samples, and their frames."""
    step = max(1, len(trajectory) // 2000)
    q = trajectory.q[::step]
    if robot.floating_base:
        q = q.copy()
        q[:, 3:7] /= np.linalg.norm(q[:, 3:7], axis=1, keepdims=True)
    positions = np.atleast_2d(robot.frame_position(q, frame))
    return positions, np.round((trajectory.t[::step] - trajectory.t[0]) * fps)


#: Most animation frames a recording holds (about 55 minutes at 30 fps): each frame stores
#: every link's pose, so a longer span × fps would exhaust memory before the page is written.
MAX_FRAMES = 100_000


def frame_count(trajectory: Trajectory, fps: float) -> int:
    """Frames of the animation of ``trajectory`` at ``fps``: ``⌊span × fps⌋ + 1``.

    Args:
        trajectory: The motion to animate.
        fps: Animation frames per second.

    Raises:
        InputError: Naming ``trajectory`` when its time span × ``fps`` exceeds
            :data:`MAX_FRAMES` (checked before anything is allocated).
    """
    span = float(trajectory.t[-1] - trajectory.t[0]) if len(trajectory) else 0.0
    frames = span * fps
    if not (np.isfinite(frames) and frames < MAX_FRAMES):
        raise InputError(
            "trajectory",
            f"at most {MAX_FRAMES} animation frames (time span × fps; a lower fps or a shorter span)",
            f"{span:g} s × {fps:g} fps = {frames:.3g} frames",
        )
    return int(np.floor(frames + 1e-9)) + 1


def motion_commands(
    robot: Robot,
    trajectory: Trajectory,
    *,
    fps: float = 30.0,
    target=None,
    frame: str | None = None,
    axes: tuple[str, ...] = (),
    max_mesh_bytes: int = MAX_MESH_BYTES,
    target_rotation: np.ndarray | None = None,
    forces: tuple = (),
    drawings: tuple = (),
) -> tuple[list[dict], float, list[str]]:
    """The meshcat commands of a motion with its task (see :func:`recording`).

    Returns:
        The commands, the animation's length in [s], and the placeholder reasons.
    """
    if trajectory.q.ndim != 2 or trajectory.q.shape[1] != robot.nq:
        raise ViewerError(f"the trajectory has {trajectory.q.shape[-1]} coordinates a sample; {robot.name} needs {robot.nq}.")
    if not (np.isfinite(fps) and 0 < fps <= 240):
        raise ViewerError(f"fps must lie in (0, 240], got {fps}.")
    frame_count(trajectory, fps)
    scene = build_scene(robot, max_mesh_bytes=max_mesh_bytes)
    if not scene.commands:
        raise ViewerError(f"robot {robot.name!r} has no visual geometry robodyn can draw: the recording would be empty.")
    moved, clips = motion(robot, trajectory, fps)
    target_m = _target(target)
    if frame is None:
        try:
            frame = robot.end_effector
        except RobodynError:
            frame = None
    path = frames = None
    if frame is not None:
        path, frames = _path_points(robot, trajectory, frame, fps)
    points = moved.points(scene)
    framed = np.vstack([points, *([target_m[None]] if target_m is not None else [])])
    task, task_clips = task_commands(points, target=target_m, path=path, path_frames=frames, fps=fps)
    if target_m is not None and target_rotation is not None:
        task += target_pose_commands(target_m, np.asarray(target_rotation, dtype=float), points)
    arrows, arrow_clips = force_commands(robot, moved.times, moved.configurations, forces, points, fps)
    drawn, drawn_clips = drawing_commands(drawings, moved.times, fps)
    task_clips |= arrow_clips | drawn_clips
    commands = [
        *scene.commands,
        *axis_commands(robot, axes, points),
        *task,
        *arrows,
        *drawn,
        *pose_commands(robot, moved.configurations[0]),
        *camera_commands(framed),
        lower_animation({**clips, **task_clips}),
    ]
    return commands, float(moved.times[-1] - moved.times[0]), scene.placeholders


def recording(
    robot: Robot,
    trajectory: Trajectory,
    *,
    fps: float = 30.0,
    target=None,
    frame: str | None = None,
    axes: tuple[str, ...] = (),
    max_mesh_bytes: int = MAX_MESH_BYTES,
    target_rotation: np.ndarray | None = None,
    forces: tuple = (),
    drawings: tuple = (),
) -> Recording:
    """Draw a trajectory: the robot, the ground, the target and the end effector's path.

    Args:
        robot: The robot (its URDF visuals are drawn).
        trajectory: The motion (``t`` in [s], ``q`` one configuration a row, shape (N, nq)).
        fps: Frames per second of the animation.
        target: Task target, X,Z (planar, Y = 0) or X,Y,Z in [m]; drawn as a red sphere.
        frame: The frame whose path is drawn (default ``robot.end_effector``; none when
            the robot has no default and none is given).
        axes: Links (or frames) that carry a small x/y/z triad (red, green, blue).
        max_mesh_bytes: Largest mesh file drawn; larger ones become placeholder boxes.
        target_rotation: The target's attitude (3, 3): the target pose drawn as a triad.
        forces: :class:`robodyn.ExternalWrench` es drawn as arrows while they act.
        drawings: More to draw (a support polygon, a moving point: :mod:`robodyn.viz.drawings`).

    Raises:
        RobodynError: If the trajectory is empty, does not fit the robot, or nothing of the
            robot can be drawn.
    """
    commands, duration, placeholders = motion_commands(
        robot, trajectory, fps=fps, target=target, frame=frame, axes=axes, max_mesh_bytes=max_mesh_bytes,
        target_rotation=target_rotation, forces=forces, drawings=drawings,
    )  # fmt: skip
    return Recording(page(commands, title=f"robodyn: {robot.name}"), duration, fps, robot.name, placeholders)


def record(
    robot: Robot,
    trajectory: Trajectory,
    path: str | os.PathLike,
    *,
    fps: float = 30.0,
    png: str | os.PathLike | None = None,
    at: float | None = None,
    target=None,
    frame: str | None = None,
    axes: tuple[str, ...] = (),
    max_mesh_bytes: int = MAX_MESH_BYTES,
    target_rotation: np.ndarray | None = None,
    forces: tuple = (),
    drawings: tuple = (),
) -> Path | None:
    """Write a self-contained HTML animation of a trajectory (plays on open).

    Args:
        robot: The robot (its URDF visuals are drawn).
        trajectory: The motion (``t`` in [s], ``q`` one configuration a row).
        path: The HTML file to write (atomically).
        fps: Frames per second of the animation.
        png: Also write a still (needs Chromium), of the frame at ``at`` seconds.
        at: Time of the still in [s], from the motion's start; ``None`` (default): the
            motion's end, the final pose with the whole path drawn (a poster of the motion,
            not of the robot at rest before it).
        target: Task target drawn as a marker, X,Z or X,Y,Z in [m].
        frame: Frame whose path is drawn (default ``robot.end_effector``).
        axes: Links that carry an x/y/z triad.
        max_mesh_bytes: Largest mesh file drawn (see :mod:`robodyn.viz.mesh_files`).
        target_rotation, forces, drawings: As for :func:`recording`.

    Returns:
        The HTML path (``None`` for standard output, ``-``).

    Raises:
        RobodynError: If the trajectory is empty or does not fit the robot, or the still
            cannot be made.
    """
    made = recording(
        robot, trajectory, fps=fps, target=target, frame=frame, axes=axes, max_mesh_bytes=max_mesh_bytes,
        target_rotation=target_rotation, forces=forces, drawings=drawings,
    )  # fmt: skip
    if png is not None:
        made.still(png, at=made.duration if at is None else at)
    return made.save(path)
