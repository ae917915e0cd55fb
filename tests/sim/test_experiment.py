"""run_simulation with the sequel's controllers, pushes and an online momentum observer.

Every check has a negative control: the impedance's deflection is ``K⁻¹ F`` only once the
push has settled; the observer's recorded residual equals the offline estimate only when
both integrate the torque the same way.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import robodyn
from robodyn.exceptions import InputError
from robodyn.sim.experiment import controller_model, run_simulation
from robodyn.sim.observer import MomentumObserver, estimate_external_torques
from robodyn.sim.report import Push
from robodyn.sim.requests import parse_push
from tests.conftest import ROOT

RP_TARGET = [0.9, 0.0, 0.5]
RP_START = [0.5, 0.13]
RP_STIFFNESS = [300.0, 300.0, 200.0]
PANDA_READY = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785, 0.0]


@pytest.fixture(scope="module")
def rp_arm():
    return robodyn.load("rp_arm")


@pytest.fixture(scope="module")
def pushed(rp_arm):
    """The RP arm under impedance, pushed by (5, 0, -4) N from 0.2 s, observed at K_O = 50 /s."""
    return run_simulation(
        rp_arm, controller="impedance", target=RP_TARGET, q0=RP_START, stiffness=RP_STIFFNESS, force_at=["0.2:5,0,-4"],
        observer_gain=50.0, duration=2.0, limits="ignore",
    )  # fmt: skip


def test_a_push_on_the_impedance_deflects_the_frame_by_k_inverse_f_within_one_percent(rp_arm, pushed):
    trajectory, summary = pushed
    task = summary.task
    expected = np.array([5.0, 0.0, -4.0]) / np.array(RP_STIFFNESS)
    measured = rp_arm.frame_position(trajectory.q[-1], "end_effector") - np.array(RP_TARGET)  # independent of the summary
    assert np.allclose(task.expected_deflection, expected, rtol=0, atol=1e-15)
    assert np.allclose(task.deflection, measured, rtol=0, atol=1e-12)
    assert np.linalg.norm(measured - expected) < 0.01 * np.linalg.norm(expected)
    assert task.deflection_error < 0.01
    assert "deflection off by" in summary.text() and summary.to_dict()["deflection_error"] == task.deflection_error


def test_the_deflection_is_not_k_inverse_f_before_the_push_has_settled(rp_arm):
    # negative control: the same push 50 ms before the end has not yet moved the arm by K⁻¹F
    _, summary = run_simulation(
        rp_arm, controller="impedance", target=RP_TARGET, q0=RP_START, stiffness=RP_STIFFNESS, force_at=["0.45:5,0,-4"],
        duration=0.5, limits="ignore",
    )  # fmt: skip
    assert summary.task.deflection_error > 0.05


def test_the_observer_recorded_in_the_run_equals_the_offline_estimate_of_its_trajectory(rp_arm, pushed):
    trajectory, summary = pushed
    offline = estimate_external_torques(rp_arm, trajectory, gain=50.0, torque="sampled")
    assert summary.observer.residual.shape == (len(trajectory), rp_arm.nv)
    assert np.abs(summary.observer.residual - offline).max() <= 1e-9
    held = estimate_external_torques(rp_arm, trajectory, gain=50.0, torque="held")
    assert np.abs(summary.observer.residual - held).max() > 1e-6  # negative control: another torque rule


def test_the_observer_follows_the_applied_external_torques_after_settling(rp_arm, pushed):
    trajectory, summary = pushed
    applied = summary.observer.applied
    q_end = trajectory.q[-1]
    jacobian = rp_arm.frame_jacobian(q_end, "end_effector")[:3]
    assert np.allclose(applied[-1], jacobian.T @ np.array([5.0, 0.0, -4.0]), atol=1e-12)
    assert not applied[: int(0.2 / 1e-3)].any()  # nothing before the push
    settled = trajectory.t > 0.2 + 10 / 50.0
    scale = np.abs(applied[-1]).max()
    assert np.abs(summary.observer.residual[settled] - applied[settled]).max() < 0.01 * scale
    assert np.abs(summary.observer.residual[trajectory.t < 0.2]).max() < 0.01 * scale  # before: nothing estimated


def test_simulate_feeds_the_observer_once_a_step_at_the_reached_state(rp_arm):
    from robodyn.sim.experiment import controller_model
    from robodyn.sim.simulation import ExternalWrench, simulate

    observer = MomentumObserver(controller_model(rp_arm), 40.0, torque="held")
    hold = np.array(RP_START)
    law = lambda t, q, v: rp_arm.gravity(q) + 400.0 * (hold - q) - 40.0 * v  # noqa: E731
    push = ExternalWrench("end_effector", [0.0, 0.0, -6.0])
    trajectory = simulate(
        rp_arm, np.array(RP_START), np.zeros(2), 1.0, 1e-3, controller=law, hold=True, external=[push], observer=observer
    )
    assert observer.times == pytest.approx(trajectory.t.tolist(), abs=1e-12)
    residual = np.array(observer.residuals)
    assert np.abs(residual - estimate_external_torques(rp_arm, trajectory, gain=40.0, torque="held")).max() <= 1e-9
    expected = rp_arm.wrench_torques(trajectory.q[-1], "end_effector", np.array([0.0, 0.0, -6.0]))
    assert np.abs(residual[-1] - expected).max() < 0.01 * np.abs(expected).max()


@pytest.mark.slow
def test_operational_space_control_reaches_a_full_pose_on_the_panda_with_a_posture():
    robot = robodyn.load("panda")
    target = [0.35, 0.05, 0.55, np.pi, 0.0, 0.0]
    trajectory, summary = run_simulation(
        robot, controller="osc", target=target, posture=PANDA_READY, duration=3.0, joint_friction=False
    )
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, trajectory.q[-1])
    placement = data.oMf[robot.model.getFrameId(robot.end_effector)]
    wanted = pin.rpy.rpyToMatrix(*target[3:])
    assert np.linalg.norm(placement.translation - target[:3]) < 1e-6
    assert np.linalg.norm(pin.log3(placement.rotation.T @ wanted)) < 1e-6
    assert summary.task.final_error < 1e-6 and summary.task.orientation_error < 1e-6 and summary.task.reached


def test_a_push_is_read_from_time_force_and_frame():
    assert parse_push("0.5:8,-6,10") == Push(0.5, (8.0, -6.0, 10.0), None)
    assert parse_push("1:0 0 -3@link2") == Push(1.0, (0.0, 0.0, -3.0), "link2")
    for bad in ("8,-6,10", "0.5:8,-6", "-1:1,2,3", "x:1,2,3"):
        with pytest.raises(InputError) as raised:
            parse_push(bad)
        assert raised.value.argument == "force_at"


def test_pose_options_are_refused_where_they_do_not_apply(rp_arm):
    cases = [
        ({"controller": "task-space", "target": [0.6, 0.3], "posture": [0.0, 0.1]}, "posture"),
        ({"controller": "osc", "target": RP_TARGET, "stiffness": [1.0, 2.0, 3.0]}, "stiffness"),
        ({"controller": "osc", "target": [0.9, 0.0]}, "target"),
        ({"controller": "osc", "target": RP_TARGET, "posture": [0.0]}, "posture"),
        ({"controller": "impedance", "target": RP_TARGET, "stiffness": [1.0, 2.0]}, "stiffness"),
        ({"controller": "osc", "target": [5.0, 0.0, 0.5]}, "target"),
        ({"controller": "osc", "target": RP_TARGET, "observer_gain": -1.0}, "observer_gain"),
    ]
    for options, parameter in cases:
        with pytest.raises(InputError) as raised:
            run_simulation(rp_arm, duration=0.01, **options)
        assert raised.value.argument == parameter, options


def test_the_compiled_engine_refuses_pushes_and_observers_by_name(rp_arm):
    with pytest.raises(InputError, match="external wrenches") as raised:
        run_simulation(rp_arm, force_at=["0:1,0,0"], duration=0.01, engine="compiled")
    assert raised.value.argument == "external"
    with pytest.raises(InputError, match="momentum observer") as raised:
        run_simulation(rp_arm, observer_gain=10.0, duration=0.01, engine="compiled")
    assert raised.value.argument == "observer"


def test_a_robot_without_a_default_end_effector_still_simulates_and_its_pushes_need_a_frame():
    robot = robodyn.load("solo12", floating_base=True)
    _, summary = run_simulation(robot, duration=0.004, dt=2e-3, limits="ignore")
    assert summary.pushes == ()
    _, summary = run_simulation(robot, duration=0.004, dt=2e-3, limits="ignore", force_at=["0:0,0,-5@FL_FOOT"])
    assert summary.pushes == (Push(0.0, (0.0, 0.0, -5.0), "FL_FOOT"),)
    with pytest.raises(robodyn.RobodynError, match="FL_FOOT"):  # negative control: no frame, no default to push at
        run_simulation(robot, duration=0.004, dt=2e-3, limits="ignore", force_at=["0:0,0,-5"])


XY_ARM = """<robot name="xy_arm">
  <link name="base"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="10" velocity="3"/></joint>
  <link name="l1"><inertial><origin xyz="0.2 0 0"/><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0.4 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="10" velocity="3"/></joint>
  <link name="l2"><inertial><origin xyz="0.2 0 0"/><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="tip" type="fixed"><parent link="l2"/><child link="tip"/><origin xyz="0.4 0 0"/></joint>
  <link name="tip"/>
</robot>"""


def test_a_two_value_target_is_refused_for_an_arm_that_moves_along_y():
    """An arm in the XY plane (like dm_control's reacher): X,Z would set Y = 0, a point it was
    never asked to reach; the XZ-plane RP arm takes X,Z (the negative control)."""
    robot = robodyn.load(XY_ARM)
    with pytest.raises(InputError, match="3 values X,Y,Z") as raised:
        run_simulation(robot, controller="task-space", target=[0.1, 0.12], frame="tip", duration=0.01)
    assert raised.value.argument == "target"
    _, summary = run_simulation(robot, controller="task-space", target=[0.5, 0.3, 0.0], frame="tip", duration=0.01)
    assert summary.task is not None
    rp_arm = robodyn.load("rp_arm")
    _, summary = run_simulation(rp_arm, controller="task-space", target=[0.7, 0.7], duration=0.01)
    assert summary.task is not None and summary.task.target[1] == 0.0


def test_a_floating_mjcf_robot_above_its_files_plane_starts_where_the_file_puts_it(tmp_path):
    """As MuJoCo does (its qpos0), not moved to 5 cm above it; the same box at the origin, half
    in the floor (the negative control), is lifted to 5 cm above it, said in the summary."""
    box = '<body name="box" pos="0.1 0.2 0.4" euler="0 0 30"><freejoint/><geom type="box" size="0.1 0.1 0.1" mass="2"/></body>'
    path = tmp_path / "box.xml"
    path.write_text(f'<mujoco><worldbody><geom type="plane" size="5 5 0.1"/>{box}</worldbody></mujoco>')
    robot = robodyn.load(path)
    trajectory, summary = run_simulation(robot, ground="file", duration=0.002)
    np.testing.assert_array_equal(trajectory.q[0], robot.default_configuration())
    assert trajectory.q[0][2] == 0.4 and not any(line.startswith("start:") for line in summary.ground)
    path.write_text(
        f'<mujoco><worldbody><geom type="plane" size="5 5 0.1"/>{box.replace("0.1 0.2 0.4", "0 0 0")}</worldbody></mujoco>'
    )
    trajectory, summary = run_simulation(robodyn.load(path), ground="file", duration=0.002)
    assert trajectory.q[0][2] == pytest.approx(0.15) and summary.ground[0].startswith("start: the base moved 0.15 m")


def test_the_observer_of_a_controller_sampled_every_control_period_integrates_its_held_torque():
    """With ``control_period`` the torque is held through each step: the observer must take
    it as held. In free motion its residual is then the integration error alone; as "sampled" (the
    negative control, the same run observed by hand) it carries about Δτ/2 per step."""
    robot = robodyn.load(ROOT / "tests" / "data" / "robots" / "oblique.urdf", gravity=(1.0, -2.0, -9.0))
    options = {"controller": "pd", "target": [0.6] * robot.nv, "duration": 0.2, "control_period": 0.003}
    trajectory, summary = run_simulation(robot, observer_gain=200.0, limits="ignore", engine="pinocchio", **options)
    held = np.abs(summary.observer.residual).max()
    sampled = MomentumObserver(controller_model(robot), 200.0, torque="sampled")
    for t, q, v, tau in zip(trajectory.t, trajectory.q, trajectory.v, trajectory.tau, strict=True):
        sampled.update(t, q, v, tau)
    wrong = np.abs(np.array(sampled.residuals)).max()
    assert held < 0.25 * wrong, (held, wrong)  # 0.28 vs 2.1 N m here; equal before the fix
