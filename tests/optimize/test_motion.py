"""robodyn.optimize.point_to_point: motions that obey the dynamics and the limits, replayed by robodyn.simulate."""

from __future__ import annotations

import json
import time
from dataclasses import replace

import numpy as np
import pinocchio as pin
import pytest

import robodyn
from robodyn.cli import main
from robodyn.exceptions import InputError
from robodyn.optimize import OptimizationError, point_to_point
from robodyn.sim.limits import limit_violations
from robodyn.trajectory import Trajectory
from tests.conftest import NONDEGENERATE_CASES, ROOT

RP_START, RP_GOAL = np.array([0.0, 0.05]), np.array([1.2, 0.25])


def weak_double_pendulum(shoulder: float = 5.0, elbow: float = 2.0) -> str:
    """The test double pendulum with effort limits too weak to lift it directly (gravity at
    the horizontal needs 9.2 N m at the shoulder) and velocity limits of 12 rad/s."""
    text = (ROOT / "tests" / "data" / "robots" / "double_pendulum.urdf").read_text()
    limited = text.replace('<axis xyz="0 1 0"/>', '<axis xyz="0 1 0"/><limit effort="EFFORT" velocity="12"/>')
    return limited.replace("EFFORT", str(shoulder), 1).replace("EFFORT", str(elbow), 1)


def replay(robot: robodyn.Robot, trajectory: Trajectory, *, shift: int = 0) -> Trajectory:
    """The motion's torques, held over each interval, simulated by robodyn (Pinocchio's ABA, RK4)."""
    t, tau = trajectory.t, trajectory.tau
    dt = float(t[1] - t[0])

    def controller(time_, q, v):
        return tau[min(max(round(time_ / dt) + shift, 0), len(tau) - 1)]

    return robodyn.simulate(
        robot, trajectory.q[0], trajectory.v[0], float(t[-1]), dt, controller=controller, hold=True, limits="ignore"
    )


def check_motion(robot: robodyn.Robot, trajectory: Trajectory, start, goal) -> None:
    """The dynamics hold at every sample (Pinocchio's RNEA), no limit is broken, the motion
    goes from start to goal, at rest at both ends."""
    model, data = robot.model, robot.data
    for q, v, a, tau in zip(trajectory.q, trajectory.v, trajectory.a, trajectory.tau, strict=True):
        assert np.max(np.abs(pin.rnea(model, data, q, v, a) - tau)) <= 1e-9 * max(1.0, np.max(np.abs(tau)))
    assert limit_violations(robot, trajectory) == []
    assert np.max(np.abs(trajectory.q[0] - start)) < 1e-9 and np.max(np.abs(trajectory.q[-1] - goal)) < 1e-9
    assert np.max(np.abs(trajectory.v[[0, -1]])) < 1e-9


def test_the_rp_arms_minimum_effort_motion_obeys_the_dynamics_and_replays_to_the_goal():
    robot = robodyn.load("rp_arm")
    motion = point_to_point(robot, RP_START, RP_GOAL, 2.0, intervals=20)
    trajectory = motion.trajectory
    assert motion.status == "Solve_Succeeded" and len(trajectory) == 21 and motion.duration == 2.0
    check_motion(robot, trajectory, RP_START, RP_GOAL)
    replayed = replay(robot, trajectory)
    assert np.max(np.abs(replayed.q[-1] - RP_GOAL)) < 1e-6 and np.max(np.abs(replayed.v[-1])) < 1e-5
    # Negative control: the same torques one interval late miss the goal.
    assert np.max(np.abs(replay(robot, trajectory, shift=-1).q[-1] - RP_GOAL)) > 1e-3


def test_minimum_time_is_no_longer_than_allowed_and_uses_the_motors():
    robot = robodyn.load(weak_double_pendulum())
    motion = point_to_point(robot, [0.0, 0.0], [0.5, -0.4], 2.0, intervals=20, cost="time")
    check_motion(robot, motion.trajectory, [0.0, 0.0], [0.5, -0.4])
    assert motion.duration < 2.0
    assert max(p / limit for p, limit in zip(motion.peak_torque, (5.0, 2.0), strict=True)) > 0.99  # bang-bang


def test_an_impossible_motion_is_refused_in_one_line_naming_the_limit():
    robot = robodyn.load(weak_double_pendulum())
    with pytest.raises(OptimizationError, match=r"Infeasible_Problem_Detected.*effort limit of 'shoulder'"):
        point_to_point(robot, [0.0, 0.0], [np.pi, 0.0], 0.3, intervals=15)


def test_bad_requests_are_refused_naming_the_parameter():
    robot = robodyn.load("rp_arm")
    for keywords, parameter in (
        ({"intervals": 1}, "intervals"),
        ({"cost": "fast"}, "cost"),
        ({"goal": [1.0, 0.5]}, "goal"),  # beyond the slider's 0.3 m
        ({"start": [0.0]}, "start"),
        ({"duration": -1.0}, "duration"),
    ):
        arguments = {"start": RP_START, "goal": RP_GOAL, "duration": 1.0, **keywords}
        with pytest.raises(InputError) as error:
            point_to_point(robot, arguments.pop("start"), arguments.pop("goal"), arguments.pop("duration"), **arguments)
        assert error.value.argument == parameter
    with pytest.raises(InputError, match="fixed-base"):
        point_to_point(robodyn.load(NONDEGENERATE_CASES["oblique"][0], floating_base=True), np.zeros(8), np.zeros(8), 1.0)


def test_the_cli_writes_a_trajectory_file(tmp_path, capsys):
    path = tmp_path / "motion.csv"
    arguments = ["optimize", "rp_arm", "--start", "0,0.05", "--goal", "1.2,0.25", "--duration", "2", "--intervals", "10"]
    assert main([*arguments, "--out", str(path)]) == 0
    assert "Solve_Succeeded" in capsys.readouterr().out
    trajectory = Trajectory.load(path)
    robot = robodyn.load("rp_arm")
    check_motion(robot, trajectory, RP_START, RP_GOAL)
    assert main(["record", "rp_arm", "--trajectory", str(path), "--out", str(tmp_path / "motion.html")]) == 0
    assert main([*arguments[:-2], "--intervals", "1", "--out", str(path)]) == 2
    assert "--intervals" in capsys.readouterr().err


@pytest.mark.slow
def test_a_weak_double_pendulum_swings_up_within_a_minute():
    robot = robodyn.load(weak_double_pendulum())
    assert np.abs(robot.gravity(np.array([np.pi / 2, 0.0])))[0] > 5.0  # too weak to lift it directly
    began = time.perf_counter()
    motion = point_to_point(robot, [0.0, 0.0], [np.pi, 0.0], 3.0, intervals=60)
    elapsed = time.perf_counter() - began
    check_motion(robot, motion.trajectory, [0.0, 0.0], [np.pi, 0.0])
    assert elapsed < 60.0
    print(
        f"swing-up: {elapsed:.2f} s in all, solve {motion.solve_time:.2f} s, cost {motion.cost:.4f}, peaks {motion.peak_torque}"
    )


def test_simulate_tracks_the_motion_with_computed_torque_to_the_goal(tmp_path, capsys):
    path = tmp_path / "motion.npz"
    arguments = ["optimize", "rp_arm", "--start", "0,0.05", "--goal", "1.2,0.25", "--duration", "2", "--intervals", "20"]
    assert main([*arguments, "--out", str(path)]) == 0
    capsys.readouterr()
    command = ["simulate", "rp_arm", "--controller", "computed-torque", "--reference", str(path), "--duration", "2.5"]
    assert main([*command, "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["final_joint_error"] < 1e-6 and summary["limit_violations"] == []
    # Negative control: the quintic to the same goal in half the time breaks the arm's velocity limit.
    assert (
        main(["simulate", "rp_arm", "--controller", "computed-torque", "--target", "1.2,0.25", "--duration", "1", "--json"]) == 0
    )
    assert json.loads(capsys.readouterr().out)["limit_violations"] != []
    assert main([*command[:3], "pd", *command[4:]]) == 2  # a reference is for computed torque only


DAMPED_PENDULUM = ROOT / "tests" / "data" / "robots" / "damped_pendulum.urdf"


@pytest.fixture(scope="module")
def damped_pendulum():
    robot = robodyn.load(DAMPED_PENDULUM)
    assert robot.joint_damping[0] == 0.1 and np.abs(robot.gravity(np.array([np.pi / 2]))[0]) > 5.0  # 1 N m cannot lift it
    return robot


@pytest.fixture(scope="module")
def damped_swing_up(damped_pendulum):
    """The damped pendulum's minimum-effort swing-up over 12 s (the straight-line start fails)."""
    return point_to_point(damped_pendulum, [0.0], [np.pi], 12.0, intervals=100)


def test_a_damped_swing_up_replayed_open_loop_by_simulate_ends_at_the_goal(damped_pendulum, damped_swing_up):
    trajectory = damped_swing_up.trajectory
    assert damped_swing_up.starts > 1 and max(damped_swing_up.peak_torque) <= 1.0  # found by the retry, within 1 N m
    replayed = replay(damped_pendulum, trajectory)  # simulate applies the file's damping by default
    assert abs(replayed.q[-1][0] - np.pi) <= 1e-6 and abs(replayed.v[-1][0]) <= 1e-5
    # the trajectory's accelerations are those of the damped plant: RNEA(q, v, a) = tau − b v
    model, data = damped_pendulum.model, damped_pendulum.data
    for q, v, a, tau in zip(trajectory.q, trajectory.v, trajectory.a, trajectory.tau, strict=True):
        assert abs(pin.rnea(model, data, q, v, a)[0] - (tau[0] - 0.1 * v[0])) <= 1e-9
    # Negative control: the rigid plan, replayed on the damped plant, misses the goal.
    rigid = point_to_point(damped_pendulum, [0.0], [np.pi], 12.0, intervals=100, joint_friction=False)
    assert abs(replay(damped_pendulum, rigid.trajectory).q[-1][0] - np.pi) > 0.1


def test_feasible_durations_are_found_by_the_retry_and_a_short_one_is_refused_as_local(damped_pendulum, damped_swing_up):
    fastest = point_to_point(damped_pendulum, [0.0], [np.pi], 12.0, intervals=100, cost="time")
    assert fastest.duration < 12.0 and fastest.status == "Solve_Succeeded"
    assert abs(replay(damped_pendulum, fastest.trajectory).q[-1][0] - np.pi) <= 1e-6
    slack = point_to_point(damped_pendulum, [0.0], [np.pi], 10.0, intervals=100)  # longer than the fastest: found
    assert slack.duration == 10.0 and slack.cost > damped_swing_up.cost  # less time, more effort
    with pytest.raises(OptimizationError, match=r"Infeasible_Problem_Detected \(from a straight line.*local verdict") as error:
        point_to_point(damped_pendulum, [0.0], [np.pi], 3.0, intervals=60)  # binds: shorter than any swing-up found
    assert error.value.status == "Infeasible_Problem_Detected"


def _hanging_still(robot: robodyn.Robot, shoulder: float) -> np.ndarray:
    """A configuration with the shoulder at ``shoulder`` where the shoulder needs no torque to rest."""
    from scipy.optimize import brentq

    elbow = brentq(lambda x: robot.gravity(np.array([shoulder, x]))[0], -np.pi / 2, 0.0)
    return np.array([shoulder, elbow])


def test_only_the_actuated_joints_get_torque(capsys, tmp_path):
    robot = robodyn.load(weak_double_pendulum(shoulder=5.0, elbow=5.0))
    goal = _hanging_still(robot, 0.1)
    motion = point_to_point(robot, [0.0, 0.0], goal, 3.0, intervals=40, actuated=["elbow"])
    assert np.all(motion.trajectory.tau[:, 0] == 0.0) and np.abs(motion.trajectory.tau[:, 1]).max() > 0.1
    replayed = replay(robot, motion.trajectory)
    assert np.abs(replayed.q[-1] - goal).max() <= 1e-6
    with pytest.raises(InputError, match=r"^actuated must be"):
        point_to_point(robot, [0.0, 0.0], goal, 3.0, actuated=["wrist"])
    # Negative control: with both joints driven (the default), the shoulder helps.
    assert np.abs(point_to_point(robot, [0.0, 0.0], goal, 3.0, intervals=40).trajectory.tau[:, 0]).max() > 0.01
    # The default set is the joints whose Dof.actuated (a file's actuators say which)
    robot.dofs = tuple(replace(dof, actuated=dof.name == "elbow") for dof in robot.dofs)
    by_default = point_to_point(robot, [0.0, 0.0], goal, 3.0, intervals=40)
    np.testing.assert_array_equal(by_default.trajectory.tau, motion.trajectory.tau)
    out = str(tmp_path / "m.csv")
    argv = ["optimize", weak_double_pendulum(shoulder=5.0, elbow=5.0), "--start", "0,0", "--goal", ",".join(map(str, goal))]
    assert main([*argv, "--duration", "3", "--intervals", "40", "--actuated", "elbow", "--out", out]) == 0
    assert np.all(Trajectory.load(out).tau[:, 0] == 0.0)


def test_coulomb_friction_is_refused_unless_planned_rigid(capsys, tmp_path):
    arm = ROOT / "tests" / "data" / "robots" / "student_arm.urdf"
    robot = robodyn.load(arm)
    with pytest.raises(InputError, match=r"^joint_friction must be False to plan joints with Coulomb friction"):
        point_to_point(robot, np.zeros(5), np.full(5, 0.1), 2.0, intervals=10)
    argv = ["optimize", str(arm), "--start", "0,0,0,0,0", "--goal", "0.1,0.1,0.1,0.1,0.1", "--duration", "2"]
    assert main([*argv, "--intervals", "10", "--out", str(tmp_path / "m.csv")]) == 2
    assert capsys.readouterr().err.startswith("robodyn: error: --no-joint-friction is needed to plan joints")
    assert main([*argv, "--intervals", "10", "--no-joint-friction", "--out", str(tmp_path / "m.csv")]) == 0
