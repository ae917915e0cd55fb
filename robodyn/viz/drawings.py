"""A run's drawings in a recording: outlines and moving points (:mod:`robodyn.sim.drawings`).

A :class:`~robodyn.sim.drawings.Polygon` is a closed line at its vertices (``task/<name>``);
a :class:`~robodyn.sim.drawings.MovingPoint` a sphere whose position the animation sets
at every frame (``task/<name>``).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import meshcat.geometry as mg
import numpy as np
from meshcat.animation import AnimationClip
from meshcat.commands import SetObject, SetTransform
from meshcat.path import Path as MeshcatPath

from robodyn.viz.task import TASK_PATH


def drawing_commands(
    drawings: Sequence[Any], times: np.ndarray, fps: float = 30.0
) -> tuple[list[dict], dict[tuple[str, ...], AnimationClip]]:
    """The commands and animation clips of a run's drawings.

    Args:
        drawings: :class:`~robodyn.sim.drawings.Polygon` and
            :class:`~robodyn.sim.drawings.MovingPoint` values.
        times: The animation's times in [s], one a frame, shape (F,).
        fps: Frames per second of the animation.

    Returns:
        Commands (the geometry) and clips (the moving points' positions).
    """
    commands: list[dict] = []
    clips: dict[tuple[str, ...], AnimationClip] = {}
    for item in drawings:
        path = MeshcatPath((*TASK_PATH, item.name))
        if hasattr(item, "vertices"):
            outline = np.asarray(item.vertices, dtype=np.float32).T
            line = mg.LineLoop(mg.PointsGeometry(outline), mg.LineBasicMaterial(color=item.colour))
            commands.append(SetObject(line, path=path).lower())
            continue
        sphere = mg.Sphere(item.radius)
        commands.append(SetObject(sphere, mg.MeshLambertMaterial(color=item.colour), path=path).lower())
        positions = item.at(np.asarray(times, dtype=float))
        matrix = np.eye(4)
        matrix[:3, 3] = positions[0]
        commands.append(SetTransform(matrix, path=path).lower())
        clip = AnimationClip(fps=fps)
        for frame, position in enumerate(positions):
            clip.set_property(frame, "position", "vector3", position.tolist())
        clips[(*TASK_PATH, item.name)] = clip
    return commands, clips


__all__ = ["drawing_commands"]
