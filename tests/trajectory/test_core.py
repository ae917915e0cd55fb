"""robodyn.trajectory.core: the Trajectory type checked and reordered against the robot's dofs."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn.exceptions import TrajectoryError
from robodyn.trajectory import Trajectory
from tests.conftest import ROOT


@pytest.fixture(scope="module")
def arm():
    return robodyn.load(ROOT / "tests" / "data" / "rrp_arm.urdf", floating_base=True)


def test_robodyn_trajectory_is_the_packages_type():
    assert robodyn.Trajectory is Trajectory and Trajectory.__module__ == "robodyn.trajectory.core"


def test_the_header_is_named_by_the_robots_dofs(arm):
    samples = 4
    trajectory = Trajectory(
        np.arange(samples) * 0.1,
        np.tile(arm.neutral_configuration(), (samples, 1)),
        np.zeros((samples, arm.nv)),
        np.zeros((samples, arm.nv)),
        np.zeros((samples, arm.nv)),
        list(arm.joint_names),
        arm.name,
    )
    dofs = [dof.name for dof in arm.dofs]
    expected = ["t", *(f"q[{n}]" for n in arm.configuration_names)] + [f"{k}[{n}]" for k in ("v", "a", "tau") for n in dofs]
    assert trajectory.header() == expected and trajectory.table().shape == (samples, len(expected))
    assert trajectory.coordinate_names == (arm.configuration_names, dofs)
    trajectory.check(arm)


def test_for_robot_puts_a_shuffled_file_in_the_robots_order(tmp_path, arm, rng):
    q = np.array([arm.integrate(arm.neutral_configuration(), rng.normal(size=arm.nv)) for _ in range(5)])
    names = list(arm.configuration_names)
    order = [*range(7), 9, 7, 8]  # the base first, then the joints shuffled
    path = tmp_path / "shuffled.csv"
    rows = "\n".join(",".join(map(repr, [0.1 * i, *row[order].tolist()])) for i, row in enumerate(q))
    path.write_text("t," + ",".join(f"q[{names[i]}]" for i in order) + "\n" + rows + "\n")
    loaded = Trajectory.load(path)
    with pytest.raises(TrajectoryError, match="another order"):
        loaded.check(arm)
    reordered = loaded.for_robot(arm)
    np.testing.assert_array_equal(reordered.q, q)
    assert reordered.joint_names == arm.joint_names
    reordered.check(arm)


def test_a_trajectory_of_another_robot_is_refused_naming_the_robots_columns(arm):
    fixed = robodyn.load(ROOT / "tests" / "data" / "rrp_arm.urdf", floating_base=False)
    samples = 3
    trajectory = Trajectory(np.arange(samples) * 0.1, np.zeros((samples, 3)), np.zeros((samples, 3)), np.zeros((samples, 3)))
    trajectory.check(fixed)
    with pytest.raises(
        TrajectoryError, match=r"nq = 10, nv = 9: q\[base\.x\], q\[base\.y\], q\[base\.z\], q\[base\.qx\] and 6 more"
    ):
        trajectory.check(arm)
