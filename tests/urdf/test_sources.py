"""Family 3 of issue #14: bounded resources (special files, sizes, depth, time, memory)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from contextlib import contextmanager

import pytest

import robodyn
from robodyn.dynamics.loading import MAX_DOF, data_memory_estimate
from robodyn.exceptions import RobodynError, UnknownRobotError, URDFError
from robodyn.urdf.sources import MAX_URDF_BYTES
from robodyn.urdf.validation import lint_urdf
from tests.data.make_hostile_corpus import chain


@contextmanager
def no_hang(seconds: int = 20):
    """Fail (instead of hanging the suite) if the block blocks."""

    def alarm(signum, frame):
        raise TimeoutError("blocked")

    previous = signal.signal(signal.SIGALRM, alarm)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


def test_a_fifo_as_the_urdf_is_refused_without_blocking(tmp_path):
    fifo = tmp_path / "robot.urdf"
    os.mkfifo(fifo)
    with no_hang(), pytest.raises(URDFError, match="is not a regular file \\(a FIFO\\)"):
        robodyn.load(fifo)
    with no_hang(), pytest.raises(URDFError, match="a FIFO"):
        robodyn.load(str(fifo))


@pytest.mark.parametrize("device", ["/dev/zero", "/dev/urandom", "/dev/null"])
def test_devices_and_links_to_them_are_refused(device, tmp_path):
    if not os.path.exists(device):
        pytest.skip(f"no {device}")
    link = tmp_path / "robot.urdf"
    link.symlink_to(device)
    for source in (device, link):
        with no_hang(), pytest.raises(URDFError, match="a character device"):
            robodyn.load(source)


def test_a_directory_is_refused(tmp_path):
    folder = tmp_path / "robot.urdf"
    folder.mkdir()
    with pytest.raises(URDFError, match="a directory"):
        robodyn.load(folder)


def test_the_size_cap_is_documented_and_overridable(tmp_path, monkeypatch):
    path = tmp_path / "arm.urdf"
    path.write_text(robodyn.rp_arm_urdf())
    size = path.stat().st_size
    assert MAX_URDF_BYTES >= 16 * 1024 * 1024
    with pytest.raises(URDFError, match=f"is {size} bytes, more than the limit of {size - 1}.*max_bytes="):
        robodyn.load(path, max_bytes=size - 1)
    assert robodyn.load(path, max_bytes=size).nv == 2
    monkeypatch.setenv("ROBODYN_MAX_URDF_BYTES", str(size - 1))
    with pytest.raises(URDFError, match="ROBODYN_MAX_URDF_BYTES"):
        robodyn.load(path)
    with pytest.raises(URDFError, match="more than the limit"):
        robodyn.load(robodyn.rp_arm_urdf())  # URDF text too


def test_a_mesh_that_is_a_fifo_loads_without_a_hang_and_a_link_to_a_device_is_an_error(tmp_path):
    # Issue 29: a FIFO mesh is one more bad mesh (a lint warning, a placeholder in drawings);
    # a link leaving the model's folder stays an error.
    (tmp_path / "meshes").mkdir()
    os.mkfifo(tmp_path / "meshes" / "link.stl")
    (tmp_path / "meshes" / "zero.stl").symlink_to("/dev/zero")
    for mesh in ("meshes/link.stl", "meshes/zero.stl"):
        text = robodyn.rp_arm_urdf().replace(
            '<geometry><box size="0.5 0.05 0.05"/></geometry>', f'<geometry><mesh filename="{mesh}"/></geometry>', 1
        )
        path = tmp_path / "arm.urdf"
        path.write_text(text)
        if mesh.endswith("link.stl"):
            with no_hang():
                assert robodyn.load(path).nv == 2
        else:
            with no_hang(), pytest.raises(URDFError, match=r"outside|leaves"):
                robodyn.load(path)


@pytest.mark.parametrize(
    "source", ["a" * 5000 + ".urdf", "b" * 5000, "/" + "c" * 300 + "/robot.urdf", "robot\x00.urdf", "x/" * 3000]
)
def test_names_too_long_or_impossible_give_one_line(source):
    with pytest.raises((URDFError, UnknownRobotError)) as raised:
        robodyn.load(source)
    assert "\n" not in str(raised.value)


def test_deep_nesting_is_one_line_not_a_recursion_error():
    text = robodyn.rp_arm_urdf().replace('<link name="link1">', '<link name="link1">' + "<a>" * 5000 + "</a>" * 5000, 1)
    with pytest.raises(URDFError, match="nested deeper than 100 levels"):
        robodyn.load(text)


def test_a_star_of_5000_links_validates_in_linear_time():
    parts = ['<robot name="star">', '<link name="hub"/>']
    for i in range(5000):
        parts.append(
            f'<joint name="j{i}" type="fixed"><parent link="hub"/><child link="l{i}"/></joint>'
            f'<link name="l{i}"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>'
        )
    spec, _ = lint_urdf("".join([*parts, "</robot>"]), floating_base=True)
    assert spec is not None and len(spec.links) == 5001


@pytest.mark.slow
def test_a_star_of_50000_links_validates():
    parts = ['<robot name="star">', '<link name="hub"/>']
    for i in range(50000):
        parts.append(
            f'<joint name="j{i}" type="revolute"><parent link="hub"/><child link="l{i}"/><axis xyz="0 0 1"/>'
            f'<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
            f'<link name="l{i}"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>'
        )
    spec, _ = lint_urdf("".join([*parts, "</robot>"]))
    assert spec is not None


def test_too_many_degrees_of_freedom_are_refused_before_pinocchio_allocates():
    text = chain(12)
    with pytest.raises(URDFError) as raised:
        robodyn.load(text, max_dof=10)
    message = str(raised.value)
    assert "12 degrees of freedom need about" in message and "GB" in message and "max_dof=" in message
    assert robodyn.load(text, max_dof=12).nv == 12
    assert MAX_DOF == 300 and data_memory_estimate(401, 401) > 3.9e9  # star_400: 4.1 GB measured


#: Measured in a process that imports Pinocchio only (the URDF comes on stdin): robodyn's own
#: imports would leave the heap in a state that changes what ``createData`` maps anew.
MEASURE = """
import sys
import pinocchio as pin

def resident():
    with open("/proc/self/statm") as stream:
        return int(stream.read().split()[1]) * 4096

model = pin.buildModelFromXML(sys.stdin.read())
before = resident()
data = model.createData()
print(resident() - before)
"""


@pytest.mark.parametrize("joints", [40, 80])
def test_the_memory_estimate_bounds_what_pinocchio_takes(joints):
    if not os.path.exists("/proc/self/statm"):
        pytest.skip("needs Linux's /proc")
    from tests.data.make_hostile_corpus import chain

    result = subprocess.run(
        [sys.executable, "-c", MEASURE], input=chain(joints), capture_output=True, text=True, check=True, cwd=os.getcwd()
    )
    measured = int(result.stdout.split()[-1])
    estimate = data_memory_estimate(joints, joints + 1)
    assert measured <= estimate <= 3 * measured + 4_000_000


def test_errors_of_this_family_are_robodyn_errors():
    assert issubclass(URDFError, RobodynError)


@pytest.mark.parametrize(
    ("text", "is_xacro"),
    [
        ('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="a"/></robot>', False),
        ('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:property name="p" value="1"/></robot>', True),
        ('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="${1}"/></robot>', True),
        ('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="$(arg a)"/></robot>', True),
        ('<robot name="r"><link name="${1}"/></robot>', False),  # no namespace: a plain URDF (its name is odd)
        ('\n\n<?xml version="1.0"?>\n<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:if value="1"/></robot>', True),
    ],
)
def test_xacro_is_expanded_where_the_namespace_and_xacro_use_meet(text, is_xacro):
    from robodyn.urdf.xacro_files import is_xacro_text

    assert is_xacro_text(text) is is_xacro


def test_a_urdf_file_holding_xacro_is_named_by_its_path_in_a_refusal(tmp_path):
    path = tmp_path / "plain.urdf"
    path.write_text('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="${().__class__}"/></robot>')
    with pytest.raises(URDFError) as raised:
        robodyn.load(path)
    assert str(raised.value).startswith(f"{path}: xacro: the expression '().__class__'")
