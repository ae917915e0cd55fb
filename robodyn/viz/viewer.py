"""Watching motions: meshcat scenes, self-contained HTML recordings, and a live viewer.

A robot's scene is built from its URDF visuals: meshes (STL, OBJ, DAE, through the
validated, confined mesh paths) or boxes, cylinders and spheres (robots without meshes,
like the RP arm). Each link is a node; a motion is a meshcat animation of the link nodes'
poses, so every mesh is sent once however many frames there are.

- :func:`record` writes one HTML file (meshcat's viewer inlined, the scene and animation
  embedded) that plays on open, offline, in any browser; written atomically.
- :class:`LiveViewer` runs meshcat's server on 127.0.0.1 (a free port), shows the robot
  and plays motions, and shuts the server down when done, on error or on a signal.
"""

from __future__ import annotations

import base64
import os
import signal
import socket
import subprocess
import sys
import time
import xml.etree.ElementTree as ET
from pathlib import Path

import meshcat.geometry as mg
import numpy as np
import pinocchio as pin
import umsgpack
from meshcat.animation import AnimationClip
from meshcat.commands import SetAnimation, SetObject, SetProperty, SetTransform
from meshcat.path import Path as MeshcatPath

from robodyn.common.files import atomic_write_text
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import RobodynError
from robodyn.sim.simulation import Trajectory
from robodyn.urdf.edit import rpy_matrix
from robodyn.urdf.meshes import MeshPathError, resolve_mesh

ROOT_PATH = ("robodyn",)
DEFAULT_COLOR = 0xB0B8C0


def _path(*entries: str) -> MeshcatPath:
    return MeshcatPath(ROOT_PATH + tuple(entries))


def _transform(xyz: np.ndarray, rpy: np.ndarray, scale: np.ndarray | None = None) -> np.ndarray:
    matrix = np.eye(4)
    matrix[:3, :3] = rpy_matrix(rpy) @ np.diag(scale if scale is not None else np.ones(3))
    matrix[:3, 3] = xyz
    return matrix


def _floats(node: ET.Element | None, attribute: str, default: str) -> np.ndarray:
    return np.array([float(x) for x in (node.get(attribute, default) if node is not None else default).split()])


def _color(visual: ET.Element, materials: dict[str, int]) -> int:
    material = visual.find("material")
    if material is None:
        return DEFAULT_COLOR
    color = material.find("color")
    if color is not None and color.get("rgba"):
        r, g, b = (min(max(float(x), 0.0), 1.0) for x in color.get("rgba").split()[:3])
        return (int(r * 255) << 16) | (int(g * 255) << 8) | int(b * 255)
    return materials.get(material.get("name", ""), DEFAULT_COLOR)


def _geometry(visual: ET.Element, robot: Robot) -> tuple[mg.Geometry | None, np.ndarray]:
    """Meshcat geometry of a URDF visual and the extra transform it needs."""
    geometry = visual.find("geometry")
    extra = np.eye(4)
    if geometry is None or len(geometry) == 0:
        return None, extra
    shape = geometry[0]
    if shape.tag == "box":
        return mg.Box(_floats(shape, "size", "0.1 0.1 0.1").tolist()), extra
    if shape.tag == "sphere":
        return mg.Sphere(float(shape.get("radius", "0.05"))), extra
    if shape.tag == "cylinder":  # three.js cylinders run along y, URDF ones along z
        extra[:3, :3] = rpy_matrix(np.array([np.pi / 2, 0.0, 0.0]))
        return mg.Cylinder(float(shape.get("length", "0.1")), float(shape.get("radius", "0.05"))), extra
    if shape.tag == "mesh":
        base_dir = robot.source_path.parent if robot.source_path is not None else None
        try:
            found = resolve_mesh(shape.get("filename", ""), base_dir=base_dir, package_dirs=robot.package_dirs)
        except MeshPathError:
            return None, extra
        if found is None:
            return None, extra
        loader = {".stl": mg.StlMeshGeometry, ".obj": mg.ObjMeshGeometry, ".dae": mg.DaeMeshGeometry}.get(found.suffix.lower())
        if loader is None:
            return None, extra
        extra[:3, :3] = np.diag(_floats(shape, "scale", "1 1 1"))
        return loader.from_file(str(found)), extra
    return None, extra


def scene_commands(robot: Robot) -> list[dict]:
    """Meshcat commands drawing every link's visuals (each mesh sent once)."""
    root = robot.spec.xml
    materials = {}
    for material in root.findall("material"):
        color = material.find("color")
        if color is not None and color.get("rgba"):
            r, g, b = (float(x) for x in color.get("rgba").split()[:3])
            materials[material.get("name", "")] = (int(r * 255) << 16) | (int(g * 255) << 8) | int(b * 255)
    commands = []
    for link in root.findall("link"):
        name = link.get("name")
        for index, visual in enumerate(link.findall("visual")):
            geometry, extra = _geometry(visual, robot)
            if geometry is None:
                continue
            origin = visual.find("origin")
            offset = _transform(_floats(origin, "xyz", "0 0 0"), _floats(origin, "rpy", "0 0 0")) @ extra
            material = mg.MeshLambertMaterial(color=_color(visual, materials))
            path = _path(name, f"visual{index}")
            commands.append(SetObject(geometry, material, path=path).lower())
            commands.append(SetTransform(offset, path=path).lower())
    return commands


def link_placements(robot: Robot, q: np.ndarray, data: pin.Data | None = None) -> dict[str, np.ndarray]:
    """World pose (4×4) of every URDF link at configuration ``q``.

    Pass ``data`` (``robot.model.createData()``) when calling this for many frames.
    """
    data = robot.model.createData() if data is None else data
    pin.framesForwardKinematics(robot.model, data, q)
    frames = robot.frame_ids
    return {name: data.oMf[frames[name]].homogeneous for name in robot.spec.links if name in frames}


def _resample(trajectory: Trajectory, fps: float) -> tuple[np.ndarray, np.ndarray]:
    """Times and configurations at ``fps`` frames per second (linear interpolation)."""
    if len(trajectory) == 0:
        raise RobodynError("the trajectory is empty: nothing to record.")
    duration = float(trajectory.t[-1] - trajectory.t[0])
    times = trajectory.t[0] + np.arange(int(np.floor(duration * fps + 1e-9)) + 1) / fps
    q = np.column_stack([np.interp(times, trajectory.t, trajectory.q[:, i]) for i in range(trajectory.q.shape[1])])
    return times, q


def animation_command(robot: Robot, trajectory: Trajectory, fps: float = 30.0) -> tuple[dict, np.ndarray]:
    """The meshcat animation of every link over a trajectory, and all link positions seen."""
    _times, configurations = _resample(trajectory, fps)
    if robot.floating_base:
        configurations[:, 3:7] /= np.linalg.norm(configurations[:, 3:7], axis=1, keepdims=True)
    clips: dict[str, AnimationClip] = {}
    positions = []
    data = robot.model.createData()
    for frame, q in enumerate(configurations):
        for name, matrix in link_placements(robot, q, data).items():
            clip = clips.setdefault(name, AnimationClip(fps=fps))
            quaternion = pin.Quaternion(matrix[:3, :3]).coeffs()  # x, y, z, w
            clip.set_property(frame, "position", "vector3", matrix[:3, 3].tolist())
            clip.set_property(frame, "quaternion", "quaternion", quaternion.tolist())
            positions.append(matrix[:3, 3])

    class _Animation:
        def lower(self) -> list[dict]:
            return [{"path": _path(name).lower(), "clip": clip.lower()} for name, clip in clips.items()]

    return SetAnimation(_Animation(), play=True, repetitions=1).lower(), np.array(positions)


def pose_commands(robot: Robot, q: np.ndarray) -> list[dict]:
    """Commands placing every link at configuration ``q`` (a still scene)."""
    return [SetTransform(matrix, path=_path(name)).lower() for name, matrix in link_placements(robot, q).items()]


def camera_commands(points: np.ndarray) -> list[dict]:
    """Aim meshcat's camera at the points' centre, far enough to see them all."""
    low, high = points.min(axis=0), points.max(axis=0)
    centre = (low + high) / 2
    radius = max(float(np.linalg.norm(high - low)) / 2, 0.25)
    distance = 1.9 * radius
    target = np.eye(4)
    target[:3, 3] = centre
    # The camera node's frame is y-up: (x, y, z) here is (x, z, -y) in the world.
    camera = MeshcatPath(("Cameras", "default", "rotated", "<object>"))
    return [
        SetTransform(target, path=MeshcatPath(("Cameras", "default"))).lower(),
        SetProperty("position", [distance * 0.8, distance * 0.45, distance * 0.8], path=camera).lower(),
        SetProperty("visible", False, path=MeshcatPath(("Grid",))).lower(),
    ]


def _html(commands: list[dict]) -> str:
    import meshcat

    script = (Path(meshcat.__file__).parent / "viewer" / "dist" / "main.min.js").read_text(encoding="utf-8")
    blobs = ",\n".join(f'"{base64.b64encode(umsgpack.packb(command)).decode("ascii")}"' for command in commands)
    return f"""<!DOCTYPE html>
<html>
<head><meta charset="utf-8"><title>robodyn recording</title>
<style>body {{ margin: 0; }} #meshcat-pane {{ width: 100vw; height: 100vh; overflow: hidden; }}</style></head>
<body>
<div id="meshcat-pane"></div>
<script>{script}</script>
<script>
var viewer = new MeshCat.Viewer(document.getElementById("meshcat-pane"));
var commands = [{blobs}];
for (var i = 0; i < commands.length; ++i) {{
  var bytes = Uint8Array.from(atob(commands[i]), function (c) {{ return c.charCodeAt(0); }});
  viewer.handle_command_bytearray(bytes);
}}
document.title = "robodyn recording (ready)";
</script>
</body>
</html>
"""


def record(
    robot: Robot, trajectory: Trajectory, path: str | os.PathLike, *, fps: float = 30.0, png: str | os.PathLike | None = None
) -> Path:
    """Write a self-contained HTML animation of a trajectory (plays on open).

    Args:
        robot: The robot (its URDF visuals are drawn).
        trajectory: The motion (``t`` in [s], ``q`` one configuration a row).
        path: The HTML file to write (atomically).
        fps: Frames per second of the animation.
        png: Also write a still of the first frame (needs Chromium).

    Returns:
        The HTML path.

    Raises:
        RobodynError: If the trajectory is empty or does not fit the robot.
    """
    if trajectory.q.ndim != 2 or trajectory.q.shape[1] != robot.nq:
        raise RobodynError(f"the trajectory has {trajectory.q.shape[-1]} coordinates a sample; {robot.name} needs {robot.nq}.")
    if not (np.isfinite(fps) and fps > 0):
        raise RobodynError(f"fps must be positive, got {fps}.")
    animation, positions = animation_command(robot, trajectory, fps)
    scene = scene_commands(robot)
    if not scene:
        raise RobodynError(f"robot {robot.name!r} has no visual geometry robodyn can draw: the recording would be empty.")
    still = [*scene, *pose_commands(robot, trajectory.q[0]), *camera_commands(positions)]
    if png is not None:  # the first frame, from the same scene without the animation
        import tempfile

        with tempfile.TemporaryDirectory() as folder:
            poster = Path(folder) / "still.html"
            poster.write_text(_html(still), encoding="utf-8")
            screenshot(poster, png)
    return atomic_write_text(path, _html([*still, animation]))


# --------------------------------------------------------------------------------------
# Headless Chromium: stills of recordings
# --------------------------------------------------------------------------------------
CHROMIUM_FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--enable-unsafe-swiftshader",
    "--use-angle=swiftshader",
    "--hide-scrollbars",
]


def chromium() -> str | None:
    """Path of a Chromium executable, or ``None``."""
    import shutil

    for name in ("chromium", "chromium-browser", "google-chrome"):
        found = shutil.which(name)
        if found:
            return found
    return None


def screenshot(
    html: str | os.PathLike, png: str | os.PathLike, *, at_seconds: float = 0.0, size: tuple[int, int] = (800, 600)
) -> Path:
    """A PNG of an HTML recording ``at_seconds`` into its animation (headless Chromium).

    Raises:
        RobodynError: If Chromium is missing or fails.
    """
    import tempfile

    from robodyn.common.files import atomic_write_bytes

    browser = chromium()
    if browser is None:
        raise RobodynError("no Chromium found for the still image: install Debian's 'chromium' package.")
    with tempfile.TemporaryDirectory() as profile:
        output = Path(profile) / "shot.png"
        budget = int(1500 + 1000 * at_seconds)  # load time, then the animation's time
        command = [
            browser, *CHROMIUM_FLAGS, f"--user-data-dir={profile}", f"--window-size={size[0]},{size[1]}",
            f"--virtual-time-budget={budget}", f"--screenshot={output}", Path(html).resolve().as_uri(),
        ]  # fmt: skip
        result = subprocess.run(command, capture_output=True, timeout=120)
        if result.returncode != 0 or not output.is_file():
            raise RobodynError(f"Chromium could not render {html} (exit {result.returncode}).")
        return atomic_write_bytes(png, output.read_bytes())


# --------------------------------------------------------------------------------------
# Live viewer: meshcat's server on 127.0.0.1, owned and shut down by robodyn
# --------------------------------------------------------------------------------------
def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


class LiveViewer:
    """Meshcat's server for one session, listening on 127.0.0.1 only.

    Use as a context manager: the server process is stopped on exit, on an exception
    and on SIGTERM/SIGINT (which become a normal exit).

    Attributes:
        url: The page to open in a browser.
    """

    def __init__(self) -> None:
        self._process: subprocess.Popen | None = None
        self.url = ""
        self._visualizer = None

    def __enter__(self) -> LiveViewer:
        web_port, zmq_port = _free_port(), _free_port()
        zmq_url = f"tcp://127.0.0.1:{zmq_port}"
        self._process = subprocess.Popen(
            [sys.executable, "-m", "robodyn.viz.server", zmq_url, str(web_port)],
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
        )
        line = self._process.stdout.readline().decode().strip()
        if not line.startswith("web_url="):
            self.close()
            raise RobodynError("the meshcat server did not start.")
        self.url = line.removeprefix("web_url=")
        import contextlib
        import io

        import meshcat

        with contextlib.redirect_stdout(io.StringIO()):  # meshcat prints the URL itself
            self._visualizer = meshcat.Visualizer(zmq_url=zmq_url)
        signal.signal(signal.SIGTERM, _raise_interrupt)
        return self

    def __exit__(self, *exc_info) -> None:
        self.close()

    def close(self) -> None:
        """Stop the server (idempotent)."""
        if self._process is not None and self._process.poll() is None:
            self._process.terminate()
            try:
                self._process.wait(timeout=5)
            except subprocess.TimeoutExpired:
                self._process.kill()
                self._process.wait()
        self._process = None

    @property
    def server_pid(self) -> int | None:
        """Process id of the server, while it runs."""
        return self._process.pid if self._process is not None else None

    def send(self, commands: list[dict]) -> None:
        """Send lowered meshcat commands to the viewer."""
        window = self._visualizer.window
        for command in commands:
            window.zmq_socket.send_multipart(
                [command["type"].encode(), command.get("path", "").encode(), umsgpack.packb(command)]
            )
            window.zmq_socket.recv()

    def show(self, robot: Robot, trajectory: Trajectory | None = None, *, fps: float = 30.0) -> None:
        """Draw the robot (at its neutral configuration or the trajectory's start) and play."""
        q = robot.neutral_configuration() if trajectory is None else trajectory.q[0]
        points = np.array([m[:3, 3] for m in link_placements(robot, q).values()])
        animation = []
        if trajectory is not None:
            command, points = animation_command(robot, trajectory, fps)
            animation = [command]
        self.send([*scene_commands(robot), *pose_commands(robot, q), *camera_commands(points), *animation])


def _raise_interrupt(signum, frame) -> None:
    raise KeyboardInterrupt


def wait(seconds: float | None) -> None:
    """Sleep ``seconds`` (forever when ``None``) until interrupted."""
    deadline = None if seconds is None else time.monotonic() + seconds
    while deadline is None or time.monotonic() < deadline:
        time.sleep(0.2)
