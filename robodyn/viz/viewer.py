"""Watching motions: one import for the scene, recordings, stills and the live viewer.

The work is split by concern: :mod:`robodyn.viz.scene` (meshcat scenes), :mod:`robodyn.viz.task` (the task drawing),
:mod:`robodyn.viz.recording` (self-contained HTML, :class:`Recording`),
:mod:`robodyn.viz.stills` (headless Chromium: stills, filmstrips, videos) and
:mod:`robodyn.viz.live` (the live viewer). This module re-exports their public names.
"""

from __future__ import annotations

from robodyn.viz.live import LiveViewer, wait
from robodyn.viz.recording import Recording, page, record, recording
from robodyn.viz.scene import (
    animation_command,
    build_scene,
    camera_commands,
    link_placements,
    pose_commands,
    scene_commands,
)
from robodyn.viz.stills import CHROMIUM_FLAGS, capture, chromium, screenshot
from robodyn.viz.task import axis_commands, task_commands

__all__ = [
    "CHROMIUM_FLAGS",
    "LiveViewer",
    "Recording",
    "animation_command",
    "axis_commands",
    "build_scene",
    "camera_commands",
    "capture",
    "chromium",
    "link_placements",
    "page",
    "pose_commands",
    "record",
    "recording",
    "scene_commands",
    "screenshot",
    "task_commands",
    "wait",
]
