"""Family 2 of issue #14: one number parser. Whatever the validator accepts, Pinocchio's
model holds exactly the validator's numbers; what it refuses names the attribute."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import robodyn
from robodyn.urdf.edit import rpy_matrix
from robodyn.urdf.validation import parse_number, parse_urdf

FINITE = st.floats(min_value=-50, max_value=50, allow_nan=False, allow_infinity=False)
POSITIVE = st.floats(min_value=0.01, max_value=20, allow_nan=False, allow_infinity=False)


@st.composite
def spelling(draw, value: float) -> str:
    """One of the accepted spellings of ``value`` (each parses back to the same float)."""
    forms = [repr(value), f"{value:.17e}", f"{value:.17E}", f" {value!r} ", f"\t{value!r}\n"]
    if math.copysign(1.0, value) > 0:
        forms.append("+" + repr(value))
    return draw(st.sampled_from(forms))


def _entity(text: str) -> str:
    return text.replace("\t", "&#9;").replace("\n", "&#10;")


@st.composite
def urdfs(draw):
    """A random tree of 1-5 moving joints with numbers spelled in every accepted way."""
    count = draw(st.integers(1, 5))
    parts, truth = ['<robot name="r">', '<link name="l0"/>'], []

    def spell(value: float) -> str:
        return _entity(draw(spelling(value)))

    for i in range(1, count + 1):
        parent = draw(st.integers(0, i - 1))
        kind = draw(st.sampled_from(["revolute", "prismatic", "continuous"]))
        xyz = [draw(FINITE) for _ in range(3)]
        rpy = [draw(st.floats(-3, 3)) for _ in range(3)]
        com = [draw(FINITE) / 10 for _ in range(3)]
        com_rpy = [draw(st.floats(-3, 3)) for _ in range(3)]
        mass = draw(POSITIVE)
        moments = sorted(draw(POSITIVE) for _ in range(3))
        moments[2] = min(moments[2], moments[0] + moments[1])  # a rigid body's moments
        limit = (
            ""
            if kind == "continuous"
            else f'<limit lower="{spell(-1.5)}" upper="{spell(1.25)}" effort="{spell(10.0)}" velocity="1"/>'
        )
        parts.append(
            f'<joint name="j{i}" type="{kind}"><parent link="l{parent}"/><child link="l{i}"/>'
            f'<origin xyz="{" ".join(spell(v) for v in xyz)}" rpy="{" ".join(spell(v) for v in rpy)}"/>'
            f'<axis xyz="0 0 1"/>{limit}</joint>'
            f'<link name="l{i}"><inertial><origin xyz="{" ".join(spell(v) for v in com)}" '
            f'rpy="{" ".join(spell(v) for v in com_rpy)}"/><mass value="{spell(mass)}"/>'
            f'<inertia ixx="{spell(moments[0])}" ixy="0" ixz="0" iyy="{spell(moments[1])}" iyz="0" izz="{spell(moments[2])}"/>'
            "</inertial></link>"
        )
        truth.append((f"j{i}", xyz, rpy, com, com_rpy, mass, moments))
    welded = draw(st.integers(0, 2))  # links welded on by fixed joints: Pinocchio merges them
    for k in range(welded):
        mass = draw(POSITIVE)
        xyz = [draw(FINITE) / 10 for _ in range(3)]
        parts.append(
            f'<joint name="w{k}" type="fixed"><parent link="l{draw(st.integers(0, count))}"/><child link="w{k}"/>'
            f'<origin xyz="{" ".join(spell(v) for v in xyz)}"/></joint>'
            f'<link name="w{k}"><inertial><mass value="{spell(mass)}"/>'
            f'<inertia ixx="{spell(0.5)}" ixy="0" ixz="0" iyy="{spell(0.5)}" iyz="0" izz="{spell(0.5)}"/></inertial></link>'
        )
    parts.append("</robot>")
    return "".join(parts), truth


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(urdfs())
def test_pinocchio_holds_exactly_the_validators_numbers(case):
    text, truth = case
    spec = parse_urdf(text)
    robot = robodyn.load(text)
    model = robot.model
    welded_to = {joint.parent for joint in spec.joints.values() if joint.type == "fixed"}
    total = sum(inertial.mass for inertial in spec.links.values() if inertial is not None)
    assert sum(body.mass for body in model.inertias) == pytest.approx(total, rel=1e-14)
    for frame in model.frames:  # fixed joints: their origins as written
        if frame.name in spec.joints and spec.joints[frame.name].type == "fixed":
            assert list(frame.placement.translation) == pytest.approx(list(spec.joints[frame.name].origin_xyz), abs=1e-14)
    for name, xyz, rpy, com, _com_rpy, mass, moments in truth:
        joint = spec.joints[name]
        inertial = spec.links[joint.child]
        # the validator read the numbers as written, whatever the spelling
        assert list(joint.origin_xyz) == xyz and list(joint.origin_rpy) == rpy
        assert inertial.mass == mass and list(inertial.origin_xyz) == com
        assert list(np.diag(inertial.inertia)) == moments
        # and Pinocchio holds those numbers
        index = model.getJointId(name)
        placement = model.jointPlacements[index]
        assert list(placement.translation) == list(joint.origin_xyz)
        np.testing.assert_allclose(placement.rotation, rpy_matrix(joint.origin_rpy), atol=1e-14)
        if joint.child in welded_to:  # its body also holds the welded links (checked by the total)
            continue
        body = model.inertias[index]
        assert body.mass == inertial.mass
        # (Pinocchio composes the inertia's frame: rounding only, no other reading of the text)
        np.testing.assert_allclose(body.lever, inertial.origin_xyz, rtol=1e-13, atol=1e-15)
        rotation = rpy_matrix(inertial.origin_rpy)
        np.testing.assert_allclose(body.inertia, rotation @ inertial.inertia @ rotation.T, rtol=1e-12, atol=1e-14)
        if joint.type != "continuous":
            assert (joint.lower, joint.upper) == (-1.5, 1.25)


GRAMMAR_ACCEPTS = ["1", "-1", "+1", "1.", ".5", "1e3", "1E-3", "-.5e+2", " 2 ", "\t2\n", "inf", "-Infinity"]
GRAMMAR_REFUSES = ["", " ", "1_000", "\uff12", "\u0662", "0x10", "1,5", "\u00a01", "1e", "e3", "--1", "1.2.3", "1 2", "½", "١٢"]


@pytest.mark.parametrize("text", GRAMMAR_ACCEPTS)
def test_the_grammar_accepts_what_c_and_python_read_alike(text):
    assert parse_number(text) == float(text.strip())


@pytest.mark.parametrize("text", GRAMMAR_REFUSES)
def test_the_grammar_refuses_what_parsers_read_differently(text):
    assert parse_number(text) is None


def test_nan_parses_for_the_caller_to_refuse():
    assert math.isnan(parse_number(" NaN "))


@settings(max_examples=60, deadline=None)
@given(st.text(min_size=1, max_size=8))
def test_anything_accepted_is_exactly_pythons_float_of_the_stripped_text(text):
    value = parse_number(text)
    if value is not None:
        assert value == float(text.strip(" \t\n\r")) or math.isnan(value)
        assert text.strip(" \t\n\r").isascii()


@pytest.mark.parametrize(
    ("attribute", "old", "new"),
    [
        ("value", '<mass value="1.0"/>', '<mass value="1_0"/>'),
        ("ixx", 'ixx="0.00041666666666666675"', 'ixx="\uff10"'),
        ("xyz", '<origin xyz="0.5 0 0" rpy="0 0 0"/>\n    <axis', '<origin xyz="0x1 0 0" rpy="0 0 0"/>\n    <axis'),
        ("upper", 'upper="0.3"', 'upper="0,3"'),
    ],
)
def test_a_refused_spelling_names_the_attribute(attribute, old, new):
    text = robodyn.rp_arm_urdf().replace(old, new, 1)
    with pytest.raises(robodyn.URDFError, match=f"{attribute}="):
        robodyn.load(text)


def test_negative_control_pinocchio_alone_misreads_the_text():
    """What the normalised copy prevents: Pinocchio on the raw text loses a moment."""
    import pinocchio as pin

    from tests.conftest import ROOT

    path = ROOT / "tests" / "data" / "hostile" / "inertia_trailing_space.urdf"
    raw = pin.buildModelFromXML(path.read_text())
    robot = robodyn.load(path)
    index = robot.model.getJointId("joint2")
    assert raw.inertias[index].inertia[1, 1] == 0.0  # 'iyy="0.0135... "' read as 0
    assert robot.model.inertias[index].inertia[1, 1] == pytest.approx(0.013541666666666669, rel=1e-12)
