"""robodyn.trajectory.io: CSV, NPZ and Parquet round trips of a floating base with a prismatic joint.

Also here:

- The trajectory file format: names, round trips, refusals that name columns and rows, derived v and a.
"""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn.cli import main
from robodyn.dynamics.dofs import BASE_Q_NAMES as BASE_Q
from robodyn.dynamics.dofs import BASE_V_NAMES as BASE_V
from robodyn.exceptions import InputError, TrajectoryError
from robodyn.sim.simulation import simulate
from robodyn.trajectory import Trajectory, derive_velocities
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


@pytest.fixture(scope="module")
def ur5():
    return robodyn.load("ur5")


@pytest.fixture(scope="module")
def solo():
    return robodyn.load("solo12")


def sine_csv(path, robot, *, t=None, columns=("q",), header=None):
    """A CSV of sine motions of every joint (non-uniform amplitudes and frequencies)."""
    t = np.linspace(0.0, 1.0, 1001) if t is None else t
    amplitude = 0.3 + 0.1 * np.arange(robot.nv)
    omega = 2.0 + 0.7 * np.arange(robot.nv)
    q = amplitude * np.sin(omega * t[:, None] + 0.2)
    values = {
        "q": q,
        "v": amplitude * omega * np.cos(omega * t[:, None] + 0.2),
        "a": -amplitude * omega**2 * np.sin(omega * t[:, None] + 0.2),
    }
    names = header or ["t"] + [f"{kind}[{j}]" for kind in columns for j in robot.joint_names]
    table = np.column_stack([t, *(values[kind] for kind in columns)])
    path.write_text(",".join(names) + "\n" + "\n".join(",".join(map(repr, row)) for row in table.tolist()) + "\n")
    return values


def test_round_trip_csv_npz_keeps_every_number(tmp_path, solo):
    trajectory = simulate(solo, solo.neutral_configuration(), np.zeros(solo.nv), 0.05, 1e-3)
    for suffix in (".csv", ".npz", ".parquet"):
        path = tmp_path / f"solo{suffix}"
        if suffix == ".parquet":
            pytest.importorskip("pyarrow")
            from robodyn.scale.datasets import write_parquet

            write_parquet(path, trajectory)
        else:
            trajectory.save(path)
        back = Trajectory.load(path)
        for kind in ("t", "q", "v", "a", "tau"):
            np.testing.assert_array_equal(getattr(back, kind), getattr(trajectory, kind), err_msg=f"{suffix} {kind}")
        assert back.joint_names == solo.joint_names
        back.check(solo)


def test_floating_base_columns_are_named(tmp_path, solo):
    trajectory = simulate(solo, solo.neutral_configuration(), np.zeros(solo.nv), 0.01, 1e-3)
    header = trajectory.header()
    assert header[1:8] == [f"q[{n}]" for n in BASE_Q]
    assert header[20:26] == [f"v[{n}]" for n in BASE_V]
    assert "q[FL_HAA]" in header and "tau[HR_KFE]" in header and len(header) == 1 + solo.nq + 3 * solo.nv


def test_files_of_robodyn_0_1_still_read(tmp_path, solo, ur5):
    """The old writer: floating q unnamed (q0..), one v name for the base, rows wider than the header."""
    trajectory = simulate(solo, solo.neutral_configuration(), np.zeros(solo.nv), 0.01, 1e-3)
    names = solo.joint_names
    header = ["t", *(f"q{i}" for i in range(solo.nq))] + [f"{k}[{n}]" for k in ("v", "a", "tau") for n in names]
    table = np.column_stack([trajectory.t, trajectory.q, trajectory.v, trajectory.a, trajectory.tau])
    path = tmp_path / "old.csv"
    path.write_text(
        "# robodyn trajectory of solo12; SI units\n"
        + ",".join(header)
        + "\n"
        + "\n".join(",".join(map(repr, r)) for r in table.tolist())
        + "\n"
    )
    back = Trajectory.load(path)
    np.testing.assert_array_equal(back.v, trajectory.v)
    np.testing.assert_array_equal(back.tau, trajectory.tau)
    back.check(solo)
    old_npz = tmp_path / "old.npz"
    np.savez(
        old_npz,
        t=trajectory.t,
        q=trajectory.q,
        v=trajectory.v,
        a=trajectory.a,
        tau=trajectory.tau,
        joint_names=np.array(names),
        robot=np.array("solo12"),
    )
    Trajectory.load(old_npz).check(solo)


def test_npz_one_array_a_column(tmp_path, ur5):
    t = np.linspace(0, 1, 11)
    q = np.outer(t, np.arange(1, 7) * 0.1)
    path = tmp_path / "columns.npz"
    np.savez(path, t=t, **{f"q[{name}]": q[:, i] for i, name in enumerate(ur5.joint_names)})
    back = Trajectory.load(path)
    np.testing.assert_allclose(back.v, np.tile(np.arange(1, 7) * 0.1, (11, 1)), atol=1e-12)  # linear motion: exact
    back.check(ur5)


def test_columns_matched_by_name_not_order(tmp_path, ur5):
    values = sine_csv(tmp_path / "a.csv", ur5, columns=("q", "v"))
    names = ["t"] + [f"{k}[{j}]" for k in ("q", "v") for j in ur5.joint_names]
    order = [0, *range(12, 0, -1)]
    table = np.loadtxt(tmp_path / "a.csv", delimiter=",", skiprows=1)[:, order]
    shuffled = tmp_path / "b.csv"
    shuffled.write_text(",".join(names[i] for i in order) + "\n" + "\n".join(",".join(map(repr, r)) for r in table.tolist()))
    back = Trajectory.load(shuffled)
    with pytest.raises(TrajectoryError, match="another order"):
        back.check(ur5)  # the joints are in reverse order: never used as they are
    ordered = back.for_robot(ur5)
    ordered.check(ur5)
    np.testing.assert_array_equal(ordered.q, values["q"])
    np.testing.assert_array_equal(ordered.v, values["v"])


def test_six_q_columns_for_ur5_report_six(tmp_path, ur5):
    """Issue 13: six q columns were reported as '5 coordinates a sample' (the implicit t)."""
    q = np.random.default_rng(0).uniform(-1, 1, (5, 6))
    with_header = tmp_path / "named.csv"
    with_header.write_text(
        ",".join(f"q[{j}]" for j in ur5.joint_names) + "\n" + "\n".join(",".join(map(repr, r)) for r in q.tolist())
    )
    with pytest.raises(TrajectoryError, match=r"no 't' column.*6 q columns"):
        Trajectory.load(with_header)
    bare = tmp_path / "bare.csv"
    bare.write_text("\n".join(",".join(map(repr, r)) for r in q.tolist()))
    with pytest.raises(TrajectoryError, match=r"no header line: the first row has 6 numbers"):
        Trajectory.load(bare)
    fixed = tmp_path / "fixed.csv"
    rows = "\n".join(f"{0.1 * i}," + ",".join(map(repr, r)) for i, r in enumerate(q.tolist()))
    fixed.write_text("t," + ",".join(f"q[{j}]" for j in ur5.joint_names) + "\n" + rows)
    trajectory = Trajectory.load(fixed)
    assert trajectory.q.shape == (5, 6)
    trajectory.check(ur5)


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (lambda h: [*h, "w[x]"], r"unknown columns w\[x\]"),
        (lambda h: h[:8] + h[9:], r"missing columns v\[shoulder_lift_joint\]"),
        (lambda h: [*h, "tau[nope]"], r"tau\[nope\] have no matching q column"),
        (lambda h: [*h, "q[shoulder_pan_joint]"], r"duplicated columns q\[shoulder_pan_joint\]"),
        (lambda h: ["time", *h[1:]], r"unknown columns time"),
    ],
)
def test_header_errors_name_the_columns(tmp_path, ur5, edit, message):
    header = ["t"] + [f"{k}[{j}]" for k in ("q", "v") for j in ur5.joint_names]
    header = edit(header)
    path = tmp_path / "bad.csv"
    path.write_text(",".join(header) + "\n" + ",".join(["0.5"] * len(header)) + "\n" + ",".join(["0.6"] * len(header)) + "\n")
    with pytest.raises(TrajectoryError, match=message):
        Trajectory.load(path)


@pytest.mark.parametrize(
    ("row", "value", "message"), [(4, "nan", r"row 4: v\[elbow_joint\] is nan"), (7, "inf", r"row 7: v\[elbow_joint\] is inf")]
)
def test_non_finite_values_refused_with_row_and_column(tmp_path, ur5, row, value, message):
    sine_csv(tmp_path / "m.csv", ur5, columns=("q", "v"))
    lines = (tmp_path / "m.csv").read_text().splitlines()
    cells = lines[row].split(",")
    cells[9] = value  # t, 6 q, then v[shoulder_pan], v[shoulder_lift], v[elbow]
    lines[row] = ",".join(cells)
    (tmp_path / "m.csv").write_text("\n".join(lines))
    with pytest.raises(TrajectoryError, match=message):
        Trajectory.load(tmp_path / "m.csv")


def test_time_must_increase(tmp_path, ur5):
    t = np.linspace(0, 1, 20)
    t[12] = t[11]
    sine_csv(tmp_path / "m.csv", ur5, t=t)
    with pytest.raises(TrajectoryError, match=r"row 13: time does not increase"):
        Trajectory.load(tmp_path / "m.csv")
    t[12] = t[10]  # decreasing
    sine_csv(tmp_path / "m.csv", ur5, t=t)
    with pytest.raises(TrajectoryError, match=r"row 13: time does not increase"):
        Trajectory.load(tmp_path / "m.csv")


def test_only_t_and_q_derives_v_and_a_to_second_order(tmp_path, ur5):
    """Against the closed-form derivatives of a sine: error falls as h² (a: h on the two end rows)."""
    errors = []
    for samples in (501, 1001):
        t = np.linspace(0.0, 1.0, samples)
        exact = sine_csv(tmp_path / "q.csv", ur5, t=t)
        trajectory = Trajectory.load(tmp_path / "q.csv")
        errors.append(
            (
                np.abs(trajectory.v - exact["v"]).max(),
                np.abs(trajectory.a[2:-2] - exact["a"][2:-2]).max(),
                np.abs(trajectory.a - exact["a"]).max(),
            )
        )
    (v1, a1, e1), (v2, a2, e2) = errors
    assert v2 < 2e-4 and a2 < 2e-3  # h = 1e-3; |q'''| ≤ 0.8 · 5.5³
    assert 3.5 < v1 / v2 < 4.5 and 3.5 < a1 / a2 < 4.5  # second order
    assert 1.6 < e1 / e2 < 4.5  # the end rows: first order at worst
    assert trajectory.tau is None


def test_derived_floating_base_velocity_matches_pinocchio(solo):
    """v derived from the sampled q of a simulated tumble equals the simulated v (base frame, angular from the quaternion)."""
    rng = np.random.default_rng(1)
    v0 = rng.normal(size=solo.nv)
    q0 = solo.floating_configuration([0.1, -0.2, 0.3], [0.4, -0.3, 0.9], rng.uniform(-0.5, 0.5, 12))
    trajectory = simulate(solo, q0, v0, 0.3, 1e-3)
    derived = derive_velocities(trajectory.t, trajectory.q, floating_base=True)
    assert np.abs(derived[1:-1] - trajectory.v[1:-1]).max() < 1e-4 * np.abs(trajectory.v).max()
    negated = trajectory.q.copy()
    negated[::3, 3:7] *= -1  # the same rotations with flipped quaternion signs
    np.testing.assert_allclose(derive_velocities(trajectory.t, negated, floating_base=True), derived, atol=1e-9)
    wrong = derive_velocities(trajectory.t, trajectory.q, floating_base=False)[:, 3:6]  # negative control: components, not ω
    assert np.abs(wrong - trajectory.v[:, 3:6]).max() > 0.1


def test_check_refuses_another_robot(tmp_path, ur5):
    panda = robodyn.load("panda")
    trajectory = simulate(panda, panda.neutral_configuration(), np.zeros(panda.nv), 0.01, 1e-3)
    trajectory.save(tmp_path / "p.csv")
    loaded = Trajectory.load(tmp_path / "p.csv")
    loaded.check(panda)
    with pytest.raises(
        TrajectoryError, match=r"p\.csv: a trajectory of 'panda' with 8 q and 8 v columns does not fit robot 'ur5'"
    ):
        loaded.check(ur5)


def test_check_names_missing_and_extra(tmp_path, ur5):
    names = ["a_joint", *ur5.joint_names[1:]]
    sine_csv(tmp_path / "m.csv", ur5, header=["t"] + [f"q[{n}]" for n in names])
    with pytest.raises(TrajectoryError, match=r"missing q\[shoulder_pan_joint\]; extra q\[a_joint\]"):
        Trajectory.load(tmp_path / "m.csv").check(ur5)


def test_hostile_joint_names_survive_the_csv(tmp_path):
    t = np.linspace(0, 1, 5)
    trajectory = Trajectory(t, np.c_[t, 2 * t], np.ones((5, 2)), np.zeros((5, 2)), None, ['a,"b"', "c\nd"], "x\ny")
    trajectory.save(tmp_path / "h.csv")
    back = Trajectory.load(tmp_path / "h.csv")
    assert back.joint_names == ['a,"b"', "c\nd"]
    np.testing.assert_array_equal(back.q, trajectory.q)


def test_readme_chain_simulate_then_record(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert (
        main(["simulate", "rp_arm", "--controller", "task-space", "--target", "0.7,0.7", "--duration", "0.2", "--out", "m.csv"])
        == 0
    )
    assert main(["record", "rp_arm", "--trajectory", "m.csv", "--out", "m.html"]) == 0
    assert (tmp_path / "m.html").stat().st_size > 1000
    assert main(["simulate", "panda", "--duration", "0.05", "--out", "m.npz"]) == 0
    assert main(["record", "panda", "--trajectory", "m.npz", "--out", "panda.html"]) == 0


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
