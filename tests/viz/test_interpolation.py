"""A floating base drawn between recorded samples: a rotation, the samples' own at sample
times, and on the shorter arc between two samples.

``robodyn.viz.scene.motion`` resamples a trajectory at the animation's frame rate. A
base's orientation in between must be a rotation (det 1, orthonormal), equal the sample's
at a sample's time, and turn the short way from one sample to the next: ``q`` and ``−q``
are one rotation, and a file may hold either (a yaw across ±180° with ``w ≥ 0`` flips the
sign), so interpolating the four numbers as they stand can swing the base the long way
round, or through a zero quaternion.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import robodyn
from robodyn.trajectory import Trajectory
from robodyn.viz.scene import motion
from tests.conftest import ROOT


@pytest.fixture(scope="module")
def floating():
    return robodyn.load(ROOT / "tests" / "data" / "robots" / "oblique.urdf", floating_base=True)


def rotation(quaternion: np.ndarray) -> np.ndarray:
    """Rotation matrix of an (x, y, z, w) quaternion, normalised."""
    x, y, z, w = np.asarray(quaternion, float) / np.linalg.norm(quaternion)
    return pin.Quaternion(w, x, y, z).toRotationMatrix()


def angle(first: np.ndarray, second: np.ndarray) -> float:
    """The angle of the rotation taking ``first`` to ``second``, in [rad]."""
    return float(np.arccos(np.clip((np.trace(first.T @ second) - 1) / 2, -1.0, 1.0)))


def samples(robot: robodyn.Robot, quaternions: np.ndarray) -> Trajectory:
    """One sample a second, the base at the given orientations, joints moving a little."""
    count = len(quaternions)
    q = np.zeros((count, robot.nq))
    q[:, :3] = np.linspace([0.0, 0.0, 0.5], [0.3, -0.2, 0.7], count)
    q[:, 3:7] = quaternions
    q[:, 7:] = np.linspace(-0.2, 0.2, count)[:, None]
    zeros = np.zeros((count, robot.nv))
    return Trajectory(np.arange(float(count)), q, zeros, zeros, zeros, list(robot.joint_names), robot.name)


def yaw(degrees: float, tilt: float = 0.0) -> np.ndarray:
    """(x, y, z, w) of a yaw then a tilt about x, with w >= 0 (a file's usual sign)."""
    matrix = pin.rpy.rpyToMatrix(np.radians(tilt), 0.0, np.radians(degrees))
    quaternion = pin.Quaternion(matrix).coeffs()
    return quaternion if quaternion[3] >= 0 else -quaternion


def check_drawn(robot: robodyn.Robot, trajectory: Trajectory, fps: float) -> None:
    moved, _clips = motion(robot, trajectory, fps)
    drawn = [rotation(c[3:7]) for c in moved.configurations]
    for matrix in drawn:
        assert np.isfinite(matrix).all()
        assert abs(np.linalg.det(matrix) - 1) < 1e-12 and np.abs(matrix.T @ matrix - np.eye(3)).max() < 1e-12
    sampled = [rotation(q[3:7]) for q in trajectory.q]
    per_second = round(fps)
    for index, matrix in enumerate(sampled):  # at a sample's time: the sample
        assert np.abs(drawn[index * per_second] - matrix).max() < 1e-12
    for index in range(len(sampled) - 1):  # between two samples: on the shorter arc
        first, second = sampled[index], sampled[index + 1]
        for matrix in drawn[index * per_second : (index + 1) * per_second + 1]:
            assert angle(first, matrix) + angle(matrix, second) <= angle(first, second) + 1e-9
    # The base link's drawn pose (the clip meshcat plays) is the drawn configuration's.
    base = robot.spec.root
    for frame, placement in enumerate(moved.placements):
        assert np.abs(placement[base][:3, :3] - drawn[frame]).max() < 1e-12


def test_a_base_turning_slowly_is_drawn_as_rotations_through_its_samples(floating):
    check_drawn(floating, samples(floating, np.array([yaw(0), yaw(40, 20), yaw(100, -30), yaw(120, 10)])), fps=8)


def test_a_yaw_across_180_degrees_with_the_sign_flipped_turns_the_short_way(floating):
    # 170° then 190°: the file's w >= 0 flips the sign between them.
    trajectory = samples(floating, np.array([yaw(170), yaw(190), yaw(210, 5)]))
    assert np.dot(trajectory.q[0, 3:7], trajectory.q[1, 3:7]) < 0  # the case itself
    check_drawn(floating, trajectory, fps=8)


def test_one_orientation_written_with_both_signs_stays_still(floating):
    quaternion = yaw(60, 25)
    trajectory = samples(floating, np.array([quaternion, -quaternion]))
    moved, _ = motion(floating, trajectory, 8)
    for configuration in moved.configurations:
        assert np.abs(rotation(configuration[3:7]) - rotation(quaternion)).max() < 1e-12


def test_the_check_sees_a_base_turning_the_long_way():  # negative control
    first, second = rotation(yaw(170)), rotation(yaw(190))
    long_way = rotation(yaw(0))  # what interpolating 170° to −170° through 0° draws halfway
    assert angle(first, long_way) + angle(long_way, second) > angle(first, second) + 1.0
