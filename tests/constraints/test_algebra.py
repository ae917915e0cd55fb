"""The constraint algebra's rotation logarithm against an independent one (SciPy's rotation
vector), across the small-angle, general and half-turn branches."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from robodyn.constraints.algebra import rotation_log

AXIS = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])


@pytest.mark.parametrize("angle", [0.0, 1e-9, 3e-7, 2e-6, 0.4, 2.0, 2.5, np.pi - 2e-6, np.pi - 3e-7, np.pi])
@pytest.mark.parametrize("axis", [AXIS, -AXIS, np.array([0.0, 0.0, 1.0]), np.array([-1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])])
def test_the_rotation_log_is_the_rotation_vector_of_every_angle(axis, angle):
    rotation = Rotation.from_rotvec(axis * angle).as_matrix()
    vector = rotation_log(rotation)
    assert np.linalg.norm(vector) == pytest.approx(angle, abs=1e-12, rel=1e-9)
    assert np.allclose(Rotation.from_rotvec(vector).as_matrix(), rotation, atol=1e-12)
    if angle < np.pi:  # below a half turn the vector is unique
        assert np.allclose(vector, axis * angle, atol=1e-12, rtol=1e-9)


def test_negative_control_a_rotation_vector_check_tells_a_wrong_vector():
    rotation = Rotation.from_rotvec(AXIS * 2.0).as_matrix()
    assert not np.allclose(Rotation.from_rotvec(AXIS * 2.0 * 1.001).as_matrix(), rotation, atol=1e-12)


def _random_rotation(rng: np.random.Generator) -> np.ndarray:
    return Rotation.from_rotvec(rng.normal(size=3)).as_matrix()


def test_the_layout_gives_stacks_rows_for_every_kind_and_a_swapped_end_is_caught(rng):
    from robodyn.constraints import FrameAnchor, PointAnchor, PointContact
    from robodyn.constraints.algebra import EndKinematics, Layout, bind, stack, world_end

    poses = {link: (_random_rotation(rng), rng.normal(size=3)) for link in "abc"}
    constraints = [
        PointAnchor("a", (0.1, 0.2, 0.3), "b", (0.0, -0.1, 0.2)),
        PointAnchor("c", (0.3, 0.0, 0.1)),  # held on the world
        FrameAnchor("b", (0.1, 0.0, 0.2, 0.3, -0.2, 0.1), "c", (0.0, 0.1, 0.0, 0.0, 0.4, 0.0)),
        FrameAnchor("a", (0.0, 0.0, 0.1, 0.2, 0.1, 0.0)),
        PointContact("c", (0.0, 0.1, 0.0), normal=(0.2, -0.3, 0.9), friction=0.5, plane_point=(0.1, 0.2, -0.3)),
        PointContact("b", (0.2, 0.0, 0.0), normal=(0.0, 0.6, 0.8), friction=0.0, plane_point=(0.0, 0.0, 0.4)),
    ]
    bounds = bind(constraints, lambda link: poses[link])
    nv = 5
    moving = {}
    for bound in bounds:
        for end in (bound.first, bound.second):
            if end.link is not None:
                moving[id(end)] = EndKinematics(
                    rng.normal(size=3), _random_rotation(rng), *rng.normal(size=(2, 3, nv)), *rng.normal(size=(2, 3))
                )

    def kinematics(end):
        return moving[id(end)] if end.link is not None else world_end(end, nv)

    expected = stack(bounds, kinematics, nv)
    layout = Layout(bounds)
    ends = [end for bound in bounds for end in (bound.first, bound.second)]
    linked = [moving[id(ends[number])] for number in layout.linked]

    def assembled(kinematics: list) -> tuple:
        return layout.assemble(
            np.array([k.position for k in kinematics]),
            [k.rotation for k in kinematics],
            np.array([np.vstack([k.linear, k.angular]) for k in kinematics]),
            np.array([np.concatenate([k.linear_drift, k.angular_drift]) for k in kinematics]),
        )

    assert layout.rows == sum(c.rows for c in constraints) == len(expected[0])
    for ours, theirs in zip(assembled(linked), expected, strict=True):
        assert ours.shape == theirs.shape
        assert np.allclose(ours, theirs, rtol=0.0, atol=1e-14)
    # the same check with the first two linked ends swapped (a loop closure's sign) fails
    for ours, theirs in zip(assembled([linked[1], linked[0], *linked[2:]])[1:], expected[1:], strict=True):
        assert not np.allclose(ours, theirs, rtol=0.0, atol=1e-3)
