"""IdentificationRun: ``robodyn identify`` as one library call with its text and files (issue 23)."""

from __future__ import annotations

import json

import numpy as np
import pytest

import robodyn
from robodyn.cli import main
from robodyn.exceptions import InputError
from robodyn.ident import base_parameters
from robodyn.ident.run import IdentificationRun, excite_run, identify_run
from robodyn.trajectory import Trajectory


@pytest.fixture
def data(tmp_path):
    """Exciting motion of the RP arm with its model's torques, as a file and loaded."""
    robot = robodyn.load("rp_arm")
    rng = np.random.default_rng(7)
    count = 200
    q = robot.random_configuration(rng, count)
    v, a = rng.normal(size=(2, count, robot.nv))
    tau = robot.inverse_dynamics(q, v, a)
    path = tmp_path / "measured.csv"
    Trajectory(np.arange(count) * 0.01, q, v, a, tau, list(robot.joint_names), robot.name).save(path)
    return robot, path


def test_the_run_text_and_files_are_what_the_cli_prints_and_writes(data, tmp_path, capsys):
    robot, path = data
    cli_out = tmp_path / "cli.json"
    assert main(["identify", "rp_arm", str(path), "--method", "wls", "--out", str(cli_out)]) == 0
    printed = capsys.readouterr().out
    lib_out = tmp_path / "lib.json"
    run = identify_run(robot, Trajectory.load(path).for_robot(robot), method="wls", out=lib_out)
    assert isinstance(run, IdentificationRun)
    assert printed.rstrip("\n") == run.text().replace(str(lib_out), str(cli_out))
    assert json.loads(cli_out.read_text()) == json.loads(lib_out.read_text()) == json.loads(json.dumps(run.to_dict()))
    assert run.identification.relative_error < 1e-9


def test_a_urdf_out_without_the_physical_method_names_the_parameter_in_the_library_and_the_flag_in_the_cli(
    data, tmp_path, capsys
):
    robot, path = data
    with pytest.raises(InputError) as raised:
        identify_run(robot, Trajectory.load(path).for_robot(robot), urdf_out=tmp_path / "x.urdf")
    assert raised.value.argument == "urdf_out" and "--" not in str(raised.value)
    assert main(["identify", "rp_arm", str(path), "--urdf-out", str(tmp_path / "x.urdf")]) == 2
    assert capsys.readouterr().err.startswith("robodyn: error: --urdf-out must be used with method")
    assert not (tmp_path / "x.urdf").exists()


def test_data_without_torques_is_refused_naming_data(data, tmp_path, capsys):
    robot, path = data
    loaded = Trajectory.load(path).for_robot(robot)
    bare = Trajectory(loaded.t, loaded.q, loaded.v, loaded.a, None, list(robot.joint_names), robot.name)
    with pytest.raises(InputError, match=r"^data must be a trajectory with tau"):
        identify_run(robot, bare)
    bare.save(tmp_path / "bare.csv")
    assert main(["identify", "rp_arm", str(tmp_path / "bare.csv")]) == 2
    assert "DATA must be a trajectory with tau[<joint>] columns" in capsys.readouterr().err


def test_excite_run_writes_the_trajectory_its_text_and_json_describe(tmp_path):
    robot = robodyn.load("rp_arm")
    out = tmp_path / "excitation.csv"
    run = excite_run(robot, out=out, rate=50.0, harmonics=2, duration=2.0, iterations=3, seed=1)
    written = Trajectory.load(out).for_robot(robot)
    assert run.samples == len(written.t) == 100 and run.to_dict()["samples"] == 100
    np.testing.assert_allclose(written.tau, robot.inverse_dynamics(written.q, written.v, written.a), atol=1e-9)
    assert run.to_dict()["base_parameters"] == run.base_count == base_parameters(robot).count
    assert f"{run.excitation.condition:.4g}" in run.text() and str(out) in run.text()


def _payload_data(tmp_path, count: int = 150):
    """The RP arm whose slider carries an unknown 0.6 kg payload: measured torques of the true
    robot, written as a file; the nominal model and the true one."""
    nominal = robodyn.load("rp_arm")
    true_text = robodyn.rp_arm_urdf().replace('<mass value="1.0"/>', '<mass value="1.6"/>', 1)
    assert true_text != robodyn.rp_arm_urdf()
    true = robodyn.load(true_text)
    rng = np.random.default_rng(11)
    q = nominal.random_configuration(rng, count)
    v, a = rng.normal(size=(2, count, nominal.nv))
    path = tmp_path / "payload.csv"
    Trajectory(np.arange(count) * 0.01, q, v, a, true.inverse_dynamics(q, v, a), list(nominal.joint_names), "rp_arm").save(path)
    return nominal, true, path


def _inertial_of(text: str, link: str) -> str:
    import xml.etree.ElementTree as ET

    node = next(n for n in ET.fromstring(text).findall("link") if n.get("name") == link)
    return ET.tostring(node.find("inertial"), encoding="unicode")


def test_identify_bodies_on_the_command_line_changes_only_those_links(tmp_path, capsys):
    # Issue 29, item 11: the library's bodies= reached from the CLI, with --urdf-out.
    nominal, true, path = _payload_data(tmp_path)
    urdf_out = tmp_path / "identified.urdf"
    command = ["identify", "rp_arm", str(path), "--method", "physical", "--bodies", "link2", "--urdf-out", str(urdf_out)]
    assert main(command) == 0
    printed = capsys.readouterr().out
    assert "[link1]" not in printed and "m[link2]" in printed
    written = urdf_out.read_text()
    assert _inertial_of(written, "link1") == _inertial_of(_text(nominal), "link1")  # untouched
    identified = robodyn.load(written)
    assert identified.total_mass == pytest.approx(true.total_mass, rel=1e-6)
    q = nominal.random_configuration(np.random.default_rng(3), 20)
    np.testing.assert_allclose(identified.inverse_dynamics(q, 0 * q, 0 * q), true.inverse_dynamics(q, 0 * q, 0 * q), atol=1e-6)
    run = identify_run(nominal, Trajectory.load(path).for_robot(nominal), method="ls", bodies=["link2"])
    names = run.identification.base.names
    assert names and all("[link2]" in name for name in names)
    assert main(["identify", "rp_arm", str(path), "--bodies", "link9"]) == 2
    assert "link1, link2" in capsys.readouterr().err


def _text(robot) -> str:
    import xml.etree.ElementTree as ET

    return ET.tostring(robot.spec.xml, encoding="unicode")
