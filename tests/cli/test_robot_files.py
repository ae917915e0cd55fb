"""Robot files as users have them on the command line: a URDF with package:// meshes and
<dynamics>, a xacro with $(find), an MJCF arm — info, check, simulate --record, equations."""

from __future__ import annotations

import json

import pytest

from robodyn.cli.app import main
from tests.conftest import ROOT

PACKAGE = ROOT / "tests" / "data" / "packages" / "robodyn_test_arm"
PACKAGE_FLAG = ["--package", f"robodyn_test_arm={PACKAGE}"]
MODELS = {
    "urdf": [str(PACKAGE / "urdf" / "two_link.urdf"), *PACKAGE_FLAG],
    "xacro": [str(PACKAGE / "urdf" / "arm.urdf.xacro"), *PACKAGE_FLAG, "--xacro-arg", "prefix:=left_"],
    "mjcf": [str(ROOT / "tests" / "data" / "mjcf" / "arm.xml")],
}


def run(capsys, *argv: str) -> tuple[int, str, str]:
    status = main(list(argv))
    captured = capsys.readouterr()
    return status, captured.out, captured.err


@pytest.mark.parametrize(
    "kind", ["urdf", pytest.param("xacro", marks=pytest.mark.slow), pytest.param("mjcf", marks=pytest.mark.slow)]
)
def test_info_check_and_equations_read_each_kind_of_file(capsys, kind):
    model = MODELS[kind]
    status, out, _ = run(capsys, "info", *model, "--json")
    assert status == 0
    info = json.loads(out)
    assert info["robot_name"] == {"urdf": "package_mesh_arm", "xacro": "xacro_test_arm", "mjcf": "mjcf_test_arm"}[kind]
    assert info["file_format"] == kind
    status, out, _ = run(capsys, "check", *model, "--samples", "7")
    assert status == 0 and "PASSED" in out
    status, out, _ = run(capsys, "equations", *model)
    assert status == 0 and out


@pytest.mark.parametrize("kind", sorted(MODELS))
def test_simulate_records_each_kind_of_file(capsys, tmp_path, kind):
    status, _, err = run(capsys, "simulate", *MODELS[kind], "--duration", "0.05", "--record", str(tmp_path / "run.html"))
    assert status == 0
    assert "placeholder" not in err and (tmp_path / "run.html").stat().st_size > 1000


def test_info_shows_the_robot_name_mimic_joints_and_package_paths(capsys):
    status, out, _ = run(capsys, "info", *MODELS["xacro"])
    assert status == 0
    assert out.startswith('robot xacro_test_arm ("arm"), expanded from xacro')
    assert "left_finger_joint = 0.5 × left_shoulder + 0.1" in out
    assert f"robodyn_test_arm={PACKAGE} (--package)" in out
    status, out, _ = run(capsys, "info", *MODELS["xacro"], "--json")
    info = json.loads(out)
    assert info["mimic_joints"] == [{"joint": "left_finger_joint", "source": "left_shoulder", "multiplier": 0.5, "offset": 0.1}]
    assert [row["joint"] for row in info["joint_dynamics"]] == ["left_shoulder", "left_slide", "left_wrist_roll"]
    assert info["package_paths"]["packages"] == [f"robodyn_test_arm={PACKAGE}"]


@pytest.mark.parametrize(
    ("flags", "message"),
    [
        (["--xacro-arg", "prefix=left_"], "--xacro-arg must be NAME:=VALUE"),
        (["--xacro-arg", ":=x"], "--xacro-arg must be NAME:=VALUE"),
        (["--package", "robodyn_test_arm"], "--package must be NAME=DIR"),
        (["--package", "robodyn_test_arm=/no/such/folder"], "--package must be an existing folder"),
        (["--xacro-arg", "no_such:=1", "--package", "x=/"], ""),
    ],
)
def test_malformed_file_flags_are_one_line_and_exit_2(capsys, flags, message):
    status, out, err = run(capsys, "info", str(PACKAGE / "urdf" / "arm.urdf.xacro"), *flags)
    if not message:  # an unused xacro argument is fine; the package is then unresolved
        assert status == 2 and "package 'robodyn_test_arm' not found" in err and "--package gives its folder" in err
    else:
        assert status == 2 and message in err
    assert len(err.strip().splitlines()) == 1 and out == ""


def test_lint_takes_the_file_flags_and_an_sdf_is_one_line(capsys, tmp_path):
    status, out, _ = run(capsys, "lint", *MODELS["xacro"])
    assert status == 0 and "0 errors, 0 warnings" in out
    (tmp_path / "m.sdf").write_text('<sdf version="1.7"><model name="m"/></sdf>')
    status, _, err = run(capsys, "info", str(tmp_path / "m.sdf"))
    assert status == 2 and "gz sdf -p model.sdf > model.urdf" in err and len(err.strip().splitlines()) == 1


def test_symbolic_equations_of_a_xacro_take_its_packages_and_arguments(capsys, monkeypatch):
    """``equations --symbolic`` reads a xacro as ``robodyn.load`` does: ``--package`` resolves
    its ``$(find)`` and ``--xacro-arg`` reaches it (the prefix renames the joints); without the
    package the same call is one line naming it."""
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    status, out, _ = run(capsys, "equations", *MODELS["xacro"], "--symbolic", "--format", "json")
    assert status == 0
    names = json.loads(out)["joint_names"]
    assert names and all(name.startswith("left_") for name in names)
    status, _, err = run(capsys, "equations", str(PACKAGE / "urdf" / "arm.urdf.xacro"), "--symbolic")
    assert status == 2 and "package 'robodyn_test_arm' not found" in err and "--package" in err


HOSTILE_XACRO = {
    "python.vars": "<link name=\"${python.vars(python.type)['mro'](python.type(()))}\"/>",
    "load_yaml": "<link name=\"${xacro.load_yaml('/etc/passwd')}\"/>",
    "optenv": '<link name="x$(optenv HOME)"/>',
    "power": '<link name="${10**10**10}"/>',
}


@pytest.mark.parametrize("name", ["robot.xacro", "plain.urdf"])
@pytest.mark.parametrize("kind", sorted(HOSTILE_XACRO))
def test_info_on_a_hostile_xacro_is_one_stderr_line_and_exit_2(capsys, tmp_path, name, kind):
    path = tmp_path / name
    path.write_text(
        f'<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">{HOSTILE_XACRO[kind]}<link name="base"/></robot>'
    )
    status, out, err = run(capsys, "info", str(path))
    assert status == 2 and out == "" and len(err.strip().splitlines()) == 1
    assert err.startswith(f"robodyn: error: {path}: xacro: ")
    assert "root:" not in err and "<class" not in err


def test_xacro_env_lets_a_xacro_read_the_environment_and_the_refusal_names_the_flag(capsys, tmp_path, monkeypatch):
    monkeypatch.setenv("ROBODYN_TEST_PREFIX", "env_")
    text = (PACKAGE / "urdf" / "arm.urdf.xacro").read_text().replace("$(arg prefix)", "$(optenv ROBODYN_TEST_PREFIX)")
    (tmp_path / "arm.urdf.xacro").write_text(text.replace("$(find robodyn_test_arm)/urdf", str(PACKAGE / "urdf")))
    model = [str(tmp_path / "arm.urdf.xacro"), *PACKAGE_FLAG]
    status, _, err = run(capsys, "info", *model)
    assert status == 2 and "'ROBODYN_TEST_PREFIX'" in err and "unless --xacro-env" in err and "xacro_env=True" not in err
    status, out, _ = run(capsys, "info", *model, "--xacro-env", "--json")
    assert status == 0 and json.loads(out)["joint_dynamics"][0]["joint"] == "env_shoulder"
    status, out, _ = run(capsys, "equations", *model, "--xacro-env", "--symbolic", "--format", "json")
    assert status == 0 and json.loads(out)["joint_names"][0] == "env_shoulder"


def test_lint_names_a_urdf_holding_xacro_by_its_path_however_long(capsys, tmp_path):
    path = tmp_path / ("a_long_robot_description_name_" * 3 + ".urdf")
    text = (PACKAGE / "urdf" / "arm.urdf.xacro").read_text()
    path.write_text(text.replace("$(find robodyn_test_arm)/urdf", str(PACKAGE / "urdf")))
    status, out, _ = run(capsys, "lint", str(path), *PACKAGE_FLAG)
    assert status == 0 and out.splitlines()[-1] == f"{path}: 0 errors, 0 warnings" and len(str(path)) > 80
