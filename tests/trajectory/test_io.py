"""robodyn.trajectory.io: CSV, NPZ and Parquet round trips of a floating base with a prismatic joint."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn.exceptions import InputError, TrajectoryError
from robodyn.trajectory import Trajectory
from robodyn.trajectory.io import read_table, write_csv
from tests.conftest import ROOT

#: A revolute-revolute-prismatic arm; loaded with a floating base it has every kind of coordinate.
ARM = ROOT / "tests" / "data" / "rrp_arm.urdf"


@pytest.fixture(scope="module")
def arm():
    robot = robodyn.load(ARM, floating_base=True)
    assert robot.floating_base and {dof.kind for dof in robot.dofs} == {"linear", "angular"}
    assert any(dof.joint_type == "prismatic" for dof in robot.dofs)
    return robot


def motion(robot, samples: int = 50) -> Trajectory:
    """A smooth motion of every coordinate (base pose through ``robot.integrate``), with torques."""
    t = np.linspace(0.0, 0.49, samples)
    rates = 0.2 + 0.1 * np.arange(robot.nv)
    q = np.array([robot.integrate(robot.neutral_configuration(), rates * np.sin(3.0 * s)) for s in t])
    v = np.outer(3.0 * np.cos(3.0 * t), rates)
    a = np.outer(-9.0 * np.sin(3.0 * t), rates)
    tau = np.cumsum(np.ones((samples, robot.nv)), axis=0) / 7.0
    return Trajectory(t, q, v, a, tau, list(robot.joint_names), robot.name)


def write(trajectory: Trajectory, path):
    if path.suffix == ".parquet":
        pytest.importorskip("pyarrow")
        from robodyn.scale.datasets import write_parquet

        return write_parquet(path, trajectory)
    return trajectory.save(path)


@pytest.mark.parametrize("suffix", [".csv", ".npz", ".parquet"])
def test_a_floating_base_with_a_prismatic_joint_reads_back_every_number(tmp_path, arm, suffix):
    trajectory = motion(arm)
    back = Trajectory.load(write(trajectory, tmp_path / f"arm{suffix}"))
    for kind in ("t", "q", "v", "a", "tau"):
        np.testing.assert_array_equal(getattr(back, kind), getattr(trajectory, kind), err_msg=kind)
    assert back.joint_names == arm.joint_names and back.robot == arm.name
    back.check(arm)


@pytest.mark.parametrize("suffix", [".csv", ".npz", ".parquet"])
def test_the_columns_are_named_by_the_robots_dofs(tmp_path, arm, suffix):
    _, layout, robot = read_table(write(motion(arm), tmp_path / f"arm{suffix}"))
    assert list(layout.q_names) == arm.configuration_names
    assert list(layout.v_names) == [dof.name for dof in arm.dofs]
    assert layout.floating_base and robot == arm.name
    assert layout.header[1 : 1 + arm.nq] == tuple(f"q[{name}]" for name in arm.configuration_names)


def test_positions_alone_read_back_with_derived_velocities(tmp_path, arm):
    trajectory = motion(arm, samples=400)
    path = tmp_path / "q_only.csv"
    header = ["t", *(f"q[{name}]" for name in arm.configuration_names)]
    write_csv(path, arm.name, header, np.column_stack([trajectory.t, trajectory.q]))
    back = Trajectory.load(path)
    np.testing.assert_allclose(back.v[2:-2], trajectory.v[2:-2], atol=2e-4)
    assert back.tau is None


def test_a_file_that_is_not_a_trajectory_is_refused_naming_it(tmp_path):
    with pytest.raises(InputError, match="path"):
        read_table(tmp_path / "motion.txt")
    with pytest.raises(TrajectoryError, match="no such file"):
        read_table(tmp_path / "missing.csv")
    broken = tmp_path / "broken.npz"
    broken.write_bytes(b"not a zip file")
    with pytest.raises(TrajectoryError, match=r"broken\.npz: not a readable trajectory"):
        read_table(broken)


def test_a_csv_with_only_a_header_is_one_error_and_no_numpy_warning(tmp_path, capsys):
    # Issue 29, item 8: numpy's "loadtxt: input contained no data" used to leak before the error.
    import warnings

    from robodyn.cli import main

    path = tmp_path / "header_only.csv"
    path.write_text("t,q[joint1],q[joint2]\n")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with pytest.raises(TrajectoryError, match="no data rows"):
            Trajectory.load(path)
    assert caught == []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert main(["record", "rp_arm", "--trajectory", str(path), "--out", str(tmp_path / "m.html")]) == 2
    err = capsys.readouterr().err
    assert caught == [] and err.count("\n") == 1 and "no data rows" in err
