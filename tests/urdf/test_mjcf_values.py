"""MJCF values as MuJoCo validates them: each value MuJoCo refuses is refused by robodyn in
one sentence (never a traceback, never a different robot), checked against MuJoCo itself."""

from __future__ import annotations

import time

import pytest

import robodyn
from robodyn.dynamics.options import MAX_DOF
from robodyn.exceptions import URDFError
from robodyn.urdf.mjcf_state import DEFAULT_MAX_DOF

mujoco = pytest.importorskip("mujoco")

TEMPLATE = """<mujoco><compiler angle="radian" {compiler}/>{defaults}<worldbody>
<body name="b" {body}><joint name="j" {joint}/>{inside}</body></worldbody></mujoco>"""
SPHERE = '<geom type="sphere" size="0.1"/>'


def document(**parts: str) -> str:
    values = {"compiler": "", "defaults": "", "body": "", "joint": "", "inside": SPHERE} | parts
    return TEMPLATE.format(**values)


#: (what, the document's parts, words robodyn's sentence has). MuJoCo 4 refuses each.
REFUSED = [
    ("gravcomp not a number", {"body": 'gravcomp="abc"'}, "gravcomp"),
    ("negative density", {"inside": SPHERE + '<geom type="sphere" size="0.1" density="-1000"/>'}, "density='-1000' is negative"),
    ("negative geom mass", {"inside": SPHERE + '<geom type="box" size="0.1 0.1 0.1" mass="-1"/>'}, "mass='-1' is negative"),
    ("negative size", {"inside": '<geom type="sphere" size="-0.1"/>'}, "must be positive"),
    ("zero size", {"inside": '<geom type="capsule" size="0.1 0"/>'}, "must be positive"),
    ("zero radius of a fromto capsule", {"inside": '<geom type="capsule" fromto="0 0 0 0 0 1" size="0"/>'}, "must be positive"),
    ("limited True", {"joint": 'limited="True" range="0 1"'}, "limited='True'"),
    ("limited 1", {"joint": 'limited="1" range="0 1"'}, "limited='1'"),
    ("inertiafromgeom True", {"compiler": 'inertiafromgeom="True"'}, "inertiafromgeom='True'"),
    ("autolimits True", {"compiler": 'autolimits="True"'}, "autolimits='True'"),
    ("joint type Hinge", {"joint": 'type="Hinge"'}, "type='Hinge'"),
    ("geom type Box", {"inside": '<geom type="Box" size="0.1 0.1 0.1"/>'}, "type='Box'"),
    (
        "a class defined twice",
        {
            "defaults": '<default><default class="a"><joint damping="1"/></default><default class="a"><joint damping="2"/></default></default>'
        },
        "defined twice",
    ),
    ("an unnamed nested default", {"defaults": '<default><default><joint damping="1"/></default></default>'}, "no class name"),
    ("an empty class name", {"defaults": '<default><default class=""><joint damping="1"/></default></default>'}, "no class name"),
    (
        "main nested again",
        {"defaults": '<default><default class="main"><joint damping="1"/></default></default>'},
        "defined twice",
    ),
    ("the top class renamed", {"defaults": '<default class="x"><joint damping="1"/></default>'}, "cannot be renamed"),
    ("a moving body without mass", {"inside": ""}, "has no mass"),
    ("a zero density only", {"inside": '<geom type="sphere" size="0.1" density="0"/>'}, "has no mass"),
    ("an inertial of negative mass", {"inside": '<inertial pos="0 0 0" mass="-1" diaginertia="1 1 1"/>'}, "negative"),
    ("an inertial of negative inertia", {"inside": '<inertial pos="0 0 0" mass="1" diaginertia="-1 1 1"/>'}, "negative"),
    ("a position with junk", {"body": 'pos="1 2 3abc"'}, "not a finite number"),
    ("a position of two numbers", {"body": 'pos="1 2"'}, "must be 3 numbers"),
]


@pytest.mark.parametrize(("what", "parts", "words"), REFUSED, ids=[case[0] for case in REFUSED])
def test_a_value_mujoco_refuses_is_refused_in_one_sentence(what, parts, words):
    text = document(**parts)
    with pytest.raises(ValueError):
        mujoco.MjModel.from_xml_string(text)  # the negative control: MuJoCo refuses it too
    with pytest.raises(URDFError) as raised:
        robodyn.load(text)
    message = str(raised.value)
    assert words in message and "\n" not in message


def test_the_same_documents_with_mujocos_spelling_load_in_both():
    for parts in ({"joint": 'limited="true" range="0 1"'}, {"compiler": 'inertiafromgeom="true"'}, {"body": 'gravcomp="0"'}):
        text = document(**parts)
        mujoco.MjModel.from_xml_string(text)
        robodyn.load(text)


def test_limited_true_gives_the_limit_mujoco_gives():
    robot = robodyn.load(document(joint='limited="true" range="-0.5 1"'))
    assert (robot.dofs[0].lower, robot.dofs[0].upper) == (-0.5, 1.0)


def test_a_sphere_whose_mass_overflows_is_one_sentence():
    text = document(inside='<geom type="sphere" size="1e200"/>')
    assert mujoco.MjModel.from_xml_string(text).body_mass[1] == float("inf")  # MuJoCo loads an infinite mass
    with pytest.raises(URDFError, match="overflows") as raised:
        robodyn.load(text)
    assert "\n" not in str(raised.value)


def test_two_top_defaults_add_to_main_as_in_mujoco():
    defaults = '<default><joint armature="0.5"/></default><default><joint damping="2"/></default>'
    text = document(defaults=defaults)
    model = mujoco.MjModel.from_xml_string(text)
    robot = robodyn.load(text)
    assert (robot.dofs[0].damping, robot.dofs[0].armature) == (model.dof_damping[0], model.dof_armature[0])


def test_a_site_named_as_a_body_is_not_a_repeated_name_but_a_welded_body_without_mass_is_fine():
    text = document(inside=SPHERE + '<body name="c" pos="0 0 1"/>')
    mujoco.MjModel.from_xml_string(text)
    assert robodyn.load(text).nv == 1


def test_the_readers_default_cap_is_robodyns():
    assert DEFAULT_MAX_DOF == MAX_DOF


def test_a_file_of_600000_bodies_is_refused_in_under_a_second():
    body = '<body name="b{}" pos="0 0 0.1"><joint type="hinge"/><geom size="0.01 0.02"/></body>\n'
    text = (
        "<mujoco><worldbody><body name='top'>" + "".join(body.format(i) for i in range(600_000)) + "</body></worldbody></mujoco>"
    )
    assert len(text) > 50e6
    start = time.perf_counter()
    with pytest.raises(URDFError, match="more than 300 degrees of freedom"):
        robodyn.load(text, max_bytes=100_000_000)
    assert time.perf_counter() - start < 1.0


def test_welded_bodies_are_capped_too_and_max_dof_moves_the_cap():
    text = "<mujoco><worldbody>" + '<body><geom size="0.1"/></body>' * 201 + "</worldbody></mujoco>"
    with pytest.raises(URDFError, match="more than 200 bodies"):
        robodyn.load(text, max_dof=10)


def test_joints_in_defaults_and_equalities_are_not_counted():
    defaults = "<default>" + '<default class="c{}"><joint damping="1"/></default>' * 20 + "</default>"
    text = document(defaults=defaults.format(*range(20)))
    assert robodyn.load(text, max_dof=1).nv == 1
