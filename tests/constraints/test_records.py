"""A file's equality records as constraints: what robodyn's rigid constraints do not model
(a soft equality's ``solref`` / ``solimp``) is reported in one line, and ``strict`` refuses it."""

from __future__ import annotations

import warnings

import pytest

import robodyn
from robodyn.exceptions import RobodynWarning, URDFError

ARM = """<mujoco><compiler angle="radian"/>{default}<worldbody>
<body name="upper"><joint name="j1" axis="0 1 0"/><geom type="capsule" size="0.05" fromto="0 0 0 0.3 0 0"/>
<body name="lower" pos="0.3 0 0"><joint name="j2" axis="0 1 0"/><geom type="capsule" size="0.05" fromto="0 0 0 0.3 0 0"/>
</body></body></worldbody><equality>{equalities}</equality></mujoco>"""
CONNECT = '<connect name="{name}" body1="lower" anchor="0.3 0 0" {extra}/>'


def equality_warnings(text: str) -> list[str]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", RobodynWarning)
        robodyn.load(text)
    return [str(warning.message) for warning in caught if "equality" in str(warning.message)]


def test_a_soft_equality_is_reported_in_one_line_naming_each():
    text = ARM.format(
        default="",
        equalities=CONNECT.format(name="tip", extra='solref="0.02 1"')
        + '<weld name="glue" body1="upper" solimp="0.9 0.95 0.001"/>'
        + CONNECT.format(name="stiff", extra=""),
    )
    (line,) = equality_warnings(text)
    assert "softness" in line and "rigid" in line
    assert "'tip' (solref)" in line and "'glue' (solimp)" in line and "stiff" not in line


def test_a_default_class_softness_is_reported_and_strict_refuses_it():
    text = ARM.format(default='<default><equality solref="0.005 1"/></default>', equalities=CONNECT.format(name="tip", extra=""))
    (line,) = equality_warnings(text)
    assert "'tip' (solref)" in line
    with pytest.raises(URDFError, match="softness"):
        robodyn.load(text, strict=True)


def test_a_rigid_equality_is_not_reported():
    assert equality_warnings(ARM.format(default="", equalities=CONNECT.format(name="tip", extra=""))) == []
