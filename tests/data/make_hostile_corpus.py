"""Write the hostile corpus (tests/data/hostile/*.urdf) and what each file must give.

Run from the repository root: ``python tests/data/make_hostile_corpus.py``. Cases of
issue #14 (families 1 terminal text, 2 numbers, 3 resources) and issue #13 item 9 (what
peers load). ``expected.json`` maps each file to ``{"family", "outcome", "fragment",
"reference"}``:

- ``"error"``: load, the reference (if ``reference``) and the CLI refuse it with an error
  containing ``fragment`` (CLI: one stderr line, exit 2);
- ``"warning"``: it loads with a RobodynWarning containing ``fragment``; ``strict=True``
  refuses it and ``robodyn lint`` counts it as an error;
- ``"ok"``: it loads without a warning (``fragment``, if any, is a warning only ``lint``
  shows).

Cases that need the file system (FIFOs, devices, huge files, long names) are made at test
time (tests/urdf/test_sources.py).
"""

from __future__ import annotations

import json
from pathlib import Path

from robodyn.urdf.models import rp_arm_urdf

FOLDER = Path(__file__).resolve().parent / "hostile"
GOOD = rp_arm_urdf()
MASS = '<mass value="1.0"/>'
LINK2_INERTIA = (
    '<inertia ixx="0.00041666666666666675" ixy="0" ixz="0" iyy="0.013541666666666669" iyz="0" izz="0.013541666666666669"/>'
)
JOINT2_LIMIT = '<limit lower="0.0" upper="0.3" effort="100.0" velocity="1.0"/>'
ORIGIN2 = '<origin xyz="0.5 0 0" rpy="0 0 0"/>\n    <axis'


def sub(old: str, new: str, text: str = GOOD) -> str:
    assert old in text, old
    return text.replace(old, new, 1)


def add(extra: str) -> str:
    return GOOD.replace("</robot>", extra + "\n</robot>")


def hostile_joint(name: str) -> str:
    """A joint with a hostile name whose child link is missing: the error names it."""
    return add(f'<joint name="{name}" type="fixed"><parent link="link2"/><child link="nowhere"/></joint>')


def nested(depth: int) -> str:
    inner = "<a>" * depth + "</a>" * depth
    return sub('<link name="link1">', f'<link name="link1"><gazebo>{inner}</gazebo>')


def chain(joints: int) -> str:
    parts = ['<robot name="long_chain">', '<link name="l0"/>']
    for i in range(1, joints + 1):
        parts.append(
            f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/><child link="l{i}"/><axis xyz="0 0 1"/>'
            f'<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
            f'<link name="l{i}"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>'
        )
    return "\n".join([*parts, "</robot>"])


FORGED = "&#10;robodyn: ok: everything fine"

CASES: dict[str, tuple[str, str, str, str, bool]] = {
    # family, outcome, text, fragment, also through the reference
    # --- 1. terminal text: names that would forge lines or recolour the terminal --------
    "name_newline_forged_line": ("terminal", "error", hostile_joint(f"j{FORGED}"), "\\nrobodyn: ok: everything fine", True),
    "name_carriage_return": ("terminal", "error", hostile_joint("j&#13;robodyn: ok"), "j\\rrobodyn: ok", True),
    "name_tab": ("terminal", "error", hostile_joint("j&#9;x"), "j\\tx", True),
    "name_c1_csi": ("terminal", "error", hostile_joint("j\x9b31m"), "j\\x9b31m", True),
    "name_next_line_c1": ("terminal", "error", hostile_joint("j\x85robodyn: ok"), "j\\x85robodyn: ok", True),
    "name_bidi_override": ("terminal", "error", hostile_joint("j\u202etxt.exe"), "j\\u202etxt.exe", True),
    "name_bidi_isolate": ("terminal", "error", hostile_joint("j\u2066x\u2069"), "j\\u2066x\\u2069", True),
    "name_line_separator": ("terminal", "error", hostile_joint("j\u2028robodyn: ok"), "j\\u2028robodyn: ok", True),
    "name_escape_sequence": ("terminal", "error", hostile_joint("j\x1b[31mred"), "not well-formed XML", True),
    "link_name_newline": (
        "terminal",
        "error",
        add(f'<link name="l{FORGED}"/>'),
        "2 root links",
        True,
    ),
    "mimic_source_newline": (
        "terminal",
        "warning",
        sub(JOINT2_LIMIT, JOINT2_LIMIT + f'<mimic joint="joint1{FORGED}" multiplier="0.5"/>').replace(
            'type="prismatic"', 'type="revolute"'
        ),
        "\\nrobodyn: ok: everything fine",
        True,
    ),
    "mass_text_newline": ("terminal", "error", sub(MASS, f'<mass value="1{FORGED}"/>'), "is not a number", True),
    # --- 2. one number grammar ---------------------------------------------------------------
    "mass_padded": ("numbers", "ok", sub(MASS, '<mass value=" 1.0 "/>'), "", True),
    "mass_tab_padded": ("numbers", "ok", sub(MASS, '<mass value="&#9;1.0&#10;"/>'), "", True),
    "inertia_trailing_space": (
        "numbers",
        "ok",
        sub(LINK2_INERTIA, LINK2_INERTIA.replace('iyy="0.013541666666666669"', 'iyy="0.013541666666666669 "')),
        "",
        True,
    ),
    "mass_leading_plus_and_dot": ("numbers", "ok", sub(MASS, '<mass value="+.5e+1"/>'), "", True),
    "mass_underscore": ("numbers", "error", sub(MASS, '<mass value="1_000"/>'), "value='1_000' is not a number", True),
    "mass_fullwidth_digit": ("numbers", "error", sub(MASS, '<mass value="\uff12"/>'), "is not a number", True),
    "mass_arabic_indic_digit": ("numbers", "error", sub(MASS, '<mass value="\u0662"/>'), "is not a number", True),
    "mass_hexadecimal": ("numbers", "error", sub(MASS, '<mass value="0x10"/>'), "value='0x10' is not a number", True),
    "mass_decimal_comma": ("numbers", "error", sub(MASS, '<mass value="1,5"/>'), "value='1,5' is not a number", True),
    "mass_no_break_space": ("numbers", "error", sub(MASS, '<mass value="\u00a01"/>'), "is not a number", True),
    "mass_infinity_word": ("numbers", "error", sub(MASS, '<mass value="Infinity"/>'), "mass inf must be finite", True),
    "mass_nan_padded": ("numbers", "error", sub(MASS, '<mass value=" nan "/>'), "is not a number", True),
    "origin_fullwidth_digit": (
        "numbers",
        "error",
        sub(ORIGIN2, '<origin xyz="0.5 0 \uff10" rpy="0 0 0"/>\n    <axis'),
        "is not a list of numbers",
        True,
    ),
    "origin_em_space_separator": (
        "numbers",
        "error",
        sub(ORIGIN2, '<origin xyz="0.5\u20030 0" rpy="0 0 0"/>\n    <axis'),
        "is not a list of numbers",
        True,
    ),
    "origin_underscore": (
        "numbers",
        "error",
        sub(ORIGIN2, '<origin xyz="0.5 0 0" rpy="0 1_0 0"/>\n    <axis'),
        "rpy='0 1_0 0' is not a list of numbers",
        True,
    ),
    "axis_fullwidth": (
        "numbers",
        "error",
        sub('<axis xyz="1 0 0"/>', '<axis xyz="\uff11 0 0"/>'),
        "is not a list of numbers",
        True,
    ),
    "limit_underscore": (
        "numbers",
        "error",
        sub(JOINT2_LIMIT, JOINT2_LIMIT.replace('upper="0.3"', 'upper="0_3"')),
        "upper='0_3' is not a number",
        True,
    ),
    "effort_underscore": (
        "numbers",
        "error",
        sub(JOINT2_LIMIT, JOINT2_LIMIT.replace('effort="100.0"', 'effort="1_00"')),
        "effort='1_00' is not a number",
        True,
    ),
    "mimic_multiplier_underscore": (
        "numbers",
        "error",
        sub(JOINT2_LIMIT, JOINT2_LIMIT + '<mimic joint="joint1" multiplier="1_0"/>').replace(
            'type="prismatic"', 'type="revolute"'
        ),
        "multiplier='1_0' is not a number",
        True,
    ),
    # --- 3. bounded resources --------------------------------------------------------------
    "nested_1000_elements": ("resources", "error", nested(1000), "nested deeper than 100 levels", True),
    "nested_102_levels": ("resources", "error", nested(99), "nested deeper than 100 levels", True),
    "nested_99_levels": ("resources", "ok", nested(96), "", True),
    "chain_301_joints": ("resources", "error", chain(301), "raises it)", False),
    # --- issue 13 item 9: what peers load ----------------------------------------------------
    "triangle_inequality": (
        "peers",
        "warning",
        sub(LINK2_INERTIA, '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.03"/>'),
        "break the triangle inequality",
        True,
    ),
    "mimic_missing_joint": (
        "peers",
        "warning",
        sub(JOINT2_LIMIT, JOINT2_LIMIT + '<mimic joint="joint7" multiplier="2"/>'),
        "mimics joint 'joint7', which does not exist: it moves independently",
        True,
    ),
    "psd_rounding_noise": (
        "peers",
        "ok",
        sub(LINK2_INERTIA, '<inertia ixx="2.407e-35" ixy="0" ixz="0" iyy="0" iyz="0" izz="-2.407e-35"/>'),
        "tiny inertia",
        True,
    ),
    "whitespace_before_declaration": ("peers", "ok", "\n\n   \t" + GOOD, "", True),
    "byte_order_mark": ("peers", "ok", "\ufeff" + GOOD, "", True),
    "singular_inertia_moving": (
        "peers",
        "ok",
        sub(LINK2_INERTIA, '<inertia ixx="0" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>'),
        "singular inertia",
        True,
    ),
    "non_psd_stays_error": (
        "peers",
        "error",
        sub(LINK2_INERTIA, '<inertia ixx="0.01" ixy="0.02" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>'),
        "inertia must be positive semi-definite",
        True,
    ),
    "fixed_only_suggests_floating": (
        "peers",
        "error",
        '<robot name="statue"><link name="a"><inertial><mass value="1"/>'
        '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link></robot>',
        "gives its root six degrees of freedom",  # floating_base=True (library), --floating-base (CLI)
        True,
    ),
}


def main() -> None:
    """Write every case and expected.json."""
    FOLDER.mkdir(exist_ok=True)
    for old in FOLDER.glob("*.urdf"):
        old.unlink()
    expected = {}
    for name, (family, outcome, text, fragment, reference) in CASES.items():
        (FOLDER / f"{name}.urdf").write_text(text, encoding="utf-8")
        expected[f"{name}.urdf"] = {"family": family, "outcome": outcome, "fragment": fragment, "reference": reference}
    (FOLDER / "expected.json").write_text(json.dumps(expected, indent=2, ensure_ascii=True) + "\n", encoding="utf-8")
    print(f"wrote {len(CASES)} cases to {FOLDER}")


if __name__ == "__main__":
    main()
