"""`robodyn simulate` writes all of its files or none, and takes --compiled."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

import robodyn
from robodyn.cli.app import main


def test_a_failed_output_leaves_every_earlier_file_untouched(tmp_path, capsys):
    old = tmp_path / "m.csv"
    old.write_text("the user's old trajectory\n")
    status = main(
        ["simulate", "rp_arm", "--duration", "0.1", "--out", str(old), "--record", str(tmp_path / "missing" / "m.html")]
    )
    assert status == 2
    error = capsys.readouterr().err.strip()
    assert error.count("\n") == 0 and "does not exist" in error
    assert old.read_text() == "the user's old trajectory\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.csv"]  # no temporary left behind


def test_outputs_are_written_together_when_all_succeed(tmp_path, capsys):
    status = main(
        ["simulate", "rp_arm", "--duration", "0.1", "--out", str(tmp_path / "m.npz"), "--plot", str(tmp_path / "m.png"), "--json"]
    )
    assert status == 0
    summary = json.loads(capsys.readouterr().out)
    assert (tmp_path / "m.npz").is_file() and (tmp_path / "m.png").is_file()
    # --engine auto (default): the engine choose_engine names (compiled once rp_arm is in the cache)
    from robodyn.cli.flags import command_line_text
    from robodyn.sim.simulation import choose_engine

    engine, reason = choose_engine(robodyn.load("rp_arm"), None)
    assert (summary["engine"], summary["engine_reason"]) == (engine, command_line_text(reason))


def test_the_summary_names_flags_not_library_parameters(capsys):
    from robodyn.cli.flags import command_line_text

    reason = "not compiled yet (engine='compiled' builds it once, in seconds to minutes; auto uses it from then on)"
    assert command_line_text(reason) == (
        "not compiled yet (--engine compiled builds it once, in seconds to minutes; auto uses it from then on)"
    )
    assert main(["simulate", "rp_arm", "--duration", "0.01", "--engine", "pinocchio"]) == 0
    out = capsys.readouterr().out
    assert "engine: pinocchio (asked for (--engine pinocchio))" in out and "engine=" not in out


STUDENT_ARM = str(Path(__file__).parents[2] / "data" / "robots" / "student_arm.urdf")
STUDENT_TARGET = "0.5,-0.5,0.3,0.05,0.02"


def test_pd_on_a_light_wrist_settles_at_one_millisecond_with_the_default_gains(capsys):
    status = main(["simulate", STUDENT_ARM, "--controller", "pd", "--target", STUDENT_TARGET, "--no-joint-friction", "--json"])
    assert status == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["final_joint_error"] < 1e-5


def test_kp_and_kd_set_the_pd_gains_and_a_wrong_count_is_one_line(capsys):
    soft = ["simulate", STUDENT_ARM, "--controller", "pd", "--target", STUDENT_TARGET, "--no-joint-friction", "--json"]
    assert main([*soft, "--kp", "0.05", "--duration", "1"]) == 0
    assert json.loads(capsys.readouterr().out)["final_joint_error"] > 0.1  # far softer than the default: far off after 1 s
    assert main([*soft, "--kp", "1,2"]) == 2
    error = capsys.readouterr().err.strip()
    assert error.count("\n") == 0 and error.startswith("robodyn: error: --kp must be") and "5 (one a joint)" in error
    assert main(["simulate", "rp_arm", "--controller", "osc", "--target", "0.9,0,0.5", "--kd", "3"]) == 2
    assert "--kd must be given only with the pd or computed-torque controller" in capsys.readouterr().err


@pytest.mark.skipif(shutil.which("cc") is None and shutil.which("gcc") is None, reason="no C compiler")
def test_compiled_flag_gives_the_same_summary(capsys):
    arguments = ["simulate", "ur5", "--controller", "pd", "--target", "0.3,-1.2,1.0,-0.5,0.4,0.2", "--duration", "0.5", "--json"]
    assert main([*arguments, "--engine", "pinocchio"]) == 0
    python = json.loads(capsys.readouterr().out)
    assert main([*arguments, "--compiled"]) == 0
    compiled = json.loads(capsys.readouterr().out)
    assert compiled["engine"] == "compiled"
    for left, right in zip(python["final_q"], compiled["final_q"], strict=True):
        assert abs(left - right) < 1e-9
    floating_task = ["--controller", "task-space", "--target", "0.1,0.1,0.1", "--frame", "FL_FOOT"]  # floating: PD / CT only
    assert main(["simulate", "solo12", "--duration", "0.1", "--compiled", *floating_task]) == 2
    assert "floating" in capsys.readouterr().err


# --------------------------------------------------------------------------------------
# Issue 29: `simulate --record` on a robot with several chain ends, and `--frame` naming the
# --------------------------------------------------------------------------------------
FORK = """<robot name="fork">
  <link name="base"><visual><geometry><box size="0.2 0.2 0.1"/></geometry></visual></link>
  <link name="left"><visual><origin xyz="0 0 0.2"/><geometry><box size="0.05 0.05 0.4"/></geometry></visual>
    <inertial><origin xyz="0 0 0.2"/><mass value="1"/><inertia ixx="0.02" iyy="0.02" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="right"><visual><origin xyz="0 0 0.2"/><geometry><box size="0.05 0.05 0.4"/></geometry></visual>
    <inertial><origin xyz="0 0 0.2"/><mass value="1"/><inertia ixx="0.02" iyy="0.02" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j_left" type="revolute"><parent link="base"/><child link="left"/><origin xyz="0 0.1 0.05"/>
    <axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="50" velocity="3"/></joint>
  <joint name="j_right" type="revolute"><parent link="base"/><child link="right"/><origin xyz="0 -0.1 0.05"/>
    <axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="50" velocity="3"/></joint>
</robot>
"""


def _simulate(tmp_path, *extra: str) -> list[str]:
    (tmp_path / "fork.urdf").write_text(FORK)  # two chain ends: no default end effector
    return ["simulate", str(tmp_path / "fork.urdf"), "--controller", "pd", "--target", "0.3,-0.2", "--duration", "0.2",
            "--dt", "0.01", "--record", str(tmp_path / "m.html"), *extra]  # fmt: skip


def test_a_pd_recording_of_a_robot_with_several_chain_ends_draws_no_path(tmp_path, capsys):
    assert main(_simulate(tmp_path)) == 0, capsys.readouterr().err
    assert (tmp_path / "m.html").stat().st_size > 10_000


def test_frame_names_the_path_drawn_under_a_pd_controller(tmp_path, capsys):
    assert main(_simulate(tmp_path, "--frame", "left")) == 0, capsys.readouterr().err
    html = (tmp_path / "m.html").read_text()
    assert "path" in html and (tmp_path / "m.html").stat().st_size > 10_000


SOLO_JOINTS = "0.1,0.8,-1.6,-0.1,0.8,-1.6,0.1,-0.8,1.6,-0.1,-0.8,1.6"


@pytest.mark.parametrize("controller", ["pd", "computed-torque"])
def test_joint_space_control_of_a_floating_robot_takes_its_joints_and_leaves_the_base_free(controller, capsys):
    assert main(["simulate", "solo12", "--controller", controller, "--target", SOLO_JOINTS, "--duration", "1", "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    torques = dict(zip(summary["dof_names"], summary["peak_abs_torque"], strict=True))
    assert all(torques[name] == 0.0 for name in ("base.x", "base.y", "base.z", "base.rx", "base.ry", "base.rz"))
    assert torques["FL_KFE"] > 0.0
    assert summary["final_joint_error"] < (1e-6 if controller == "computed-torque" else 0.02)


def test_a_floating_robots_joint_target_of_the_wrong_length_is_one_line_naming_its_joints(capsys):
    full = "0,0,0.3,0,0,0,1," + SOLO_JOINTS  # 19 values: the whole configuration
    assert main(["simulate", "solo12", "--controller", "pd", "--target", full, "--duration", "0.1"]) == 2
    error = capsys.readouterr().err.strip()
    assert len(error.splitlines()) == 1 and "Traceback" not in error
    assert "--target must be 12 joint values" in error and "'FL_HAA'" in error and "got 19 values" in error
