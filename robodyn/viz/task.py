"""The task around a robot's scene: ground grid, target marker, growing path, link triads.

- a ground grid at the lowest point of the motion (or z = 0 above it), with a margin;
- the target as a red sphere;
- the end effector's path as an orange line with dots, in segments that the animation
  switches visible as the motion reaches them (so the path grows with time);
- x/y/z triads (red, green, blue) riding on chosen links;
- the target pose (position and attitude) as a triad (:func:`target_pose_commands`);
- external forces as arrows (an orange shaft and cone from the frame the force acts on,
  pointing along it, its length in proportion, shown while the force acts:
  :func:`force_commands`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import meshcat.geometry as mg
import numpy as np
import pinocchio as pin
from meshcat.animation import AnimationClip
from meshcat.commands import SetObject, SetTransform
from meshcat.path import Path as MeshcatPath

from robodyn.dynamics.robot import Robot
from robodyn.exceptions import FrameError
from robodyn.viz.scene import ROOT_PATH

TASK_PATH = ("task",)


def _task_path(*entries: str) -> MeshcatPath:
    return MeshcatPath(TASK_PATH + tuple(entries))


def _nice_step(length: float) -> float:
    raw = length / 10
    power = 10 ** np.floor(np.log10(raw))
    return float(min((s * power for s in (1, 2, 5, 10) if s * power >= raw), default=power * 10))


def _segments(points: np.ndarray, rgb: tuple[float, float, float] | None = None) -> mg.PointsGeometry:
    """Points for lines and dots; ``rgb`` colours every vertex (meshcat's points use vertex colours)."""
    points = np.asarray(points, dtype=np.float32).T
    colors = None if rgb is None else np.tile(np.asarray(rgb, dtype=np.float32)[:, None], (1, points.shape[1]))
    return mg.PointsGeometry(points, colors)


def task_commands(
    points: np.ndarray,
    *,
    target: np.ndarray | None = None,
    path: np.ndarray | None = None,
    path_frames: np.ndarray | None = None,
    fps: float = 30.0,
) -> tuple[list[dict], dict[tuple[str, ...], AnimationClip]]:
    """The task around the robot: a ground grid, the target, the growing end-effector path.

    Args:
        points: Everything the robot's visuals cover over the motion, shape (K, 3), in [m].
        target: Target position, shape (3,), in [m].
        path: End-effector positions, shape (P, 3), in [m].
        path_frames: Animation frame at which each path point is reached, shape (P,).
        fps: Frames per second of the animation.

    Returns:
        Commands, and animation clips (the path's segments turning visible).
    """
    low, high = points.min(axis=0), points.max(axis=0)
    size = max(float(np.linalg.norm(high - low)), 0.1)
    commands: list[dict] = []
    clips: dict[tuple[str, ...], AnimationClip] = {}
    # Ground grid at the lowest point of the motion (or z = 0 above it), a margin around it.
    floor = min(float(low[2]), 0.0) - 1e-3
    extent = float(np.max(high[:2] - low[:2])) + size
    step = _nice_step(extent)
    centre = np.round((low[:2] + high[:2]) / 2 / step) * step
    half = step * np.ceil(extent / 2 / step)
    lines = []
    for offset in np.arange(-half, half + step / 2, step):
        lines += [[centre[0] - half, centre[1] + offset, floor], [centre[0] + half, centre[1] + offset, floor]]
        lines += [[centre[0] + offset, centre[1] - half, floor], [centre[0] + offset, centre[1] + half, floor]]
    grid = mg.LineSegments(_segments(np.array(lines)), mg.LineBasicMaterial(color=0x555555))
    commands.append(SetObject(grid, path=_task_path("grid")).lower())
    if target is not None:
        marker = mg.Sphere(max(0.02 * size, 0.008))
        commands.append(SetObject(marker, mg.MeshLambertMaterial(color=0xE02020), path=_task_path("target")).lower())
        matrix = np.eye(4)
        matrix[:3, 3] = target
        commands.append(SetTransform(matrix, path=_task_path("target")).lower())
    if path is not None and len(path) > 1:
        frames = np.asarray(path_frames if path_frames is not None else np.zeros(len(path)), dtype=int)
        last = int(frames.max())
        chunks = max(1, min(last, 200))  # one segment object a frame (at most 200)
        bounds = np.linspace(0, last, chunks + 1)
        dot = max(0.012 * size, 0.004)
        for index in range(chunks):
            upto = bounds[index + 1]
            chosen = np.flatnonzero((frames >= bounds[index]) & (frames <= upto))
            if chosen.size == 0:
                continue
            chosen = np.arange(max(chosen[0] - 1, 0), chosen[-1] + 1)  # join to the previous segment
            name = f"path{index:03d}"
            points_geometry = _segments(path[chosen], (1.0, 0.69, 0.0))
            colour = 0xFFB000
            commands.append(
                SetObject(mg.Line(points_geometry, mg.LineBasicMaterial(color=colour)), path=_task_path(name, "line")).lower()
            )
            commands.append(SetObject(mg.Points(points_geometry, mg.PointsMaterial(size=dot, color=colour)), path=_task_path(name, "dots")).lower())  # fmt: skip
            if upto > 0:
                clip = AnimationClip(fps=fps)
                clip.set_property(0, "visible", "boolean", False)
                clip.set_property(int(np.ceil(upto)), "visible", "boolean", True)
                clips[(*TASK_PATH, name)] = clip
    return commands, clips


def axis_commands(robot: Robot, links: tuple[str, ...] | list[str], points: np.ndarray) -> list[dict]:
    """An x/y/z triad (red, green, blue lines; a tenth of the scene's size) on each link.

    Args:
        robot: The robot drawn.
        links: Names of the links given a triad.
        points: Points of the scene, shape (K, 3), in [m] (their extent sizes the triads).

    Raises:
        FrameError: For a name that is not a URDF link.
    """
    size = max(float(np.linalg.norm(points.max(axis=0) - points.min(axis=0))), 0.1)
    commands = []
    for link in links:
        if link not in robot.spec.links:
            raise FrameError(link, robot.name)
        commands.append(SetObject(mg.triad(0.1 * size), path=MeshcatPath((*ROOT_PATH, link, "axes"))).lower())
    return commands


#: Colour of the force arrows.
FORCE_COLOUR = 0xFF6A00
#: Length of the largest force's arrow, relative to the scene's size.
FORCE_LENGTH = 0.25


def _scene_size(points: np.ndarray) -> float:
    return max(float(np.linalg.norm(points.max(axis=0) - points.min(axis=0))), 0.1)


def target_pose_commands(position: np.ndarray, rotation: np.ndarray, points: np.ndarray) -> list[dict]:
    """The target pose as an x/y/z triad (red, green, blue; a sixth of the scene's size).

    Args:
        position: Target position in [m], shape (3,).
        rotation: Target attitude, world axes, shape (3, 3).
        points: Everything the robot's visuals cover over the motion, shape (K, 3), in [m].
    """
    matrix = np.eye(4)
    matrix[:3, :3], matrix[:3, 3] = rotation, position
    path = _task_path("target_pose")
    return [SetObject(mg.triad(_scene_size(points) / 6), path=path).lower(), SetTransform(matrix, path=path).lower()]


def force_commands(
    robot: Any,
    times: np.ndarray,
    configurations: np.ndarray,
    forces: Sequence[Any],
    points: np.ndarray,
    fps: float = 30.0,
) -> tuple[list[dict], dict[tuple[str, ...], AnimationClip]]:
    """External forces as arrows at the frames they act on, animated with the motion.

    Args:
        robot: The robot (:class:`robodyn.Robot`).
        times: Animation times in [s], shape (F,).
        configurations: The configuration at each, shape (F, nq).
        forces: :class:`robodyn.ExternalWrench` es (their force part is drawn).
        points: Everything the robot's visuals cover over the motion, shape (K, 3), in [m].
        fps: Frames per second of the animation.

    Returns:
        Commands (the arrows' geometry) and animation clips (their poses and visibility).
    """
    commands: list[dict] = []
    clips: dict[tuple[str, ...], AnimationClip] = {}
    values = [np.array([np.asarray(item.value(float(t)), float)[:3] for t in times]) for item in forces]
    largest = max((float(np.linalg.norm(v, axis=1).max()) for v in values), default=0.0)
    if largest == 0.0:
        return commands, clips
    scale = FORCE_LENGTH * _scene_size(points) / largest
    for index, (item, force) in enumerate(zip(forces, values, strict=True)):
        name = f"force{index:02d}"
        shaft, tip = mg.Cylinder(0.8, radius=0.015), mg.Cylinder(0.2, radiusTop=0.0, radiusBottom=0.045)
        parts = ((shaft, "shaft", 0.4), (tip, "tip", 0.9))
        for geometry, part, offset in parts:  # a unit arrow along y (meshcat's cylinders' axis) from the origin
            matrix = np.eye(4)
            matrix[1, 3] = offset
            commands.append(SetObject(geometry, mg.MeshLambertMaterial(color=FORCE_COLOUR), path=_task_path(name, part)).lower())
            commands.append(SetTransform(matrix, path=_task_path(name, part)).lower())
        clip = AnimationClip(fps=fps)
        for frame, (q, f) in enumerate(zip(configurations, force, strict=True)):
            length = float(np.linalg.norm(f))
            direction = f / length if length > 0 else np.array([0.0, 1.0, 0.0])
            rotation = pin.Quaternion.FromTwoVectors(np.array([0.0, 1.0, 0.0]), direction).coeffs()
            clip.set_property(frame, "position", "vector3", robot.frame_position(q, item.frame).tolist())
            clip.set_property(frame, "quaternion", "quaternion", rotation.tolist())
            clip.set_property(frame, "scale", "vector3", [max(scale * length, 1e-6)] * 3)
            clip.set_property(frame, "visible", "boolean", length > 0)
        clips[(*TASK_PATH, name)] = clip
    return commands, clips
