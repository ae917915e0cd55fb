"""The sequel on the command line: ``simulate --controller osc|impedance --force-at
--observer-gain`` and ``robodyn observe``.

The pose is measured with Pinocchio's forward kinematics from the written file, the
columns are compared with the Python values by name, and each check has a negative control.
"""

from __future__ import annotations

import csv
import json

import numpy as np
import pinocchio as pin
import pytest

import robodyn
from robodyn.cli import main
from robodyn.sim.observer import detect_collision, estimate_external_torques, external_wrench
from robodyn.trajectory import Trajectory
from robodyn.trajectory.io import read_extra

PANDA_READY = "0,-0.785,0,-2.356,0,1.571,0.785,0"
POSE = [0.35, 0.05, 0.55, np.pi, 0.0, 0.0]
RP_IMPEDANCE = ["rp_arm", "--controller", "impedance", "--target", "0.9,0,0.5", "--q0", "0.5,0.13", "--stiffness", "300,300,200"]


def _columns(path) -> dict[str, np.ndarray]:
    with open(path, encoding="utf-8") as stream:
        lines = [line for line in stream if not line.startswith("#")]
    header = next(csv.reader([lines[0]]))
    table = np.loadtxt(lines[1:], delimiter=",", ndmin=2)
    return {name: table[:, index] for index, name in enumerate(header)}


@pytest.mark.slow
def test_simulate_osc_reaches_a_full_pose_on_the_panda_by_pinocchios_forward_kinematics(tmp_path, capsys):
    out = tmp_path / "osc.csv"
    target = ",".join(repr(value) for value in POSE)
    argv = ["simulate", "panda", "--controller", "osc", "--target", target, "--posture", PANDA_READY, "--out", str(out), "--json"]
    argv.append("--no-joint-friction")  # the rigid-body law: the panda's joint damping would leave 4e-5 m after 3 s
    assert main(argv) == 0
    summary = json.loads(capsys.readouterr().out)
    robot = robodyn.load("panda")
    trajectory = Trajectory.load(out)
    data = robot.model.createData()
    frame = robot.model.getFrameId(summary["frame"])
    wanted = pin.rpy.rpyToMatrix(*POSE[3:])

    def pose_error(q):
        pin.framesForwardKinematics(robot.model, data, q)
        placement = data.oMf[frame]
        return np.linalg.norm(placement.translation - POSE[:3]), np.linalg.norm(pin.log3(placement.rotation.T @ wanted))

    position, angle = pose_error(trajectory.q[-1])
    assert position < 1e-6 and angle < 1e-6
    assert summary["final_error_m"] == pytest.approx(position, abs=1e-12)
    assert summary["final_orientation_error_rad"] == pytest.approx(angle, abs=1e-9)
    start_position, start_angle = pose_error(trajectory.q[0])  # negative control: the start is far from the pose
    assert start_position > 0.05 and start_angle > 0.1


def test_simulate_impedance_with_a_push_and_an_observer_writes_tau_ext_columns_equal_to_the_python_values(tmp_path, capsys):
    out = tmp_path / "push.csv"
    argv = [*RP_IMPEDANCE, "--force-at", "0.2:5,0,-4", "--observer-gain", "50", "--duration", "1.5", "--limits", "ignore"]
    assert main(["simulate", *argv, "--out", str(out), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["deflection_error"] < 0.01
    assert summary["pushes"] == [{"time_s": 0.2, "force_N": [5.0, 0.0, -4.0], "frame": "end_effector"}]
    robot = robodyn.load("rp_arm")
    trajectory = Trajectory.load(out)  # the extra columns are skipped by the trajectory reader
    columns = _columns(out)
    offline = estimate_external_torques(robot, trajectory, gain=50.0, torque="sampled")
    for index, dof in enumerate(robot.dofs):
        assert np.abs(columns[f"tau_ext[{dof.name}]"] - offline[:, index]).max() <= 1e-9
        applied = [robot.wrench_torques(q, "end_effector", np.array([5.0, 0.0, -4.0]))[index] for q in trajectory.q]
        assert np.allclose(columns[f"tau_env[{dof.name}]"], np.where(trajectory.t >= 0.2, applied, 0.0), atol=1e-12)
    assert np.array_equal(read_extra(out, "tau_ext"), np.column_stack([columns[f"tau_ext[{d.name}]"] for d in robot.dofs]))
    held = estimate_external_torques(robot, trajectory, gain=50.0, torque="held")  # negative control
    assert np.abs(columns["tau_ext[joint1]"] - held[:, 0]).max() > 1e-6


def test_observe_writes_the_estimate_the_wrench_and_finds_the_push(tmp_path, capsys):
    run = tmp_path / "push.npz"
    argv = [*RP_IMPEDANCE, "--force-at", "0.3:5,0,-4", "--duration", "1.0", "--limits", "ignore", "--out", str(run)]
    assert main(["simulate", *argv]) == 0
    capsys.readouterr()
    out, plot = tmp_path / "est.csv", tmp_path / "est.png"
    argv = ["observe", "rp_arm", str(run), "--gain", "40", "--frame", "end_effector", "--threshold", "0.5", "--torque", "sampled"]
    assert main([*argv, "--out", str(out), "--plot", str(plot), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    robot = robodyn.load("rp_arm")
    trajectory = Trajectory.load(run)
    residual = estimate_external_torques(robot, trajectory, gain=40.0, torque="sampled")
    wrench = external_wrench(robot, trajectory.q, residual, "end_effector")
    columns = _columns(out)
    assert next(iter(columns)) == "t" and np.array_equal(columns["t"], trajectory.t)
    for index, dof in enumerate(robot.dofs):
        assert np.array_equal(columns[f"tau_ext[{dof.name}]"], residual[:, index])
    for index, axis in enumerate("xyz"):
        assert np.array_equal(columns[f"force[{axis}]"], wrench[:, index])
        assert np.array_equal(columns[f"torque[{axis}]"], wrench[:, 3 + index])
    # two joints cannot tell a force from a torque at the tip: the least-norm wrench explains the residual
    jacobian = robot.frame_jacobian(trajectory.q[-1], "end_effector")
    assert np.allclose(jacobian.T @ wrench[-1], residual[-1], atol=1e-9)
    collision = detect_collision(robot, trajectory.t, residual, 0.5)
    assert report["collision"]["time_s"] == collision.time and 0.3 <= collision.time < 0.3 + 1 / 40.0
    assert report["collision"]["dof"] == "joint2"
    assert report["final_tau_ext_error"] < 0.01 * np.abs(read_extra(run, "tau_env")[-1]).max()
    assert plot.stat().st_size > 10_000 and report["plot"] == str(plot)
    # negative control: before the push nothing crosses the threshold
    assert detect_collision(robot, trajectory.t[trajectory.t < 0.3], residual[trajectory.t < 0.3], 0.5) is None


def test_command_line_errors_name_the_flags_in_one_line(tmp_path, capsys):
    cases = [
        (["simulate", "rp_arm", "--force-at", "0:1,0,0", "--compiled", "--duration", "0.01"], "--force-at"),
        (["simulate", *RP_IMPEDANCE, "--force-at", "1,0,0", "--duration", "0.01"], "--force-at"),
        (
            ["simulate", "rp_arm", "--controller", "osc", "--target", "0.9,0,0.5", "--stiffness", "1", "--duration", "0.01"],
            "--stiffness",
        ),
        (
            ["simulate", "rp_arm", "--controller", "osc", "--target", "0.9,0,0.5", "--posture", "1", "--duration", "0.01"],
            "--posture",
        ),
        (["observe", "rp_arm", str(tmp_path / "none.csv"), "--gain", "-1"], None),
    ]
    for argv, flag in cases:
        assert main(argv) == 2, argv
        error = capsys.readouterr().err.strip()
        assert len(error.splitlines()) == 1, error
        if flag:
            assert flag in error, error
