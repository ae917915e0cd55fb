"""Simulation under constraints: a four-bar's passive swing stays closed (≤ 1e-9 m), follows
Freudenstein's position solution (≤ 1e-8 rad) and keeps its energy; the step is a pure
function; the result is a Trajectory; refusals."""

from __future__ import annotations

import math

import numpy as np
import pytest

from robodyn.constraints import PointAnchor
from robodyn.exceptions import InputError
from robodyn.sim.constrained import constrained_rk4_step, simulate_constrained
from tests.constraints.linkages import closed_configuration, freudenstein, load_linkage, rocker_angle


def rocker_errors(robot, trajectory, name: str, coupler: float | None = None) -> np.ndarray:
    """|rocker angle − Freudenstein's| along a motion, in [rad] (``coupler``: a wrong length,
    for the negative control)."""
    crank = trajectory.q[:, robot.joint_names.index("crank_joint")]
    rocker = trajectory.q[:, robot.joint_names.index("rocker_joint")]
    expected = np.array([rocker_angle(name, c) for c in crank])
    if coupler is not None:
        from tests.constraints import linkages

        saved = linkages.FOUR_BARS[name]
        linkages.FOUR_BARS[name] = (saved[0], coupler, saved[2], saved[3])
        try:
            expected = np.array([rocker_angle(name, c) for c in crank])
        finally:
            linkages.FOUR_BARS[name] = saved
    return np.abs((rocker - expected + math.pi) % (2 * math.pi) - math.pi)


def energy(robot, trajectory) -> np.ndarray:
    return np.array(
        [robot.kinetic_energy(q, v) + robot.potential_energy(q) for q, v in zip(trajectory.q, trajectory.v, strict=True)]
    )


def swing(duration: float):
    robot = load_linkage("four_bar")
    run = simulate_constrained(robot, closed_configuration(robot, "four_bar", 0.3), duration=duration, dt=1e-3)
    return robot, run


def check_swing(robot, run) -> None:
    trajectory = run.trajectory
    assert run.residual.max() <= 1e-9
    assert rocker_errors(robot, trajectory, "four_bar").max() <= 1e-8
    crank, rocker = (trajectory.q[:, robot.joint_names.index(j)] for j in ("crank_joint", "rocker_joint"))
    assert max(abs(freudenstein("four_bar", c, r)) for c, r in zip(crank, rocker, strict=True)) < 1e-8
    total = energy(robot, trajectory)
    scale = np.abs(total - total.min()).max() + abs(total[0])
    assert np.abs(total - total[0]).max() <= 1e-6 * scale
    assert np.ptp(crank) > 1.0  # it did swing


def test_a_passive_four_bar_stays_closed_follows_freudenstein_and_keeps_its_energy():
    robot, run = swing(0.6)
    check_swing(robot, run)
    assert run.initial_correction < 1e-12
    assert rocker_errors(robot, run.trajectory, "four_bar", coupler=0.3501).max() > 1e-5  # the checker can fail


@pytest.mark.slow
def test_a_passive_four_bar_stays_closed_for_ten_seconds():
    robot, run = swing(10.0)
    check_swing(robot, run)


@pytest.mark.parametrize("name", ["parallelogram", "slider_crank", "four_bar_3d"])
def test_the_other_linkages_stay_closed(name, rng):
    robot = load_linkage(name)
    q0 = robot.neutral_configuration() + 0.3 * rng.normal(size=robot.nq)
    if name == "parallelogram":
        q0 = closed_configuration(robot, name, 0.9)
    run = simulate_constrained(robot, q0, rng.normal(size=robot.nv), duration=0.1, dt=1e-3, tau=rng.normal(size=robot.nv))
    assert run.residual.max() <= 1e-9
    jacobian = robot.constraint_jacobian(run.trajectory.q)
    assert np.abs(np.einsum("nij,nj->ni", jacobian, run.trajectory.v)).max() < 1e-9


def test_the_step_is_a_pure_function_and_the_result_a_trajectory(tmp_path):
    robot, run = swing(0.01)
    q, v = run.trajectory.q[0].copy(), run.trajectory.v[0].copy()
    first = constrained_rk4_step(robot, q, v, None, 1e-3)
    assert np.array_equal(first[0], constrained_rk4_step(robot, q, v, None, 1e-3)[0])
    assert np.array_equal(q, run.trajectory.q[0])
    assert np.allclose(first[0], run.trajectory.q[1], atol=0, rtol=0)
    run.trajectory.check(robot)
    path = run.trajectory.save(tmp_path / "swing.npz")
    assert path.exists()
    assert run.multipliers.shape == (len(run.trajectory), 3)


def test_bad_steps_and_unreachable_constraints_are_refused():
    robot = load_linkage("four_bar")
    with pytest.raises(InputError, match="dt"):
        simulate_constrained(robot, np.zeros(3), duration=1.0, dt=0.0)
    with pytest.raises(InputError, match="q0"):
        simulate_constrained(robot, np.zeros((2, 3)), duration=0.01)
    with pytest.raises(InputError, match="tau"):
        constrained_rk4_step(robot, np.zeros(3), np.zeros(3), [1.0, 2.0], 1e-3)
    far = PointAnchor("coupler", (0.35, 0, 0), None, (5.0, 0.0, 0.0))
    with pytest.raises(InputError, match="constraints"):
        simulate_constrained(robot, np.zeros(3), constraints=[far], duration=0.01, dt=1e-3)


def test_solo12_held_by_its_feet_and_the_contact_torques_stands_still():
    import robodyn
    from robodyn.constraints import PointContact
    from tests.dynamics.test_constrained import FEET

    robot = robodyn.load("solo12", gravity=(0.3, -0.2, -9.7))
    q = robot.floating_configuration([0.1, -0.2, 0.3], [0.05, -0.04, 0.7], np.tile([0.1, 0.8, -1.6], 4))
    feet = [PointContact(foot, friction=0.7, plane_point=robot.frame_position(q, foot)) for foot in FEET]  # feet on the ground
    zero = np.zeros(robot.nv)
    tau, _ = robot.contact_inverse_dynamics(q, zero, zero, feet)
    run = simulate_constrained(robot, q, constraints=feet, duration=0.03, dt=1e-3, tau=tau)
    assert np.abs(run.trajectory.q - q).max() < 1e-9 and np.abs(run.trajectory.v).max() < 1e-9
    assert abs(np.linalg.norm(run.trajectory.q[-1, 3:7]) - 1.0) < 1e-12


def test_the_csv_has_a_column_a_multiplier_row_and_they_are_the_dynamics_lambda_at_the_recorded_states(tmp_path, rng):
    from pathlib import Path

    import robodyn
    from robodyn.constraints.files import read_constraints
    from robodyn.trajectory import Trajectory
    from robodyn.trajectory.columns import constraint_columns
    from robodyn.trajectory.io import read_table

    examples = Path(__file__).resolve().parents[2] / "examples"
    robot = robodyn.load(str(examples / "four_bar.urdf"), constraints=read_constraints(examples / "four_bar_constraints.yaml"))
    tau = rng.normal(size=robot.nv)
    run = simulate_constrained(robot, robot.neutral_configuration(), rng.normal(size=robot.nv), duration=0.03, tau=tau)
    written = run.save(tmp_path / "four_bar.csv")
    table, layout, _ = read_table(written)
    assert [name for name in layout.header if name.startswith("lambda")] == [f"lambda[loop].{a}" for a in "xyz"]
    back = Trajectory.load(written)  # a trajectory reader skips the multipliers
    assert np.array_equal(back.q, run.trajectory.q)
    lam = constraint_columns(list(layout.header), table, run.labels)
    expected = robot.constrained_forward_dynamics(back.q, back.v, back.tau)[1]
    assert np.abs(lam - expected).max() <= 1e-9 * np.abs(expected).max()
    assert np.abs(lam[1:] - expected[:-1]).max() > 1e-3  # one row late: the check can fail
    (name, peak, torque), *_ = run.peak_forces()
    assert (name, torque) == ("loop", None) and peak == pytest.approx(np.linalg.norm(lam, axis=1).max(), rel=1e-12)
    lines = run.summary_lines()
    assert float(lines[0].split("run ")[1].split(" m")[0]) <= 1e-9 and "'loop': |λ|" in lines[1]
    with pytest.raises(InputError, match="csv"):
        run.save(tmp_path / "four_bar.npz")
