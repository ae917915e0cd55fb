"""xacro sources: expanded by the xacro package with robodyn's package lookup, compared with
xacro + Pinocchio run directly; every failure one line, nothing printed."""

from __future__ import annotations

import os
import warnings

import numpy as np
import pinocchio as pin
import pytest
import xacro

import robodyn
import robodyn.reference
from robodyn.exceptions import RobodynWarning, URDFError
from tests.conftest import ROOT

PACKAGE = ROOT / "tests" / "data" / "packages" / "robodyn_test_arm"
ARM = PACKAGE / "urdf" / "arm.urdf.xacro"
PACKAGES = {"robodyn_test_arm": str(PACKAGE)}


def expanded_directly(tmp_path, args: dict[str, str]) -> str:
    """The arm expanded by xacro itself, its $(find) written out by hand (no ROS here)."""
    for name in ("arm.urdf.xacro", "macros.xacro"):
        text = (PACKAGE / "urdf" / name).read_text().replace("$(find robodyn_test_arm)", str(tmp_path))
        (tmp_path / "urdf").mkdir(exist_ok=True)
        (tmp_path / "urdf" / name).write_text(text)
    return xacro.process_file(str(tmp_path / "urdf" / "arm.urdf.xacro"), mappings=args).toprettyxml()


def test_a_xacro_with_find_args_macros_and_an_include_gives_xacro_and_pinocchios_tau(tmp_path, capsys):
    args = {"prefix": "left_", "upper_mass": "2.1", "finger": "false"}  # Pinocchio's own mimic τ is another thing
    robot = robodyn.load(ARM, xacro_args=args, packages=PACKAGES, gravity=(0.4, 0.1, -9.7))
    model = pin.buildModelFromXML(expanded_directly(tmp_path, args))
    model.gravity.linear = np.array([0.4, 0.1, -9.7])
    data = model.createData()
    assert robot.joint_names == ["left_shoulder", "left_slide", "left_wrist_roll"]
    assert robot.spec.name == "xacro_test_arm" and robot.source.file_format == "xacro"
    assert robot.total_mass == pytest.approx(2.1 + 0.7 + 0.4, abs=1e-12)
    rng = np.random.default_rng(7)
    worst = 0.0
    for q in robot.random_configuration(rng, 7):
        v, a = rng.normal(size=robot.nv), rng.normal(size=robot.nv)
        tau = robot.inverse_dynamics(q, v, a)
        expected = _pinocchio_tau(model, data, robot, q, v, a)
        worst = max(worst, float(np.abs(tau - expected).max()))
    assert worst <= 1e-12
    assert capsys.readouterr() == ("", "")


def _pinocchio_tau(model, data, robot, q, v, a) -> np.ndarray:
    """Pinocchio's τ of the directly expanded URDF, matched to robodyn's joints by name."""
    order = [model.getJointId(name) for name in robot.joint_names]
    qs, vs, accs = (np.zeros(model.nq), np.zeros(model.nv), np.zeros(model.nv))
    for index, joint in zip(order, robot.joint_names, strict=True):
        position = robot.joint_names.index(joint)
        start = model.joints[index].idx_q
        if model.joints[index].nq == 2:  # a continuous joint: cos, sin in Pinocchio's q
            qs[start : start + 2] = np.cos(q[position]), np.sin(q[position])
        else:
            qs[start] = q[position]
        vs[model.joints[index].idx_v] = v[position]
        accs[model.joints[index].idx_v] = a[position]
    tau = pin.rnea(model, data, qs, vs, accs)
    return np.array([tau[model.joints[index].idx_v] for index in order])


def test_different_xacro_args_are_caught_and_the_default_keeps_the_mimic_finger():
    default = robodyn.load(ARM, packages=PACKAGES)
    heavier = robodyn.load(ARM, packages=PACKAGES, xacro_args={"upper_mass": "2.1"})
    assert heavier.total_mass - default.total_mass == pytest.approx(0.8, abs=1e-12)
    assert default.joint_names == ["shoulder", "slide", "wrist_roll"]
    assert default.spec.joints["finger_joint"].mimic.joint == "shoulder"
    expanded = robodyn.load(default.urdf)  # the expansion as plain URDF: the same robot
    q = default.random_configuration(np.random.default_rng(4))
    assert np.abs(expanded.mass_matrix(q) - default.mass_matrix(q)).max() == 0


def test_find_resolves_through_ros_package_path(monkeypatch):
    monkeypatch.setenv("ROS_PACKAGE_PATH", os.pathsep.join(["/nonexistent", str(PACKAGE.parent)]))
    robot = robodyn.load(ARM)
    assert robot.package_dirs.find("robodyn_test_arm") == PACKAGE


def test_xacro_text_is_expanded_too_its_includes_inside_a_named_package():
    text = ARM.read_text().replace("$(find robodyn_test_arm)", str(PACKAGE))
    robot = robodyn.load(text, xacro_args={"prefix": "r_"}, packages=PACKAGES)
    assert robot.joint_names == ["r_shoulder", "r_slide", "r_wrist_roll"]
    with pytest.raises(URDFError, match=r"xacro: the include '.*macros\.xacro' is outside the file's folder tree"):
        robodyn.load(text)  # XML text has no folder: an include must be inside a package or the zoo


def test_the_reference_reads_the_same_expansion():
    robot = robodyn.load(ARM, packages=PACKAGES)
    reference = robodyn.reference.load(ARM, packages=PACKAGES)
    q = robot.random_configuration(np.random.default_rng(3))
    assert np.abs(reference.mass_matrix(q) - robot.mass_matrix(q)).max() < 1e-12


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (("$(find robodyn_test_arm)", "$(find no_such_package)"), "package 'no_such_package' not found (looked in"),
        (("macros.xacro", "missing.xacro"), "missing.xacro: no such file"),
        (('x="0.04" y="0.06" z="0.1"', 'x="0.04" y="0.06"'), "xacro: "),
        (("$(arg prefix)", "$(arg no_such_arg)"), "undefined argument 'no_such_arg'"),
        (("${-pi/2}", "${__import__('os')}"), "xacro: "),
        (('<link name="${prefix}base"/>', '<link name="${prefix}base">'), "xacro: "),
    ],
)
def test_a_xacro_that_does_not_expand_is_one_line_naming_why(tmp_path, capsys, edit, message):
    for name in ("arm.urdf.xacro", "macros.xacro"):
        (tmp_path / name).write_text((PACKAGE / "urdf" / name).read_text().replace(*edit))
    (tmp_path / "arm.urdf.xacro").write_text(
        (tmp_path / "arm.urdf.xacro").read_text().replace("$(find robodyn_test_arm)/urdf", str(tmp_path))
        if edit[0] != "$(find robodyn_test_arm)"
        else (tmp_path / "arm.urdf.xacro").read_text()
    )
    with pytest.raises(URDFError) as raised:
        robodyn.load(tmp_path / "arm.urdf.xacro", packages=PACKAGES)
    assert message in str(raised.value) and "\n" not in str(raised.value)
    assert capsys.readouterr() == ("", "")


def test_an_include_that_is_a_fifo_or_too_large_is_refused(tmp_path):
    os.mkfifo(tmp_path / "fifo.xacro")
    (tmp_path / "top.xacro").write_text(
        '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:include filename="fifo.xacro"/></robot>'
    )
    with pytest.raises(URDFError, match=r"fifo\.xacro: is not a regular file"):
        robodyn.load(tmp_path / "top.xacro")
    (tmp_path / "big.xacro").write_text("<robot>" + " " * 5000 + "</robot>")
    (tmp_path / "top.xacro").write_text((tmp_path / "top.xacro").read_text().replace("fifo", "big"))
    with pytest.raises(URDFError, match=r"big\.xacro: is 5015 bytes, more than the limit of 1000"):
        robodyn.load(tmp_path / "top.xacro", max_bytes=1000)


def test_what_xacro_prints_becomes_one_warning(tmp_path, capsys):
    (tmp_path / "say.xacro").write_text(
        ARM.read_text().replace('<link name="${prefix}base"/>', '<link name="${prefix}base"/>${xacro.warning("hello")}')
    )
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        robodyn.load(tmp_path / "say.xacro", packages=PACKAGES)
    assert [w for w in caught if issubclass(w.category, RobodynWarning) and "hello" in str(w.message)]
    assert capsys.readouterr() == ("", "")
