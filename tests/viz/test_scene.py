"""The camera frames the whole motion and the initial pose (issue 29, item 5).

Meshcat's orbit controls make the camera look at the world origin, whatever the transform
of its parent node ``/Cameras/default``; the model below applies exactly that: the camera's
world position is the parent's transform of its ``position`` (in the y-up ``rotated``
frame), and its line of sight goes to the world origin.
"""

from __future__ import annotations

import numpy as np
import pytest

from robodyn.viz.scene import CAMERA_FOV, camera_commands

ROTATED = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])  # y-up -> z-up (meshcat's "rotated")


def _seen_angles(commands: list[dict], points: np.ndarray) -> np.ndarray:
    """Angle in [rad] of each point off the camera's line of sight, as meshcat renders it."""
    parent = next(c for c in commands if c["type"] == "set_transform" and c["path"] == "/Cameras/default")
    matrix = np.array(parent["matrix"], dtype=float).reshape(4, 4).T  # column-major
    local = next(c for c in commands if c.get("property") == "position")["value"]
    camera = matrix[:3, :3] @ ROTATED @ np.array(local) + matrix[:3, 3]
    sight = -camera / np.linalg.norm(camera)  # lookAt(world origin)
    rays = points - camera
    return np.arccos(np.clip(rays @ sight / np.linalg.norm(rays, axis=1), -1, 1))


def _upright_arm(height: float = 1.0, reach: float = 0.2) -> np.ndarray:
    """Points of an arm standing straight up from the origin, swinging a little sideways."""
    z = np.linspace(0.0, height, 30)
    return np.vstack([np.column_stack([reach * s * z, 0.05 * z, z]) for s in (-1.0, 0.0, 1.0)])


@pytest.mark.parametrize(
    "points",
    [
        _upright_arm(),
        _upright_arm(2.5, 0.05),  # tall and narrow: its top used to be cropped
        _upright_arm() + np.array([3.0, -2.0, 0.0]),  # far from the origin (a floating base that walked)
        np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.3]]),  # planar, in the x-z plane
    ],
)
def test_every_point_of_the_motion_is_within_the_field_of_view(points):
    angles = _seen_angles(camera_commands(points), points)
    assert np.degrees(angles.max()) < CAMERA_FOV / 2


def test_the_check_fails_for_a_camera_that_looks_elsewhere():  # negative control
    points = _upright_arm(2.5, 0.05)
    commands = camera_commands(points)
    local = next(c for c in commands if c.get("property") == "position")
    local["value"] = [local["value"][0] * 0.2, local["value"][1] * 0.2, local["value"][2] * 0.2]  # too close
    assert np.degrees(_seen_angles(commands, points).max()) > CAMERA_FOV / 2
