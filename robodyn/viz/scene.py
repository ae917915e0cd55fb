"""Meshcat scenes of a robot: its visuals, its motion as an animation, and the task around it.

A robot's scene is built from its URDF visuals: meshes (STL, OBJ, DAE, through the
validated, confined mesh paths and the defensive reader of :mod:`robodyn.viz.mesh_files`)
or boxes, cylinders and spheres. Each link is a node; a motion is a meshcat animation of
the link nodes' poses, so every mesh is sent once however many frames there are.

The camera is framed from the visuals' bounds over the whole motion, so the robot never
leaves the picture; :mod:`robodyn.viz.task` draws the task around it.
"""

from __future__ import annotations

import warnings
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from typing import cast

import meshcat.geometry as mg
import numpy as np
import pinocchio as pin
from meshcat.animation import AnimationClip
from meshcat.commands import SetAnimation, SetObject, SetProperty, SetTransform
from meshcat.path import Path as MeshcatPath

from robodyn.common.rotations import rpy_matrix
from robodyn.dynamics.robot import Robot
from robodyn.exceptions import MeshFileError, MeshWarning, ViewerError
from robodyn.trajectory import Trajectory
from robodyn.urdf.meshes import MeshPathError, resolve_mesh
from robodyn.viz.mesh_files import MAX_MESH_BYTES, read_mesh

ROOT_PATH = ("robodyn",)
DEFAULT_COLOR = 0xB0B8C0
PLACEHOLDER_COLOR = 0xFF00FF
PLACEHOLDER_SIZE = 0.05
#: Vertical field of view of the camera, in [deg] (meshcat's default 75° distorts the edges).
CAMERA_FOV = 45.0
#: Largest sideways tilt of the camera from its preferred direction towards the points, in [deg].
CAMERA_TILT = 35.0
_UNIT_CUBE = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float)


def _path(*entries: str) -> MeshcatPath:
    return MeshcatPath(ROOT_PATH + tuple(entries))


def _transform(xyz: np.ndarray, rpy: np.ndarray, scale: np.ndarray | None = None) -> np.ndarray:
    matrix = np.eye(4)
    matrix[:3, :3] = rpy_matrix(rpy) @ np.diag(scale if scale is not None else np.ones(3))
    matrix[:3, 3] = xyz
    return matrix


def _floats(node: ET.Element | None, attribute: str, default: str) -> np.ndarray:
    return np.array([float(x) for x in (node.get(attribute, default) if node is not None else default).split()])


def _rgb(rgba: str) -> int:
    r, g, b = (min(max(float(x), 0.0), 1.0) for x in rgba.split()[:3])
    return (int(r * 255) << 16) | (int(g * 255) << 8) | int(b * 255)


def _color(visual: ET.Element, materials: dict[str, int]) -> int:
    material = visual.find("material")
    if material is None:
        return DEFAULT_COLOR
    color = material.find("color")
    rgba = None if color is None else color.get("rgba")
    if rgba:
        return _rgb(rgba)
    return materials.get(material.get("name", ""), DEFAULT_COLOR)


def _box_corners(low: np.ndarray, high: np.ndarray) -> np.ndarray:
    return low + _UNIT_CUBE * (high - low)


@dataclass
class Scene:
    """A robot's drawing: meshcat commands and where its visuals are.

    Attributes:
        commands: Lowered meshcat commands (objects and their fixed offsets).
        corners: Per link, corners of its visuals' boxes in the link frame, shape (K, 3), in [m].
        placeholders: One line a mesh drawn as a placeholder box (why).
    """

    commands: list[dict] = field(default_factory=list)
    corners: dict[str, np.ndarray] = field(default_factory=dict)
    placeholders: list[str] = field(default_factory=list)


def _geometry(visual: ET.Element, robot: Robot, scene: Scene, link: str, max_mesh_bytes: int):
    """Meshcat geometry of a URDF visual, the extra transform it needs, its local box, and
    whether it is a placeholder."""
    geometry = visual.find("geometry")
    extra = np.eye(4)
    if geometry is None or len(geometry) == 0:
        return None, extra, None
    shape = geometry[0]
    if shape.tag == "box":
        size = _floats(shape, "size", "0.1 0.1 0.1")
        return mg.Box(size.tolist()), extra, (-size / 2, size / 2)
    if shape.tag == "sphere":
        radius = float(shape.get("radius", "0.05"))
        return mg.Sphere(radius), extra, (-np.full(3, radius), np.full(3, radius))
    if shape.tag == "cylinder":  # three.js cylinders run along y, URDF ones along z
        length, radius = float(shape.get("length", "0.1")), float(shape.get("radius", "0.05"))
        extra[:3, :3] = rpy_matrix(np.array([np.pi / 2, 0.0, 0.0]))
        box = np.array([radius, radius, length / 2])
        return mg.Cylinder(length, radius), np.eye(4) @ extra, (-box, box)
    if shape.tag != "mesh":
        return None, extra, None
    filename = shape.get("filename", "")
    base_dir = robot.source_path.parent if robot.source_path is not None else None
    try:
        found = resolve_mesh(filename, base_dir=base_dir, package_dirs=robot.package_dirs)
        if found is None:
            raise MeshFileError(filename, "was not found or is not a regular file")
        mesh, bounds = read_mesh(found, max_bytes=max_mesh_bytes)
    except (MeshPathError, MeshFileError) as error:
        reason = f"link {link!r}: {error}"
        scene.placeholders.append(reason)
        warnings.warn(f"{reason}; drawn as a placeholder box", MeshWarning, stacklevel=4)
        half = np.full(3, PLACEHOLDER_SIZE / 2)
        return mg.Box([PLACEHOLDER_SIZE] * 3), extra, (-half, half), True
    scale = _floats(shape, "scale", "1 1 1")
    extra[:3, :3] = np.diag(scale)
    low, high = np.minimum(bounds[0] * scale, bounds[1] * scale), np.maximum(bounds[0] * scale, bounds[1] * scale)
    return mesh, extra, (low, high)


def build_scene(robot: Robot, *, max_mesh_bytes: int = MAX_MESH_BYTES) -> Scene:
    """Every link's visuals as meshcat commands (each mesh sent once), and their boxes.

    A mesh that cannot be drawn (missing, outside the model's folders, not a regular file,
    over ``max_mesh_bytes``, corrupt) becomes a magenta placeholder box and a
    :class:`~robodyn.viz.mesh_files.MeshWarning`.

    Args:
        robot: The robot drawn.
        max_mesh_bytes: Largest mesh file drawn, in bytes (larger: a placeholder box).
    """
    root = robot.spec.xml
    materials = {}
    for material in root.findall("material"):
        color = material.find("color")
        rgba = None if color is None else color.get("rgba")
        if rgba:
            materials[material.get("name", "")] = _rgb(rgba)
    scene = Scene()
    for link in root.findall("link"):
        name = cast(str, link.get("name"))  # the strict reader refused nameless links
        corners = []
        for index, visual in enumerate(link.findall("visual")):
            result = _geometry(visual, robot, scene, name, max_mesh_bytes)
            geometry, extra, box = result[:3]
            if geometry is None:
                continue
            placeholder = len(result) == 4
            origin = visual.find("origin")
            offset = _transform(_floats(origin, "xyz", "0 0 0"), _floats(origin, "rpy", "0 0 0"))
            rgb = PLACEHOLDER_COLOR if placeholder else _color(visual, materials)
            lambert = mg.MeshLambertMaterial(color=rgb, wireframe=placeholder)
            path = _path(name, f"visual{index}")
            scene.commands.append(SetObject(geometry, lambert, path=path).lower())
            scene.commands.append(SetTransform(offset @ extra, path=path).lower())
            local = _box_corners(*box) @ offset[:3, :3].T + offset[:3, 3]
            corners.append(local)
        if corners:
            scene.corners[name] = np.vstack(corners)
    return scene


def scene_commands(robot: Robot, *, max_mesh_bytes: int = MAX_MESH_BYTES) -> list[dict]:
    """Meshcat commands drawing every link's visuals (each mesh sent once).

    Args:
        robot: The robot drawn.
        max_mesh_bytes: Largest mesh file drawn, in bytes (larger: a placeholder box).
    """
    return build_scene(robot, max_mesh_bytes=max_mesh_bytes).commands


def link_placements(robot: Robot, q: np.ndarray, data: pin.Data | None = None) -> dict[str, np.ndarray]:
    """World pose (4×4) of every URDF link at configuration ``q``.

    Pass ``data`` (``robot.model.createData()``) when calling this for many frames.

    Args:
        robot: The robot drawn.
        q: Configuration, shape (nq,), in [rad] / [m].
        data: Pinocchio data of ``robot.model`` to reuse (``None``: new data).
    """
    data = robot.model.createData() if data is None else data
    pin.framesForwardKinematics(robot.model, data, q)
    frames = robot.frame_ids
    return {name: data.oMf[frames[name]].homogeneous for name in robot.spec.links if name in frames}


def resample(trajectory: Trajectory, fps: float, *, floating_base: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Times and configurations at ``fps`` frames per second (linear interpolation).

    With ``floating_base``, each sample's quaternion (``q[3:7]``) first takes the sign
    nearest the previous one's (``q`` and ``−q`` are one rotation: interpolated across a
    sign flip the base would turn the long way round, or through a zero quaternion); the
    caller renormalises.

    Args:
        trajectory: The motion.
        fps: Frames per second.
        floating_base: Whether ``q[3:7]`` is a floating base's quaternion.
    """
    if len(trajectory) == 0:
        raise ViewerError("the trajectory is empty: nothing to record.")
    duration = float(trajectory.t[-1] - trajectory.t[0])
    times = trajectory.t[0] + np.arange(int(np.floor(duration * fps + 1e-9)) + 1) / fps
    samples = trajectory.q
    if floating_base:
        samples = samples.copy()
        turns = np.einsum("ij,ij->i", samples[1:, 3:7], samples[:-1, 3:7]) < 0
        samples[1:, 3:7] *= np.where(np.logical_xor.accumulate(turns), -1.0, 1.0)[:, None]
    q = np.column_stack([np.interp(times, trajectory.t, samples[:, i]) for i in range(samples.shape[1])])
    return times, q


@dataclass
class Motion:
    """A motion, lowered for meshcat.

    Attributes:
        animation: The ``set_animation`` command (every link's poses a frame).
        times: Frame times in [s], shape (F,).
        configurations: Shape (F, nq).
        placements: Per frame, every link's 4×4 world pose.
    """

    animation: dict
    times: np.ndarray
    configurations: np.ndarray
    placements: list[dict[str, np.ndarray]]

    def points(self, scene: Scene) -> np.ndarray:
        """World corners of every visual box over the whole motion, shape (K, 3), in [m].

        Args:
            scene: The scene of the robot (its visual boxes' corners).
        """
        seen = []
        for placement in self.placements:
            for name, corners in scene.corners.items():
                if name in placement:
                    matrix = placement[name]
                    seen.append(corners @ matrix[:3, :3].T + matrix[:3, 3])
        return np.vstack(seen) if seen else np.vstack([p[:3, 3] for frame in self.placements for p in frame.values()])


def lower_animation(clips: dict[tuple[str, ...], AnimationClip]) -> dict:
    """A ``set_animation`` command (plays once on open) of clips by meshcat path.

    Args:
        clips: Animation clips by meshcat path (a tuple of path parts).
    """

    class _Animation:
        def lower(self) -> list[dict]:
            return [{"path": MeshcatPath(path).lower(), "clip": clip.lower()} for path, clip in clips.items()]

    return SetAnimation(_Animation(), play=True, repetitions=1).lower()


def motion(robot: Robot, trajectory: Trajectory, fps: float = 30.0) -> tuple[Motion, dict[tuple[str, ...], AnimationClip]]:
    """Every link's poses at ``fps`` over a trajectory, as animation clips.

    Args:
        robot: The robot drawn.
        trajectory: The motion (the robot's configurations over time).
        fps: Animation frames per second.
    """
    times, configurations = resample(trajectory, fps, floating_base=robot.floating_base)
    if robot.floating_base:
        configurations[:, 3:7] /= np.linalg.norm(configurations[:, 3:7], axis=1, keepdims=True)
    clips: dict[tuple[str, ...], AnimationClip] = {}
    placements = []
    data = robot.model.createData()
    for frame, q in enumerate(configurations):
        placement = link_placements(robot, q, data)
        placements.append(placement)
        for name, matrix in placement.items():
            clip = clips.setdefault((*ROOT_PATH, name), AnimationClip(fps=fps))
            quaternion = pin.Quaternion(matrix[:3, :3]).coeffs()  # x, y, z, w
            clip.set_property(frame, "position", "vector3", matrix[:3, 3].tolist())
            clip.set_property(frame, "quaternion", "quaternion", quaternion.tolist())
    return Motion(lower_animation(clips), times, configurations, placements), clips


def animation_command(robot: Robot, trajectory: Trajectory, fps: float = 30.0) -> tuple[dict, np.ndarray]:
    """The meshcat animation of every link over a trajectory, and all link positions seen.

    Args:
        robot: The robot drawn.
        trajectory: The motion (the robot's configurations over time).
        fps: Animation frames per second.
    """
    moved, _clips = motion(robot, trajectory, fps)
    return moved.animation, np.array([m[:3, 3] for frame in moved.placements for m in frame.values()])


def pose_commands(robot: Robot, q: np.ndarray) -> list[dict]:
    """Commands placing every link at configuration ``q`` (a still scene).

    Args:
        robot: The robot drawn.
        q: Configuration, shape (nq,), in [rad] / [m].
    """
    return [SetTransform(matrix, path=_path(name)).lower() for name, matrix in link_placements(robot, q).items()]


def camera_commands(points: np.ndarray, *, fov_deg: float = CAMERA_FOV, margin: float = 1.15) -> list[dict]:
    """Place meshcat's camera so that the points' bounding sphere is all in view.

    Meshcat's orbit controls make the camera look at the *world origin* whatever its parent
    node's transform, so the camera node stays at the origin and only the camera's position
    is chosen: along a direction near the preferred one (a motion in the x-z plane, such as
    a planar arm, is seen from the side, anything else from a corner above), tilted at most
    :data:`CAMERA_TILT` sideways towards the points' centre, at the smallest distance at which the
    whole sphere (times ``margin``) lies within the vertical field of view (the narrower
    one for a landscape picture) as seen looking at the origin. The points are the whole
    motion, the initial pose included. Meshcat's own grid is hidden (the task grid replaces
    it).

    Args:
        points: Points to keep in view, shape (K, 3), in [m], world frame.
        fov_deg: Meshcat's vertical field of view in [deg].
        margin: Factor on the bounding sphere's radius (1: the sphere just fits).
    """
    low, high = points.min(axis=0), points.max(axis=0)
    centre = (low + high) / 2
    radius = max(float(np.linalg.norm(high - low)) / 2, 0.05)
    span = high - low
    planar = span[1] < 0.25 * max(span[0], span[2])
    local = np.array([0.25, 0.35, 1.0] if planar else [0.8, 0.6, 0.8])
    # The camera node's frame is y-up: (x, y, z) there is (x, -z, y) in the world.
    preferred = np.array([local[0], -local[2], local[1]]) / np.linalg.norm(local)
    level = np.array([centre[0], centre[1], 0.0])  # only sideways: an upright arm stays seen from the side
    towards = level / max(float(np.linalg.norm(level)), 1e-12)
    best = None
    for weight in np.linspace(0.0, 1.0, 11):
        direction = (1 - weight) * preferred + weight * towards
        direction /= max(float(np.linalg.norm(direction)), 1e-12)
        if np.degrees(np.arccos(np.clip(direction @ preferred, -1.0, 1.0))) > CAMERA_TILT:
            break
        position = _camera_position(centre, radius * margin, direction, np.radians(fov_deg) / 2)
        if best is None or np.linalg.norm(position) < np.linalg.norm(best):
            best = position
    assert best is not None  # weight 0 is the preferred direction itself
    camera = MeshcatPath(("Cameras", "default", "rotated", "<object>"))
    return [
        SetTransform(np.eye(4), path=MeshcatPath(("Cameras", "default"))).lower(),
        SetProperty("position", [float(best[0]), float(best[2]), float(-best[1])], path=camera).lower(),
        SetProperty("fov", fov_deg, path=camera).lower(),
        SetProperty("visible", False, path=MeshcatPath(("Grid",))).lower(),
    ]


def _camera_position(centre: np.ndarray, radius: float, direction: np.ndarray, half: float) -> np.ndarray:
    """The nearest ``centre + d · direction`` from which, looking at the world origin, the
    sphere (``centre``, ``radius``) lies within the half-angle ``half`` [rad]."""
    distance = radius / np.sin(half)
    for _ in range(400):  # at most 1.02^400 ≈ 2750 times farther
        position = centre + distance * direction
        to_centre = centre - position
        length = float(np.linalg.norm(to_centre))
        sight = -position / max(float(np.linalg.norm(position)), 1e-12)
        off_axis = float(np.arccos(np.clip(sight @ to_centre / length, -1.0, 1.0)))
        if off_axis + np.arcsin(min(1.0, radius / length)) <= half:
            break
        distance *= 1.02
    return centre + distance * direction
