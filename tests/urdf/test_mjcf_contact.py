"""MJCF geoms as collision geometry by MuJoCo's contype/conaffinity rule, and the
worldbody's plane as the robot's ground (height, normal, the pair's friction)."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import robodyn
from robodyn.exceptions import InputError, RobodynWarning, URDFError
from robodyn.reference import load as load_reference
from robodyn.sim.ground import Ground, collision_points, resolve_ground
from tests.conftest import ROOT

DATA = ROOT / "tests" / "data" / "mjcf"


def _load(tmp_path, body: str, world: str = '<geom type="plane" size="1 1 0.1"/>', **options) -> robodyn.Robot:
    path = tmp_path / "robot.xml"
    path.write_text(
        f'<mujoco model="m"><worldbody>{world}<body name="b" pos="0 0 1"><freejoint/>{body}</body></worldbody></mujoco>'
    )
    return robodyn.load(path, **options)


def test_a_box_geom_is_a_collision_box_whose_corners_are_contact_points():
    robot = robodyn.load(DATA / "contact_box.xml")
    found = collision_points(robot)
    corners = np.array([point.position for point in found.points])
    assert len(corners) == 8 and found.skipped == ()
    assert np.allclose(np.sort(np.abs(corners), axis=0), np.tile([0.15, 0.1, 0.05], (8, 1)))


def test_the_worldbody_plane_is_the_ground_with_the_larger_friction_of_the_pair():
    robot = robodyn.load(DATA / "contact_box.xml")
    assert robot.source.ground == (0.1, (0.0, 0.0, 1.0), 0.7)  # max(box 0.5, plane 0.7)
    assert resolve_ground(robot, "file") == Ground(0.1, (0.0, 0.0, 1.0), 0.7)


def test_capsule_legs_are_two_spheres_at_their_ends_said_in_one_line():
    robot = robodyn.load(DATA / "contact_legs.xml")
    found = collision_points(robot)
    ends = {(tuple(np.round(point.position, 9)), point.radius) for point in found.points if ".capsule" in point.name}
    expected = {
        ((0.18, 0.08, 0.0), 0.02), ((0.22, 0.12, -0.2), 0.02), ((0.18, -0.08, 0.0), 0.02), ((0.22, -0.12, -0.2), 0.02),
        ((-0.2, 0.1, 0.0), 0.025), ((-0.2, 0.1, -0.2), 0.025), ((-0.2, -0.1, 0.0), 0.025), ((-0.2, -0.1, -0.2), 0.025),
    }  # fmt: skip
    assert ends == expected
    assert [line for line in found.skipped if "capsules × 4" in line and "approximated" in line]


def test_a_geom_with_contype_and_conaffinity_zero_gives_no_contact_point(tmp_path):
    """The ghost sphere (class 'ghost': 0 and 0) hangs below the legs; with its class
    removed it is a contact point (the negative control)."""
    robot = robodyn.load(DATA / "contact_legs.xml")
    assert not [point for point in collision_points(robot).points if point.radius == 0.03]
    text = (DATA / "contact_legs.xml").read_text().replace('class="ghost" ', "")
    (tmp_path / "control.xml").write_text(text)
    control = robodyn.load(tmp_path / "control.xml")
    assert [point for point in collision_points(control).points if point.radius == 0.03]


@pytest.mark.parametrize(
    ("geom", "plane", "collides"),
    [
        ('contype="2" conaffinity="0"', "", False),  # (2 & 1) | (1 & 0)
        ('contype="1" conaffinity="0"', "", True),
        ('contype="0" conaffinity="1"', "", True),
        ('contype="2" conaffinity="0"', 'conaffinity="2"', True),
        ('contype="1" conaffinity="1"', 'contype="2" conaffinity="2"', False),
    ],
)
def test_collision_follows_mujocos_contype_conaffinity_rule(tmp_path, geom, plane, collides):
    robot = _load(tmp_path, f'<geom type="sphere" size="0.1" {geom}/>', f'<geom type="plane" size="1 1 0.1" {plane}/>')
    assert bool(collision_points(robot).points) == collides


def test_default_classes_set_contype(tmp_path):
    path = tmp_path / "robot.xml"
    path.write_text(
        '<mujoco><default><geom contype="0" conaffinity="0"/><default class="on"><geom contype="1"/></default></default>'
        '<worldbody><geom type="plane" size="1 1 .1" conaffinity="1"/><body><freejoint/>'
        '<geom type="sphere" size="0.1"/><geom class="on" type="sphere" size="0.2"/></body></worldbody></mujoco>'
    )
    assert [point.radius for point in collision_points(robodyn.load(path)).points] == [0.2]


def test_a_tilted_plane_gives_its_normal_and_the_height_where_it_meets_z(tmp_path):
    robot = _load(
        tmp_path, '<geom type="sphere" size="0.1"/>', '<geom type="plane" size="1 1 .1" pos="1 0 0.2" zaxis="0.1 0 1"/>'
    )
    height, normal, friction = robot.source.ground
    assert math.isclose(height, 0.3, rel_tol=1e-12)  # n·p / n_z = (0.1 · 1 + 0.2) / 1
    assert np.allclose(normal, np.array([0.1, 0.0, 1.0]) / math.hypot(0.1, 1.0)) and friction == 1.0


def test_frictionless_pairs_and_differing_friction_are_said(tmp_path):
    robot = _load(tmp_path, '<geom type="sphere" size="0.1" condim="1"/>', '<geom type="plane" size="1 1 .1" condim="1"/>')
    assert robot.source.ground[2] == 0.0
    with pytest.warns(RobodynWarning, match="friction differs"):
        _load(tmp_path, '<geom type="sphere" size="0.1" friction="2"/><geom type="box" size=".1 .1 .1"/>')
    with pytest.warns(RobodynWarning, match="torsional and rolling friction"):
        _load(tmp_path, '<geom type="sphere" size="0.1" condim="6"/>')
    with pytest.raises(URDFError, match="contype"):
        _load(tmp_path, '<geom type="sphere" size="0.1" contype="-1"/>')


def test_cylinders_ellipsoids_and_meshes_are_reported_not_modelled(tmp_path):
    robot = _load(
        tmp_path, '<geom type="sphere" size="0.1"/><geom type="cylinder" size=".1 .2"/><geom type="ellipsoid" size=".1 .2 .3"/>'
    )
    skipped = " ".join(collision_points(robot).skipped)
    assert "cylinder × 1" in skipped and "ellipsoid × 1" in skipped


def test_without_a_plane_the_file_ground_is_refused(tmp_path):
    robot = _load(tmp_path, '<geom type="sphere" size="0.1"/>', "")
    assert robot.source.ground is None and collision_points(robot).points
    with pytest.raises(InputError, match="no ground plane"):
        resolve_ground(robot, "file")
    with pytest.raises(InputError, match="ground"):
        resolve_ground(robot, "floor")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert resolve_ground(robot, None) is None


def test_the_collision_urdf_is_read_by_the_reference_and_a_strict_load(tmp_path):
    """Capsules and ellipsoids are written so that other URDF readers (the reference's
    yourdfpy) take the file; a sphere's collision radius is its first size number."""
    body = '<geom type="capsule" size=".05 .1"/><geom type="ellipsoid" size=".1 .2 .3"/><geom type="sphere" size=".1 .7"/>'
    robot = _load(tmp_path, body, strict=True)
    assert "n=6" in repr(load_reference(tmp_path / "robot.xml", floating_base=True))  # one free body
    assert sorted(point.radius for point in collision_points(robot).points) == [0.05, 0.05, 0.1]
