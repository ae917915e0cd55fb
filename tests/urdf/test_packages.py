"""One package lookup for package:// meshes and $(find): packages=, then ROS_PACKAGE_PATH,
then the zoo; drawings, lint and loading all use it."""

from __future__ import annotations

import pickle
import shutil
import warnings

import pytest

import robodyn
from robodyn.exceptions import InputError, MeshWarning, URDFError
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
