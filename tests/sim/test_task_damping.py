"""The variable damping's parts (:mod:`robodyn.sim.task_damping`) against what they are
defined as: the chain's length summed by hand on a branched robot, the scaled Gram matrix
and its singular value against NumPy's SVD of ``S J``, the generic rank unchanged by the
robot's scale, and each switch of the damping at the value where it turns."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn.sim.task_damping import (
    characteristic_length,
    damped_task_inertia,
    generic_rank,
    relative_singular_value,
    scaled_gram,
    total_damping,
    variable_damping,
)


def _link(name: str) -> str:
    inertia = '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/>'
    return f'<link name="{name}"><inertial><mass value="1"/>{inertia}</inertial></link>'


def _joint(name: str, parent: str, child: str, xyz: str, kind: str = "revolute", axis: str = "0 0 1") -> str:
    limit = '<limit lower="-3" upper="3" effort="10" velocity="5"/>' if kind == "revolute" else ""
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xyz}"/><axis xyz="{axis}"/>{limit}</joint>'
    )


# The branch first in the file, so that the arm's chain does not hold joint 1.
BRANCHED = (
    '<robot name="branched">'
    + "".join(_link(name) for name in ("base", "side", "tip", "l1", "l2", "l3", "tool"))
    + _joint("b1", "base", "side", "0 0.2 0")
    + _joint("bt", "side", "tip", "0.1 0 0", kind="fixed")
    + _joint("j1", "base", "l1", "0 0 0.5")
    + _joint("j2", "l1", "l2", "0.3 0 0.4", axis="0 1 0")
    + _joint("j3", "l2", "l3", "0.6 0.8 0", axis="0 1 0")
    + _joint("tt", "l3", "tool", "0 0 0.2", kind="fixed")
    + "</robot>"
)


def test_the_characteristic_length_sums_the_offsets_past_the_first_moving_joint():
    robot = robodyn.load(BRANCHED)
    assert characteristic_length(robot, "tool") == pytest.approx(0.2 + 0.5 + 1.0, abs=1e-15)  # j1's 0.5 m left out
    assert characteristic_length(robot, "l2") == pytest.approx(0.5, abs=1e-15)
    assert characteristic_length(robot, "tip") == pytest.approx(0.1, abs=1e-15)  # shorter than 1 m: kept
    assert characteristic_length(robot, "l1") == 1.0  # on the first joint's axis: 1 m


def test_the_scaled_gram_and_its_singular_value_are_those_of_s_j():
    rng = np.random.default_rng(39)
    jacobian, length = rng.integers(-3, 4, size=(6, 4)), 0.37  # integers: the rows are scaled as floats
    scaled = np.diag([1, 1, 1, length, length, length]) @ jacobian
    np.testing.assert_allclose(scaled_gram(jacobian, length), scaled @ scaled.T / length**2, rtol=1e-13, atol=1e-13)
    singular = np.linalg.svd(scaled, compute_uv=False) / length
    for rank in (1, 2, 4):
        assert relative_singular_value(jacobian, length, rank) == pytest.approx(singular[rank - 1], rel=1e-10)
    assert relative_singular_value(jacobian, length, 0) == 0.0  # no generic rank: no singular value
    assert relative_singular_value(jacobian[:3], length, 0) == 0.0  # though all three rows are independent
    assert np.linalg.svd(jacobian[:3], compute_uv=False)[-1] > 0.1


class _Scaled:
    """A stand-in robot whose position Jacobian has the singular values ``scale · (1, 1e-6, 1e-12)``."""

    def __init__(self, scale: float) -> None:
        self.scale = scale
        self.rng = np.random.default_rng(7)

    def random_configuration(self, rng: np.random.Generator) -> np.ndarray:
        return rng.normal(size=3)

    def frame_jacobian(self, q: np.ndarray, frame: str) -> np.ndarray:
        u, _ = np.linalg.qr(self.rng.normal(size=(3, 3)))
        v, _ = np.linalg.qr(self.rng.normal(size=(3, 3)))
        return np.vstack([self.scale * u @ np.diag([1.0, 1e-6, 1e-12]) @ v.T, np.zeros((3, 3))])


@pytest.mark.parametrize("scale", [1e-10, 1e-6, 1.0, 1e6])
def test_the_generic_rank_is_relative_to_the_largest_singular_value_at_any_scale(scale):
    assert generic_rank(_Scaled(scale), "tool", 3) == 2  # type: ignore[arg-type]
    assert generic_rank(_Scaled(scale), "tool", 6) == 2  # type: ignore[arg-type]


def test_a_frame_no_joint_moves_has_rank_0_and_one_joint_rank_1():
    robot = robodyn.load(BRANCHED)
    assert generic_rank(robot, "base", 6) == 0
    assert generic_rank(robot, "tip", 3) == 1


def test_each_switch_of_the_damping_turns_at_its_own_value():
    assert variable_damping(0.03, 0.05, 1.0) == pytest.approx(0.8, rel=1e-15)  # a maximum of 1 is not "off"
    assert variable_damping(0.03, 0.05, 0.0) == 0.0
    assert total_damping(1e-8, 1.0) == pytest.approx(1.0, rel=1e-15)  # a variable part of 1 is not "off"
    assert total_damping(3.0, 4.0) == 5.0
    inverse = np.diag([1.0, 2.0])  # damping · largest = 1: the floor is exactly 1
    np.testing.assert_allclose(damped_task_inertia(inverse, 0.5), np.diag([1 / 2, 2 / 5]), rtol=1e-15)
