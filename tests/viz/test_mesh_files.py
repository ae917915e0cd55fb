"""Hostile meshes: corrupt, special files, over the cap -> a placeholder and a warning, never an empty page."""

from __future__ import annotations

import os
import struct
import subprocess
import sys

import numpy as np
import pytest

import robodyn
from robodyn.exceptions import MeshFileError, MeshWarning
from robodyn.trajectory import Trajectory
from robodyn.viz.mesh_files import read_mesh
from robodyn.viz.recording import recording
from tests.conftest import ROOT
from tests.viz.test_viewer import commands_of


def _stl(triangles: int = 2) -> bytes:
    rng = np.random.default_rng(3)
    body = b"".join(struct.pack("<12fH", *rng.uniform(-0.1, 0.1, 12), 0) for _ in range(triangles))
    return b"\0" * 80 + struct.pack("<I", triangles) + body


URDF = """<robot name="meshy">
  <link name="base"><visual><geometry><mesh filename="{base}"/></geometry></visual>
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="arm"><visual><geometry><mesh filename="{arm}" scale="2 1 0.5"/></geometry></visual>
    <inertial><origin xyz="0 0 0.2"/><mass value="0.7"/><inertia ixx="0.02" iyy="0.02" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="hinge" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0.6 0.8"/>
    <limit lower="-2" upper="2" effort="10" velocity="3"/></joint>
</robot>"""


def _robot(folder, base: str, arm: str = "good.stl"):
    (folder / "good.stl").write_bytes(_stl())
    path = folder / "meshy.urdf"
    path.write_text(URDF.format(base=base, arm=arm))
    return robodyn.load(str(path))


def _motion(robot):
    t = np.linspace(0, 1, 11)
    q = np.linspace(-0.5, 0.7, 11)[:, None]
    return Trajectory(t, q, np.zeros_like(q), np.zeros_like(q), np.zeros_like(q), robot.joint_names, robot.name)


def _bad_files(folder):
    (folder / "corrupt.stl").write_bytes(b"\0" * 80 + struct.pack("<I", 1000) + b"\1" * 200)  # 1000 triangles promised
    (folder / "corrupt.dae").write_text("<COLLADA><library_geometries><geometry><mesh><source")  # cut off
    (folder / "words.stl").write_text("solid nothing\nthis is not a mesh\nendsolid\n")
    (folder / "empty.obj").write_bytes(b"")
    os.mkfifo(folder / "pipe.stl")
    os.symlink("/dev/zero", folder / "zero.stl")
    return ["corrupt.stl", "corrupt.dae", "words.stl", "empty.obj", "pipe.stl", "zero.stl", "missing.stl"]


def test_good_mesh_is_read_with_its_bounds(tmp_path):
    (tmp_path / "good.stl").write_bytes(_stl(5))
    geometry, bounds = read_mesh(tmp_path / "good.stl")
    assert geometry.mesh_format == "stl" and bounds.shape == (2, 3)
    assert np.all(bounds[0] < bounds[1]) and np.all(np.abs(bounds) <= 0.1)


@pytest.mark.parametrize("kind", ["corrupt.stl", "corrupt.dae", "words.stl", "empty.obj", "pipe.stl"])
def test_bad_mesh_files_are_refused_by_the_reader(tmp_path, kind):
    _bad_files(tmp_path)
    with pytest.raises(MeshFileError):
        read_mesh(tmp_path / kind)


def test_a_device_is_refused_by_the_reader_and_a_link_to_one_by_the_loader(tmp_path):
    with pytest.raises(MeshFileError, match="not a regular file"):
        read_mesh("/dev/zero")
    _bad_files(tmp_path)
    with pytest.raises(robodyn.URDFError, match="leaves the URDF's folder"):  # zero.stl -> /dev/zero
        _robot(tmp_path, "zero.stl")


def test_mesh_over_the_cap_is_refused_and_the_cap_overridable(tmp_path):
    (tmp_path / "big.stl").write_bytes(_stl(40))  # 2084 bytes
    with pytest.raises(MeshFileError, match="over the cap"):
        read_mesh(tmp_path / "big.stl", max_bytes=1000)
    assert read_mesh(tmp_path / "big.stl", max_bytes=5000)[1].shape == (2, 3)


@pytest.mark.parametrize("bad", ["corrupt.stl", "corrupt.dae", "words.stl", "empty.obj", "missing.stl", "pipe.stl"])
def test_bad_mesh_becomes_a_placeholder_in_the_recording(tmp_path, bad):
    _bad_files(tmp_path)
    robot = _robot(tmp_path, bad)
    with pytest.warns(MeshWarning, match="placeholder"):
        made = recording(robot, _motion(robot))
    assert len(made.placeholders) == 1 and "'base'" in made.placeholders[0]
    objects = [c for c in commands_of(made.html) if c["type"] == "set_object" and c["path"].startswith("/robodyn/")]
    kinds = {c["path"].split("/")[2]: c["object"]["geometries"][0]["type"] for c in objects}
    assert kinds == {"base": "BoxGeometry", "arm": "_meshfile"}  # the placeholder, and the good mesh still drawn


def test_cap_applies_in_recordings(tmp_path):
    robot = _robot(tmp_path, "good.stl")
    with pytest.warns(MeshWarning, match="over the cap"):
        made = recording(robot, _motion(robot), max_mesh_bytes=100)
    assert len(made.placeholders) == 2


def test_record_command_warns_in_one_line_for_each_bad_mesh(tmp_path):
    _bad_files(tmp_path)
    robot = _robot(tmp_path, "words.stl", arm="corrupt.dae")
    _motion(robot).save(tmp_path / "m.npz")
    result = subprocess.run(
        [sys.executable, "-c", "import sys; from robodyn.cli import main; sys.exit(main())", "record", str(tmp_path / "meshy.urdf"), "--trajectory",
         str(tmp_path / "m.npz"), "--out", str(tmp_path / "m.html")],
        capture_output=True, text=True, timeout=60, cwd=ROOT,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 2 and all(line.startswith("robodyn: warning: link ") for line in lines)
    assert "not a valid STL" in result.stderr and "not a valid DAE" in result.stderr
    assert (tmp_path / "m.html").stat().st_size > 100_000


def test_record_command_cap_option(tmp_path):
    from robodyn.cli.app import main

    robot = _robot(tmp_path, "good.stl")
    _motion(robot).save(tmp_path / "m.npz")
    command = ["record", str(tmp_path / "meshy.urdf"), "--trajectory", str(tmp_path / "m.npz"), "--out", str(tmp_path / "m.html")]
    assert main([*command, "--max-mesh-mb", "0.0001"]) == 0  # 100 bytes: both meshes become placeholders
    assert main([*command, "--max-mesh-mb", "-1"]) == 2
