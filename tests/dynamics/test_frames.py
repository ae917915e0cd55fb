"""Issue 13, item 1: the task frame is never one that nothing moves.

Reproductions: ur5's default end effector was ``world`` (payloads and forces changed no
torque, task-space control left the arm still); solo12's was one foot of four.
"""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn import exceptions
from robodyn.cli.app import main
from robodyn.exceptions import FrameError
from robodyn.sim.control import TaskSpace
from robodyn.sim.experiment import controller_model, run_simulation
from robodyn.sim.simulation import ExternalWrench, simulate
from robodyn.sim.whatif import sweep

#: A hand-written arm: a non-unit axis, an offset tool frame behind a fixed joint.
HAND_WRITTEN = """<?xml version="1.0"?>
<robot name="tilted">
  <link name="world"/>
  <joint name="mount" type="fixed"><parent link="world"/><child link="base"/><origin xyz="0.1 0 0.2"/></joint>
  <link name="base"><inertial><mass value="2"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <joint name="yaw" type="revolute"><parent link="base"/><child link="arm"/>
    <axis xyz="0.2 0 2"/><limit lower="-3" upper="3" effort="50" velocity="3"/></joint>
  <link name="arm"><inertial><origin xyz="0.2 0 0"/><mass value="1.5"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.02"/></inertial></link>
  <joint name="pitch" type="revolute"><parent link="arm"/><child link="forearm"/><origin xyz="0.4 0 0"/>
    <axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="30" velocity="3"/></joint>
  <link name="forearm"><inertial><origin xyz="0.15 0 0"/><mass value="0.8"/>
    <inertia ixx="0.005" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="tool_joint" type="fixed"><parent link="forearm"/><child link="tool"/><origin xyz="0.3 0 0.05"/></joint>
  <link name="tool"/>
</robot>
"""


def moved_by_every_joint(robot: robodyn.Robot, frame: str) -> bool:
    """Whether moving any one joint of the frame's chain changes its pose; the joints
    outside the chain may only be a gripper's fingers."""
    import pinocchio as pin

    rng = np.random.default_rng(3)
    q = robot.random_configuration(rng)
    frame_id = robot.frame_id(frame)
    chain = [j for j in robot.model.supports[robot.model.frames[frame_id].parentJoint] if j != 0 and robot.model.joints[j].nv]
    outside = set(robot.joint_names) - {robot.model.names[j] for j in chain}
    assert all("finger" in name for name in outside), outside

    def pose(q):
        data = robot.model.createData()
        pin.framesForwardKinematics(robot.model, data, q)
        return data.oMf[frame_id].homogeneous.copy()

    before = pose(q)
    for index in (robot.model.joints[j].idx_q for j in chain):
        moved = q.copy()
        moved[index] += 0.05
        if np.abs(pose(moved) - before).max() < 1e-9:
            return False
    return True


@pytest.mark.parametrize("name", ["ur5", "ur10", "panda", "z1", "rp_arm", HAND_WRITTEN])
def test_default_end_effector_moves_with_every_joint_of_its_chain(name):
    robot = robodyn.load(name)
    frame = robot.end_effector
    assert frame not in ("world", "universe", robot.spec.root)
    assert moved_by_every_joint(robot, frame)


def test_fixed_frames_after_the_tip_are_followed_when_unique():
    robot = robodyn.load(HAND_WRITTEN)
    assert robot.end_effector == "tool"  # forearm → tool is the only way on
    assert robodyn.load("panda").end_effector == "panda_hand_tcp"  # a gripper is not a second chain


@pytest.mark.parametrize(("name", "tips"), [("solo12", 4), ("baxter", 5), ("tiago", 11)])
def test_several_chains_have_no_silent_default(name, tips):
    robot = robodyn.load(name)
    with pytest.raises(exceptions.AmbiguousEndEffectorError) as caught:
        _ = robot.end_effector
    assert len(caught.value.candidates) == tips
    assert "\n" not in str(caught.value) and all(tip in str(caught.value) for tip in caught.value.candidates)
    for tip in caught.value.candidates:  # each candidate is a real, moving frame
        assert robot.task_frame(tip, "a test") == tip


def test_static_frames_are_refused_everywhere():
    robot = robodyn.load("ur5")
    with pytest.raises(exceptions.StaticFrameError, match="no joint moves it"):
        robot.task_frame("world", "a payload")
    with pytest.raises(exceptions.StaticFrameError):
        TaskSpace(controller_model(robot), "base_link", np.array([0.3, 0.2, 0.4]))
    with pytest.raises(exceptions.StaticFrameError):
        simulate(robot, np.zeros(6), np.zeros(6), 0.01, 1e-3, external=[ExternalWrench("world", [0, 0, -10])])
    with pytest.raises(exceptions.StaticFrameError):
        sweep("ur5", payloads=(0.0, 1.0), frame="world")
    with pytest.raises(FrameError):
        robot.task_frame("no_such_frame", "a payload")
    assert isinstance(exceptions.StaticFrameError("r", "f", "x"), FrameError)


def test_payload_adds_its_weight_through_the_frame_jacobian_by_finite_differences():
    """A static 'motion' (q_start = q_end): the payload adds m g ∂z/∂q at the frame."""
    robot = robodyn.load("ur5")
    q = np.array([0.3, -1.0, 1.2, -0.5, 0.8, 0.1])
    rows = sweep("ur5", payloads=(0.0, 2.0), q_start=q, q_end=q)
    frame = robot.end_effector
    step = 1e-6
    height = [
        (robot.frame_position(q + step * e, frame)[2] - robot.frame_position(q - step * e, frame)[2]) / (2 * step)
        for e in np.eye(6)
    ]
    expected = 2.0 * 9.81 * np.abs(np.array(height))
    # Same sign as the arm's own gravity torque here, so peaks add up.
    np.testing.assert_allclose(np.abs(rows[1].peak - rows[0].peak), expected, rtol=1e-6, atol=1e-6)
    assert np.abs(rows[1].peak - rows[0].peak).max() > 1.0


def test_whatif_command_shows_the_payload_and_force(capsys):
    assert main(["whatif", "ur5", "--payloads", "0,2", "--force", "0,0,-20", "--json"]) == 0
    import json

    rows = json.loads(capsys.readouterr().out)["rows"]
    peaks = [np.array(row["peak_torque"]) for row in rows]
    assert np.abs(peaks[2] - peaks[0]).max() > 1.0  # 2 kg
    assert np.abs(peaks[1] - peaks[0]).max() > 1.0  # 20 N


@pytest.mark.parametrize(("name", "target"), [("ur5", [0.3, 0.2, 0.4]), ("panda", [0.4, 0.2, 0.5]), ("z1", [0.3, 0.1, 0.3])])
# "warn" (the default) in the slow tier: "enforce" runs the same law on the same robots,
# differing only where a limit binds, and the fast tier's other task-space runs use "warn".
@pytest.mark.parametrize("limits", [pytest.param("warn", marks=pytest.mark.slow), "enforce"])
def test_task_space_control_reaches_reachable_targets(name, target, limits):
    robot = robodyn.load(name)
    trajectory, summary = run_simulation(
        robot, controller="task-space", target=target, duration=3.0, limits=limits, joint_friction=False
    )  # the rigid-body law: z1's joint friction (2 N m) would hold it short of 1e-3
    assert summary["frame"] == robot.end_effector
    assert summary["final_error_m"] < 1e-3 and summary["target_reached"]
    np.testing.assert_allclose(robot.frame_position(trajectory.q[-1], summary["frame"]), target, atol=1e-3)


def test_unreachable_target_is_refused_with_the_reach():
    robot = robodyn.load("ur5")
    with pytest.raises(robodyn.InputError, match="reach"):
        run_simulation(robot, controller="task-space", target=[3.0, 0.0, 0.5], duration=0.1)


def test_info_shows_the_default_frame(capsys):
    assert main(["info", "ur5"]) == 0
    assert f"end effector (default task frame): {robodyn.load('ur5').end_effector}" in capsys.readouterr().out
    assert main(["info", "solo12"]) == 0
    assert "FL_FOOT" in capsys.readouterr().out


def test_attach_payload_refuses_a_link_nothing_moves():
    from robodyn.dynamics.payload import attach_payload

    with pytest.raises(exceptions.StaticFrameError):
        attach_payload(robodyn.load("ur5"), "base_link", 1.0)


def _zoo_robots():
    import warnings

    from robodyn.exceptions import RobodynError

    robots = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for name in robodyn.robot_names():
            try:
                robots.append(robodyn.load(name))
            except RobodynError:
                continue  # item 9 (loading) is another engineer's
    return robots


@pytest.mark.slow
def test_every_zoo_robot_has_a_moving_default_or_names_its_tips():
    for robot in _zoo_robots():
        try:
            frame = robot.end_effector
        except exceptions.AmbiguousEndEffectorError as error:
            assert len(error.candidates) >= 2, robot.name
            for tip in error.candidates:
                assert robot.task_frame(tip, "a test") == tip
            continue
        assert moved_by_every_joint(robot, frame), (robot.name, frame)


@pytest.mark.slow
def test_task_space_control_reaches_a_reachable_target_on_every_zoo_arm():
    """The target: the end effector's position at a configuration 0.1 rad (or m) inside the
    limits (a task-space law does not know the stops; a goal on one is reached only slowly)."""
    for robot in _zoo_robots():
        if robot.floating_base:
            continue
        try:
            frame = robot.end_effector
        except exceptions.AmbiguousEndEffectorError:
            continue
        rng = np.random.default_rng(0)
        lower, upper = robot.physical_limits()
        q = np.clip(robot.default_configuration() + rng.uniform(-0.3, 0.3, robot.nq), lower + 0.1, upper - 0.1)
        target = robot.frame_position(q, frame)
        import warnings

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            _, summary = run_simulation(
                robot, controller="task-space", target=target.tolist(), limits="enforce", joint_friction=False
            )
        assert summary["target_reached"], (robot.name, summary["final_error_m"])
