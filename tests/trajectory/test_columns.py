"""robodyn.trajectory.columns: names from the robot's dofs, layouts of any column order, one-line errors."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn.dynamics.dofs import BASE_Q_NAMES, BASE_V_NAMES
from robodyn.exceptions import TrajectoryError
from robodyn.trajectory.columns import check_table, coordinate_names, coordinate_names_to_joints, parse_header
from tests.conftest import ROOT


@pytest.fixture(scope="module", params=[True, False], ids=["floating", "fixed"])
def arm(request):
    return robodyn.load(ROOT / "tests" / "data" / "rrp_arm.urdf", floating_base=request.param)


def test_coordinate_names_are_the_robots_configuration_and_dof_names(arm):
    q_names, v_names = coordinate_names(arm.joint_names, arm.floating_base)
    assert q_names == arm.configuration_names and v_names == [dof.name for dof in arm.dofs]
    assert coordinate_names_to_joints(v_names, arm.floating_base) == arm.joint_names
    if arm.floating_base:
        assert tuple(q_names[:7]) == BASE_Q_NAMES and tuple(v_names[:6]) == BASE_V_NAMES


def test_a_shuffled_header_gives_the_base_first_and_the_joints_in_file_order(arm, rng):
    header = ["t", *(f"q[{n}]" for n in arm.configuration_names), *(f"tau[{d.name}]" for d in arm.dofs)]
    shuffled = [header[i] for i in rng.permutation(len(header))]
    layout = parse_header(shuffled, "shuffled.csv")
    joints = [name[2:-1] for name in shuffled if name.startswith("q[") and name[2:-1] not in BASE_Q_NAMES]
    q_names, v_names = coordinate_names([*arm.joint_names[:1], *joints] if arm.floating_base else joints, arm.floating_base)
    assert list(layout.q_names) == q_names and list(layout.v_names) == v_names
    assert sorted(layout.q_names) == sorted(arm.configuration_names) and layout.floating_base == arm.floating_base
    position = {name: index for index, name in enumerate(shuffled)}
    assert layout.time == position["t"]
    assert layout.columns["q"].tolist() == [position[f"q[{n}]"] for n in q_names]
    assert layout.columns["tau"].tolist() == [position[f"tau[{n}]"] for n in v_names]
    assert layout.columns["v"] is None and sorted(layout.joint_names) == sorted(arm.joint_names)


@pytest.mark.parametrize("name", ["j\x1b[31m", "k\u202ereversed", "line\nrobodyn: ok: forged", "nul\x00", "back\\slash"])
def test_errors_about_hostile_column_names_are_one_printable_line(name):
    with pytest.raises(TrajectoryError) as raised:
        parse_header(["t", "q[a]", name], "hostile.csv")
    message = str(raised.value)
    assert message.isprintable() and message.startswith("hostile.csv: unknown columns")
    assert "\x1b" not in message and "\u202e" not in message and "\n" not in message


def test_an_incomplete_floating_base_names_the_missing_columns():
    with pytest.raises(TrajectoryError, match=r"missing columns q\[base.qx\], q\[base.qy\], q\[base.qz\], q\[base.qw\]"):
        parse_header(["t", "q[base.x]", "q[base.y]", "q[base.z]", "q[j]"], "base.csv")


def test_check_table_names_the_row_and_the_column():
    layout = parse_header(["t", "q[a]", "q[b]"], "m.csv")
    table = np.array([[0.0, 1.0, 2.0], [0.1, 1.0, np.inf], [0.2, 1.0, 2.0]])
    with pytest.raises(TrajectoryError, match=r"m\.csv, row 12: q\[b\] is inf"):
        check_table(table, layout, "m.csv", first_row=11)
    table[1, 2] = 2.0
    table[2, 0] = 0.1
    with pytest.raises(TrajectoryError, match=r"row 3: time does not increase"):
        check_table(table, layout, "m.csv")
