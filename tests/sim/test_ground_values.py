"""Issue 39, the ground and its contact points as values (mutmut's survivors in
``robodyn/sim/ground.py``, through its public functions): each refusal's whole sentence,
numbers stored as Python floats, the contact axes a right-handed orthonormal frame whose
third row is the normal (also for a normal near x), the signed gap of a raised tilted
plane, and the contact points of every collision shape against positions computed here
with SciPy's rotations (a sphere's centre, a box's eight corners, an MJCF capsule's two
end spheres), with the one-line notes of what is not modelled."""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import robodyn
from robodyn.exceptions import FrameError, InputError, StaticFrameError
from robodyn.sim.ground import ContactPoint, Ground, collision_points, contact_points, resolve_ground

DATA_MJCF = Path(__file__).resolve().parent.parent / "data" / "mjcf"


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        ({"height": math.inf}, "height must be a finite height in [m], got inf."),
        ({"friction": -0.1}, "friction must be a finite coefficient μ ≥ 0, got -0.1."),
        ({"friction": math.nan}, "friction must be a finite coefficient μ ≥ 0, got nan."),
        ({"friction": True}, "friction must be a finite coefficient μ ≥ 0, got True."),
        ({"friction": "0.5"}, "friction must be a finite coefficient μ ≥ 0, got '0.5'."),
        ({"normal": (0, 0, 0)}, "normal must be a non-zero finite 3-vector, got (0, 0, 0)."),
        ({"normal": (0, 0, 1e-10)}, "normal must be a non-zero finite 3-vector, got (0, 0, 1e-10)."),
        ({"normal": (1, 2)}, "normal must be a non-zero finite 3-vector, got (1, 2)."),
        ({"normal": (0, math.nan, 1)}, "normal must be a non-zero finite 3-vector, got (0, nan, 1)."),
    ],
)
def test_a_ground_with_impossible_numbers_is_refused_in_one_sentence(arguments, message):
    with pytest.raises(InputError) as error:
        Ground(**arguments)
    assert str(error.value) == message


def test_a_grounds_numbers_are_floats_its_normal_a_unit_vector_and_its_axes_a_right_handed_frame():
    ground = Ground(1, (0, 0, 2), 1)
    assert (ground.height, ground.normal, ground.friction) == (1.0, (0.0, 0.0, 1.0), 1.0)
    assert all(type(x) is float for x in (ground.height, ground.friction, *ground.normal))
    assert Ground(normal=(1e-8, 0, 0)).normal == (1.0, 0.0, 0.0)  # small but above 1e-9: normalised
    for normal in [(0.0, 0.0, 1.0), (1.0, 0.0, 0.0), (0.95, 0.1, 0.3), (-0.89, 0.2, 0.4), (0.3, -0.5, 0.8)]:
        axes = Ground(normal=normal).frame()
        np.testing.assert_allclose(axes @ axes.T, np.eye(3), atol=1e-15)
        np.testing.assert_allclose(axes[2], np.array(normal) / np.linalg.norm(normal), atol=1e-15)
        np.testing.assert_allclose(np.cross(axes[0], axes[1]), axes[2], atol=1e-15)
    flat = Ground().frame()
    np.testing.assert_allclose(flat, np.eye(3), atol=1e-15)  # flat: the world's axes
    flat[0, 0] = 5.0  # a copy: the ground keeps its axes
    assert Ground().frame()[0, 0] == 1.0


def test_a_tilted_raised_plane_gives_the_signed_distance_of_points():
    ground = Ground.tilted(0.3, friction=0.2, height=0.1)
    assert (ground.height, ground.friction) == (0.1, 0.2)
    np.testing.assert_array_equal(ground.point, [0.0, 0.0, 0.1])
    normal = np.array([math.sin(0.3), 0.0, math.cos(0.3)])
    assert ground.normal == pytest.approx(tuple(normal), abs=1e-15)
    points = np.array([[0.0, 0.0, 0.1], [1.0, 2.0, 3.0], [-2.0, 0.5, -1.0]])
    np.testing.assert_allclose(ground.gap(points), (points - [0.0, 0.0, 0.1]) @ normal, atol=1e-15)
    assert ground.gap(np.array([0.0, 0.0, 0.1]) - 0.25 * normal) == pytest.approx(-0.25, abs=1e-15)  # below: negative


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        ({"name": ""}, "name must be a non-empty name, got ''."),
        ({"link": 3}, "link must be a non-empty name, got 3."),
        ({"position": (1, 2)}, "position must be 3 finite coordinates in [m], got (1, 2)."),
        ({"position": (0, math.inf, 0)}, "position must be 3 finite coordinates in [m], got (0, inf, 0)."),
        ({"position": list(range(40))}, f"position must be 3 finite coordinates in [m], got {repr(list(range(40)))[:80]}."),
        ({"radius": -0.01}, "radius must be a finite radius ≥ 0 in [m], got -0.01."),
        ({"radius": True}, "radius must be a finite radius ≥ 0 in [m], got True."),
        ({"radius": math.inf}, "radius must be a finite radius ≥ 0 in [m], got inf."),
    ],
)
def test_an_impossible_contact_point_is_refused_in_one_sentence(arguments, message):
    with pytest.raises(InputError) as error:
        ContactPoint(**({"name": "heel", "link": "foot"} | arguments))
    assert str(error.value) == message


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda: Ground(normal=("0", "0", "1")), "normal must be a non-zero finite 3-vector, got ('0', '0', '1')."),
        (lambda: Ground(normal="001"), "normal must be a non-zero finite 3-vector, got '001'."),
        (lambda: Ground(normal=(True, False, True)), "normal must be a non-zero finite 3-vector, got (True, False, True)."),
        (
            lambda: Ground(normal=np.array([0.0, 0.0, 1.0]) > 0.5),
            "normal must be a non-zero finite 3-vector, got array([False, False,  True]).",
        ),
        (lambda: Ground(height="1"), "height must be a finite height in [m], got '1'."),
        (lambda: Ground(height=True), "height must be a finite height in [m], got True."),
        (
            lambda: ContactPoint("heel", "foot", ("1", "2", "3")),
            "position must be 3 finite coordinates in [m], got ('1', '2', '3').",
        ),
        (lambda: ContactPoint("heel", "foot", "123"), "position must be 3 finite coordinates in [m], got '123'."),
        (
            lambda: ContactPoint("heel", "foot", ((0, 1), 2, 3)),
            "position must be 3 finite coordinates in [m], got ((0, 1), 2, 3).",
        ),
        (lambda: ContactPoint("heel", "foot", (1j, 2, 3)), "position must be 3 finite coordinates in [m], got (1j, 2, 3)."),
    ],
)
def test_text_and_booleans_are_not_a_grounds_or_a_contact_points_numbers(make, message):
    """As the constraint values refuse them: ``("1", "2", "3")`` is not ``(1, 2, 3)``, ``"123"`` not three digits."""
    with pytest.raises(InputError) as error:
        make()
    assert str(error.value) == message


def test_numpy_numbers_are_a_grounds_and_a_contact_points_numbers():
    ground = Ground(height=np.float32(0.5), normal=np.array([0, 0, 2]))
    assert (ground.height, ground.normal) == (0.5, (0.0, 0.0, 1.0)) and type(ground.height) is float
    assert ContactPoint("heel", "foot", [1, 2.5, np.int64(3)]).position == (1.0, 2.5, 3.0)


def test_a_contact_points_numbers_are_floats():
    point = ContactPoint("heel", "foot", np.array([1, 2, 3]), 0)
    assert point == ContactPoint("heel", "foot", (1.0, 2.0, 3.0), 0.0)
    assert type(point.radius) is float and all(type(x) is float for x in point.position)


INERTIA = '<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'
SHAPES = f"""<robot name="shapes">
  <link name="base"/>
  <link name="body">{INERTIA}
    <collision><origin xyz="0.1 0.2 0.3" rpy="0.3 0.2 0.1"/><geometry><sphere radius="0.05"/></geometry></collision>
    <collision><origin xyz="0 0 0.5" rpy="0.1 -0.2 0.5"/><geometry><box size="0.2 0.4 0.6"/></geometry></collision>
    <collision name="mjcf:capsule"><origin xyz="0.1 0 0" rpy="0.5 0.2 0"/><geometry><cylinder radius="0.03" length="0.4"/></geometry></collision>
    <collision><geometry><cylinder radius="0.03" length="0.4"/></geometry></collision>
    <collision><origin xyz="1 1 1"/></collision>
    <collision><geometry><sphere radius="0.02"/></geometry></collision>
  </link>
  {"".join(f'<link name="l{i}">{INERTIA}<collision><geometry><cylinder radius="0.1" length="0.1"/></geometry></collision></link>' for i in range(4))}
  <joint name="hinge" type="revolute"><parent link="base"/><child link="body"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  {"".join(f'<joint name="j{i}" type="fixed"><parent link="body"/><child link="l{i}"/></joint>' for i in range(4))}
</robot>"""


def test_every_collision_shape_gives_its_points_where_they_are_and_what_is_not_modelled_is_said():
    found = collision_points(robodyn.load(SHAPES))
    points = {point.name: point for point in found.points}

    def where(xyz, rpy, local=(0.0, 0.0, 0.0)) -> np.ndarray:
        return np.array(xyz) + Rotation.from_euler("xyz", rpy).apply(local)

    assert list(points) == [
        "body.sphere0",
        *(f"body.box1.corner{j}" for j in range(8)),
        "body.capsule2.end0",
        "body.capsule2.end1",
        "body.sphere5",
    ]
    assert points["body.sphere0"].position == pytest.approx((0.1, 0.2, 0.3)) and points["body.sphere0"].radius == 0.05
    for j, signs in enumerate(itertools.product((-1.0, 1.0), repeat=3)):
        corner = points[f"body.box1.corner{j}"]
        np.testing.assert_allclose(
            corner.position, where((0, 0, 0.5), (0.1, -0.2, 0.5), 0.5 * np.array([0.2, 0.4, 0.6]) * signs), atol=1e-15
        )
        assert corner.radius == 0.0 and corner.link == "body"
    for end, sign in enumerate((-1.0, 1.0)):
        cap = points[f"body.capsule2.end{end}"]
        np.testing.assert_allclose(cap.position, where((0.1, 0, 0), (0.5, 0.2, 0), (0, 0, sign * 0.2)), atol=1e-15)
        assert cap.radius == 0.03
    assert points["body.sphere5"].position == (0.0, 0.0, 0.0) and points["body.sphere5"].radius == 0.02
    assert found.skipped == (
        "collision geometry not modelled as contacts (spheres, boxes and capsules are): cylinder × 5 ('body', 'l0', 'l1', …)",
        "collision geometry not modelled as contacts (spheres, boxes and capsules are): no geometry × 1 ('body')",
        "capsules × 1: approximated by the spheres at their two ends (their sides do not touch)",
    )


def test_a_malformed_collision_size_is_refused_naming_the_geometry():
    bad = SHAPES.replace('size="0.2 0.4 0.6"', 'size="0.2 0.4"')
    with pytest.raises(InputError) as error:
        collision_points(robodyn.load(bad, check_inertia=False))
    assert str(error.value) == "collision geometry must be 3 finite numbers, got '0.2 0.4'."


def test_the_ground_a_run_stands_on_is_given_or_the_files_or_refused():
    robot = robodyn.load(SHAPES)
    ground = Ground(friction=0.3)
    assert resolve_ground(robot, ground) is ground and resolve_ground(robot, None) is None
    with pytest.raises(InputError) as error:
        resolve_ground(robot, "file")
    assert str(error.value) == 'ground must be a Ground: the robot\'s file states no ground plane, got "file".'
    with pytest.raises(InputError) as error:
        resolve_ground(robot, "floor" * 30)
    assert (
        str(error.value)
        == f'ground must be a Ground, "file" (the plane the robot\'s file states) or None, got {repr("floor" * 30)[:80]}.'
    )


def test_named_contacts_are_frames_in_order_and_a_name_twice_or_none_is_refused():
    robot = robodyn.load(SHAPES)
    assert contact_points(robot, "l2").names == ["l2"]  # one name
    found = contact_points(robot, ["l3", ContactPoint("tip", "body", (0.1, 0, 0), 0.01)])
    assert found.names == ["l3", "tip"] and found.points[1].radius == 0.01 and found.skipped == ()
    with pytest.raises(InputError) as error:
        contact_points(robot, ["l3", "l1", "l3", "l1"])
    assert str(error.value) == "contacts must be contact points with distinct names, got 'l1' twice."
    with pytest.raises(InputError) as error:
        contact_points(robot, [])
    assert str(error.value) == "contacts must be at least one contact point: name the frames that touch the ground, got none."


def test_a_frictionless_ground_and_the_tilted_planes_default_friction():
    assert Ground(friction=0).friction == 0.0
    assert Ground.tilted(0.2).friction == 1.0 and Ground.tilted(0.2).height == 0.0


class _Text:
    """A stand-in robot for :func:`collision_points`, which reads only the URDF text."""

    def __init__(self, links: str) -> None:
        self.urdf = f'<robot name="stub">{links}</robot>'


def test_shapes_without_sizes_are_points_and_an_origin_without_rpy_is_unrotated():
    found = collision_points(
        _Text(
            '<link name="a"><collision><origin xyz="0.1 0.2 0.3"/><geometry><box size="0.2 0.4 0.6"/></geometry></collision>'
            '<collision><origin xyz="0 0 1"/><geometry><sphere/></geometry></collision>'
            '<collision name="mjcf:capsule"><origin xyz="0 1 0"/><geometry><cylinder radius="0.1"/></geometry></collision>'
            '<collision name="mjcf:capsule"><geometry><cylinder length="0.4"/></geometry></collision>'
            "<collision><geometry><box/></geometry></collision></link>"
        )
    )
    points = {point.name: point for point in found.points}
    for j, signs in enumerate(itertools.product((-1.0, 1.0), repeat=3)):  # no rpy: the box's own axes
        assert points[f"a.box0.corner{j}"].position == pytest.approx(
            tuple(np.array([0.1, 0.2, 0.3]) + 0.5 * np.array([0.2, 0.4, 0.6]) * signs)
        )
    assert (points["a.sphere1"].position, points["a.sphere1"].radius) == ((0.0, 0.0, 1.0), 0.0)
    assert [points[f"a.capsule2.end{end}"].position for end in (0, 1)] == [
        (0.0, 1.0, 0.0)
    ] * 2  # no length: both ends at its centre
    assert points["a.capsule3.end0"].radius == 0.0 and points["a.capsule3.end1"].position == (0.0, 0.0, 0.2)
    assert {points[f"a.box4.corner{j}"].position for j in range(8)} == {(0.0, 0.0, 0.0)}


@pytest.mark.parametrize(("count", "shown"), [(3, "('l0', 'l1', 'l2')"), (4, "('l0', 'l1', 'l2', …)")])
def test_a_note_names_three_links_then_an_ellipsis(count, shown):
    links = "".join(
        f'<link name="l{i}"><collision><geometry><cylinder radius="1" length="1"/></geometry></collision></link>'
        for i in range(count)
    )
    assert collision_points(_Text(links)).skipped == (
        f"collision geometry not modelled as contacts (spheres, boxes and capsules are): cylinder × {count} {shown}",
    )


def test_an_mjcf_geom_with_no_urdf_shape_is_said_by_its_type():
    found = collision_points(robodyn.load(DATA_MJCF / "geoms.xml"))
    assert found.skipped == (
        "collision geometry not modelled as contacts (spheres, boxes and capsules are): cylinder × 1 ('lower')",
        "collision geometry not modelled as contacts (spheres, boxes and capsules are): ellipsoid × 1 ('hand')",
        "capsules × 2: approximated by the spheres at their two ends (their sides do not touch)",
    )


def test_the_links_named_foot_that_a_joint_moves_are_the_contacts_without_spheres_or_boxes():
    urdf = f"""<robot name="leg">
      <link name="base"/><link name="base_foot"/><link name="leg">{INERTIA}</link><link name="foot"/>
      <joint name="weld" type="fixed"><parent link="base"/><child link="base_foot"/></joint>
      <joint name="hip" type="revolute"><parent link="base"/><child link="leg"/><axis xyz="0 1 0"/>
        <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
      <joint name="ankle" type="fixed"><parent link="leg"/><child link="foot"/><origin xyz="0 0 -0.5"/></joint>
    </robot>"""
    found = contact_points(robodyn.load(urdf), "collision")
    assert found.names == ["foot"]  # moved by the first joint; the world's base_foot is not
    assert found.skipped == ("contacts: the links named *foot (1), the collision geometry has no sphere or box",)


def test_the_ground_a_file_states_is_its_plane():
    robot = robodyn.load(DATA_MJCF / "contact_box.xml")  # <geom type="plane" pos="0 0 0.1" friction="0.7"/>
    ground = resolve_ground(robot, "file")
    assert (ground.height, ground.normal, ground.friction) == (0.1, (0.0, 0.0, 1.0), 0.7)


def test_an_unknown_or_world_fixed_contact_frame_is_refused_in_one_sentence():
    robot = robodyn.load("solo12")
    close = [name for name in robot.frame_ids if "l" in name.lower()][:5]
    assert len([name for name in robot.frame_ids if "l" in name.lower()]) > 5
    with pytest.raises(FrameError) as error:
        contact_points(robot, ["L"])
    assert str(error.value) == f"robot 'solo12' has no frame named 'L' (did you mean {', '.join(repr(name) for name in close)}?)."
    with pytest.raises(StaticFrameError) as static:
        contact_points(robodyn.load(SHAPES), ["base"])
    assert str(static.value).startswith(
        "robot 'shapes': frame 'base' is fixed to the world (no joint moves it), so a contact point on it would have no effect"
    )
    with pytest.raises(InputError) as named:
        ContactPoint(b"x" * 100, "foot")
    assert str(named.value) == f"name must be a non-empty name, got {repr(b'x' * 100)[:80]}."
