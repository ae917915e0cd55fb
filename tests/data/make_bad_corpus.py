"""Write the corpus of bad URDFs (tests/data/bad/*.urdf) and the error each must produce.

Run from the repository root: ``python tests/data/make_bad_corpus.py``. Each case is the
valid RP arm (or a small document) broken in one way; ``expected.json`` maps each file to
a fragment of the robodyn error message it must produce.
"""

from __future__ import annotations

import json
from pathlib import Path

from robodyn.urdf.models import rp_arm_urdf

FOLDER = Path(__file__).resolve().parent / "bad"
GOOD = rp_arm_urdf()
LINK2_INERTIA = (
    '<inertia ixx="0.00041666666666666675" ixy="0" ixz="0" iyy="0.013541666666666669" iyz="0" izz="0.013541666666666669"/>'
)
JOINT1_LIMIT = '<limit lower="-3.141592653589793" upper="3.141592653589793" effort="100.0" velocity="3.0"/>'
JOINT2_LIMIT = '<limit lower="0.0" upper="0.3" effort="100.0" velocity="1.0"/>'


def sub(old: str, new: str) -> str:
    assert old in GOOD, old
    return GOOD.replace(old, new, 1)


def add(extra: str) -> str:
    return GOOD.replace("</robot>", extra + "\n</robot>")


def chain(depth: int) -> str:
    parts = ['<robot name="deep">', '<link name="l0"/>']
    for i in range(1, depth + 1):
        parts.append(
            f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/><child link="l{i}"/><axis xyz="0 0 1"/>'
            f'<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
            f'<link name="l{i}"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>'
        )
    return "\n".join([*parts, "</robot>"])


LAUGHS = """<?xml version="1.0"?>
<!DOCTYPE lolz [<!ENTITY lol "lol"><!ENTITY lol2 "&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;">
<!ENTITY lol3 "&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;">]>
<robot name="&lol3;"><link name="a"/></robot>"""
XXE = """<?xml version="1.0"?>
<!DOCTYPE robot [<!ENTITY secret SYSTEM "file:///etc/passwd">]>
<robot name="x"><link name="&secret;"/></robot>"""

CASES: dict[str, tuple[str, str]] = {
    "truncated": (GOOD[: len(GOOD) // 2], "not well-formed XML"),
    "empty": ("", "not well-formed XML"),
    "plain_text": ("this is not a robot", "not well-formed XML"),
    "wrong_root": ('<sdf version="1.6"><model name="m"/></sdf>', "the root element must be <robot>, not <sdf>"),
    "two_robots": ('<robot name="a"><link name="a"/></robot><robot name="b"/>', "not well-formed XML"),
    "external_entity": (XXE, "DOCTYPE and entity declarations are not allowed"),
    "billion_laughs": (LAUGHS, "DOCTYPE and entity declarations are not allowed"),
    "duplicate_link": (add('<link name="link1"/>'), 'link "link1": is defined twice'),
    "duplicate_joint": (
        add('<joint name="joint2" type="fixed"><parent link="link2"/><child link="end_effector"/></joint>'),
        'joint "joint2": is defined twice',
    ),
    "missing_parent_link": (sub('<parent link="link1"/>', '<parent link="link9"/>'), "its parent link 'link9' does not exist"),
    "missing_child_link": (sub('<child link="link2"/>', '<child link="link9"/>'), "its child link 'link9' does not exist"),
    "two_parents": (
        add('<joint name="extra" type="fixed"><parent link="base_link"/><child link="link2"/></joint>'),
        'link "link2": has two parent joints',
    ),
    "cycle": (
        add('<joint name="back" type="fixed"><parent link="end_effector"/><child link="base_link"/></joint>'),
        "no root link (the joints form a cycle)",
    ),
    "two_roots": (add('<link name="floating_island"/>'), "2 root links"),
    "unknown_joint_type": (sub('type="prismatic"', 'type="hinge"'), "unknown joint type 'hinge'"),
    "floating_joint_inside": (sub('type="prismatic"', 'type="floating"'), "floating joints inside a URDF are not supported"),
    "planar_joint": (sub('type="prismatic"', 'type="planar"'), "planar joints inside a URDF are not supported"),
    "revolute_without_limit": (sub(JOINT1_LIMIT, ""), "a revolute joint needs a <limit> element"),
    "prismatic_without_limit": (sub(JOINT2_LIMIT, ""), "a prismatic joint needs a <limit> element"),
    "nan_limit": (sub('lower="0.0" upper="0.3"', 'lower="nan" upper="0.3"'), "lower='nan' is not a number"),
    "infinite_limit": (sub('lower="0.0" upper="0.3"', 'lower="0.0" upper="inf"'), "limits [0.0, inf] must be finite"),
    "negative_effort": (
        sub('effort="100.0" velocity="1.0"', 'effort="-5" velocity="1.0"'),
        "effort limit -5.0 must not be negative",
    ),
    "zero_axis": (sub('<axis xyz="1 0 0"/>', '<axis xyz="0 0 0"/>'), 'joint "joint2": axis must not be zero'),
    "nan_axis": (sub('<axis xyz="1 0 0"/>', '<axis xyz="nan 0 1"/>'), "xyz='nan 0 1' must be finite"),
    "short_axis": (sub('<axis xyz="1 0 0"/>', '<axis xyz="1 0"/>'), "xyz='1 0' must have 3 numbers"),
    "text_origin": (
        sub('<origin xyz="0.5 0 0" rpy="0 0 0"/>\n    <axis', '<origin xyz="half 0 0" rpy="0 0 0"/>\n    <axis'),
        "xyz='half 0 0' is not a list of numbers",
    ),
    "infinite_rpy": (
        sub('<origin xyz="0.5 0 0" rpy="0 0 0"/>\n    <axis', '<origin xyz="0.5 0 0" rpy="0 inf 0"/>\n    <axis'),
        "rpy='0 inf 0' must be finite",
    ),
    "negative_mass": (sub('<mass value="1.0"/>', '<mass value="-1.0"/>'), 'link "link2": mass -1.0 kg must not be negative'),
    "nan_mass": (sub('<mass value="1.0"/>', '<mass value="nan"/>'), "value='nan' is not a number"),
    "infinite_mass": (sub('<mass value="1.0"/>', '<mass value="inf"/>'), "mass inf must be finite"),
    "huge_mass": (sub('<mass value="1.0"/>', '<mass value="1e300"/>'), "value='1e300' is beyond ±1e+12: not a physical robot"),
    "huge_length": (
        sub('<origin xyz="0.5 0 0" rpy="0 0 0"/>\n    <axis', '<origin xyz="1e200 0 0" rpy="0 0 0"/>\n    <axis'),
        "xyz='1e200 0 0' is beyond ±1e+12",
    ),
    "text_mass": (sub('<mass value="1.0"/>', '<mass value="heavy"/>'), "value='heavy' is not a number"),
    "inertial_without_mass": (sub('<mass value="1.0"/>', ""), "<inertial> has no <mass>"),
    "mass_without_value": (sub('<mass value="1.0"/>', "<mass/>"), "<mass> has no value"),
    "negative_inertia": (
        sub(LINK2_INERTIA, LINK2_INERTIA.replace('iyy="0.013541666666666669"', 'iyy="-0.01"')),
        "inertia must be positive semi-definite",
    ),
    "nan_inertia": (sub(LINK2_INERTIA, LINK2_INERTIA.replace('ixy="0"', 'ixy="nan"')), "ixy='nan' is not a number"),
    "joint_without_name": (sub('<joint name="joint2" type="prismatic">', '<joint type="prismatic">'), "joint #2: has no name"),
    "link_without_name": (add("<link/>"), "has no name"),
    "joint_without_parent": (sub('<parent link="link1"/>', ""), "needs <parent link=...> and <child link=...>"),
    "mimic_of_fixed": (
        sub(JOINT2_LIMIT, JOINT2_LIMIT + '<mimic joint="end_effector_joint"/>'),
        "mimics the fixed joint 'end_effector_joint'",
    ),
    "mimic_of_mimic": (sub(JOINT2_LIMIT, JOINT2_LIMIT + '<mimic joint="joint2"/>'), "which is itself a mimic joint"),
    "mimic_nan_multiplier": (
        sub(JOINT2_LIMIT, JOINT2_LIMIT + '<mimic joint="joint1" multiplier="nan"/>'),
        "multiplier='nan' is not a number",
    ),
    "mimic_type_mismatch": (
        sub(JOINT2_LIMIT, JOINT2_LIMIT + '<mimic joint="joint1"/>'),
        "a prismatic joint cannot mimic the revolute joint 'joint1'",
    ),
    "too_deep": (chain(1001), "the kinematic chain is deeper than 1000 links"),
    "mesh_escapes_folder": (
        sub('<geometry><box size="0.5 0.05 0.05"/></geometry>', '<geometry><mesh filename="../../../etc/passwd"/></geometry>'),
        "leaves the URDF's folder",
    ),
    "mesh_file_url_elsewhere": (
        sub('<geometry><box size="0.5 0.05 0.05"/></geometry>', '<geometry><mesh filename="file:///etc/passwd"/></geometry>'),
        "is outside the URDF's folder and package folders",
    ),
    "mesh_absolute_elsewhere": (
        sub('<geometry><box size="0.5 0.05 0.05"/></geometry>', '<geometry><mesh filename="/etc/hostname"/></geometry>'),
        "is outside the URDF's folder and package folders",
    ),
    "mesh_without_filename": (
        sub('<geometry><box size="0.5 0.05 0.05"/></geometry>', "<geometry><mesh/></geometry>"),
        "<mesh> has no filename",
    ),
    "no_links": ('<robot name="nothing"/>', "the robot has no links"),
    "no_moving_joint": (
        '<robot name="statue"><link name="a"/><link name="b"/><joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint></robot>',
        "the robot has no moving joint (",  # then floating_base=True (library) or --floating-base (CLI)
    ),
}
# Moved to tests/data/hostile (they load with a RobodynWarning, see make_hostile_corpus.py):
# mimic_missing_joint, triangle_inequality.


def main() -> None:
    """Write every case and expected.json."""
    FOLDER.mkdir(exist_ok=True)
    for old in FOLDER.glob("*.urdf"):
        old.unlink()
    for name, (text, _) in CASES.items():
        (FOLDER / f"{name}.urdf").write_text(text, encoding="utf-8")
    expected = {f"{name}.urdf": fragment for name, (_, fragment) in CASES.items()}
    (FOLDER / "expected.json").write_text(json.dumps(expected, indent=2) + "\n", encoding="utf-8")
    print(f"wrote {len(CASES)} cases to {FOLDER}")


if __name__ == "__main__":
    main()
