"""One package lookup for package:// meshes and $(find): packages=, then ROS_PACKAGE_PATH,
then the zoo; drawings, lint and loading all use it."""

from __future__ import annotations

import pickle
import shutil
import warnings

import pytest

import robodyn
from robodyn.exceptions import InputError, MeshPathError, MeshWarning, URDFError
from robodyn.urdf.meshes import resolve_mesh
from robodyn.urdf.packages import package_lookup
from robodyn.urdf.sources import lint_source
from tests.conftest import ROOT

PACKAGE = ROOT / "tests" / "data" / "packages" / "robodyn_test_arm"
URDF = PACKAGE / "urdf" / "two_link.urdf"
MESH = "package://robodyn_test_arm/meshes/link.stl"


def test_an_explicit_package_comes_before_ros_package_path_even_when_its_folder_is_named_otherwise(tmp_path, monkeypatch):
    copy = tmp_path / "checkout-main"
    shutil.copytree(PACKAGE, copy)
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(PACKAGE.parent))
    assert package_lookup().find("robodyn_test_arm") == PACKAGE
    lookup = package_lookup({"robodyn_test_arm": copy})
    assert lookup.find("robodyn_test_arm") == copy.resolve()
    assert resolve_mesh(MESH, base_dir=None, package_dirs=lookup) == copy.resolve() / "meshes" / "link.stl"
    assert pickle.loads(pickle.dumps(lookup)) == lookup and lookup != package_lookup()


def test_ros_package_path_needs_a_package_xml(tmp_path, monkeypatch):
    (tmp_path / "src" / "robodyn_test_arm").mkdir(parents=True)  # a folder of that name, no package.xml
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path))
    assert package_lookup(zoo=False).find("robodyn_test_arm") is None
    (tmp_path / "src" / "robodyn_test_arm" / "package.xml").write_text("<package/>")
    assert package_lookup(zoo=False).find("robodyn_test_arm") == tmp_path / "src" / "robodyn_test_arm"


def test_a_missing_package_names_the_places_looked_in(monkeypatch):
    monkeypatch.setenv("ROS_PACKAGE_PATH", "/nowhere/ros")
    with pytest.raises(URDFError) as raised:
        package_lookup({"other": PACKAGE}).require("robodyn_test_arm", "arm.xacro")
    assert "/nowhere/ros ($ROS_PACKAGE_PATH)" in str(raised.value) and "packages=" in str(raised.value)


@pytest.mark.parametrize("packages", [{"a/b": str(PACKAGE)}, {"robodyn_test_arm": "/no/such/folder"}])
def test_a_bad_packages_argument_is_one_input_error(packages):
    with pytest.raises(InputError, match=r"^packages must be"):
        robodyn.load(URDF, packages=packages)


def test_package_meshes_resolve_for_loading_lint_and_drawings(monkeypatch):
    from robodyn.viz.scene import build_scene

    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    robot = robodyn.load(URDF, packages={"robodyn_test_arm": str(PACKAGE)})
    assert lint_source(URDF, packages={"robodyn_test_arm": str(PACKAGE)}) == []
    with warnings.catch_warnings():
        warnings.simplefilter("error", MeshWarning)
        scene = build_scene(robot)
    assert scene.placeholders == []
    assert robot.spec.joints["shoulder"].damping == 0.5 and robot.spec.joints["shoulder"].friction == 0.05


def test_lint_reports_a_mesh_it_cannot_find_with_the_places_it_looked(monkeypatch):
    monkeypatch.setenv("ROS_PACKAGE_PATH", "/nowhere/ros")
    problems = lint_source(URDF)
    assert problems and all(problem.severity == "warning" for problem in problems)
    assert "not found (looked in /nowhere/ros ($ROS_PACKAGE_PATH)" in problems[0].rule


NOT_NAMES = ["", ".", "..", "a/b", "a\\b", "a\x00b"]


@pytest.mark.parametrize("name", NOT_NAMES)
def test_a_name_that_is_not_a_package_name_is_refused_by_find_and_the_lookup(name, monkeypatch):
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(PACKAGE.parent))
    lookup = package_lookup()
    assert lookup.find(name) is None
    with pytest.raises(URDFError, match=r"is not a package name") as raised:
        lookup.require(name, "arm.xacro")
    assert "\n" not in str(raised.value)


@pytest.mark.parametrize("kind", ["the zoo's folders", "the lookup"])
def test_package_dot_dot_cannot_reach_the_folder_above_the_packages(tmp_path, kind):
    share = tmp_path / "share"
    (share / "robodyn_test_arm").mkdir(parents=True)
    (tmp_path / "secret.stl").write_text("solid x\nendsolid x\n")  # one folder above the package folders
    folders = [share] if kind == "the zoo's folders" else package_lookup({"robodyn_test_arm": share / "robodyn_test_arm"})
    for path in ("package://../secret.stl", "package://./../secret.stl", "package://..\\secret.stl"):
        with pytest.raises(MeshPathError, match=r"is not a package name"):
            resolve_mesh(path, base_dir=None, package_dirs=folders)


def test_find_dot_dot_in_a_xacro_and_package_dot_dot_in_a_urdf_are_one_line_each(tmp_path):
    xacro_text = (
        '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<xacro:include filename="$(find ..)/lib/x.xacro"/><link name="a"/></robot>'
    )
    with pytest.raises(URDFError, match=r"package '\.\.' is not a package name"):
        robodyn.load(xacro_text)
    mesh = '<robot name="r"><link name="a"><visual><geometry><mesh filename="package://../x.stl"/></geometry></visual></link></robot>'
    assert [p.rule for p in lint_source(mesh) if "is not a package name" in p.rule]
