"""A constraints file (YAML): the four-bar's loop read into the value written in Python,
every kind of table, and hostile files refused in one sentence naming the table and key."""

from __future__ import annotations

import pickle
import re
from pathlib import Path

import numpy as np
import pytest

import robodyn
from robodyn.constraints import FrameAnchor, PointAnchor, PointContact
from robodyn.constraints.files import MAX_FILE_BYTES, read_constraints
from robodyn.exceptions import InputError

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"

EVERY_KIND = """
contact:
  - name: foot
    frame: rocker
    point: [0.3, 0, 0]
    normal: [0, 0, 2]
    friction: 0
    plane_point: [0, 0, -1]
anchor:
  - frame1: crank
    point1: [0.1, 0, 0]
weld:
  - name: tool
    frame1: coupler
    origin1: [0, 0, 0, 0, 0, 0.5]
    frame2: crank
    origin2: [0.1, 0, 0, 0, 0, 0]
"""


def test_the_example_file_is_the_loop_written_in_python():
    (loop,) = read_constraints(EXAMPLES / "four_bar_constraints.yaml")
    assert loop == PointAnchor("coupler", (0.35, 0, 0), "rocker", (0.3, 0, 0), name="loop")
    robot = robodyn.load(str(EXAMPLES / "four_bar.urdf"), constraints=[loop])
    q = robot.neutral_configuration()
    assert np.abs(robot.constraint_residual(q)).max() < 1e-12  # the bars are placed closed at q = 0
    assert robot.constraint_rank(q) == 2  # planar: one of the three rows is redundant


def test_every_kind_of_table_is_read_in_the_order_anchors_welds_contacts():
    anchor, weld, contact = read_constraints(EVERY_KIND)
    assert anchor == PointAnchor("crank", (0.1, 0, 0))
    assert weld == FrameAnchor("coupler", (0, 0, 0, 0, 0, 0.5), "crank", (0.1, 0, 0, 0, 0, 0), name="tool")
    assert contact == PointContact("rocker", (0.3, 0, 0), (0, 0, 1), friction=0.0, plane_point=(0, 0, -1), name="foot")
    assert pickle.loads(pickle.dumps((anchor, weld, contact))) == (anchor, weld, contact)


@pytest.mark.parametrize(
    ("text", "named"),
    [
        ("anchor: [{frame1: crank}\n", "constraints"),  # not YAML
        ("anchor:\n  - frame1: crank\n    ponit1: [0, 0, 0]\n", "anchor[0].ponit1"),  # a typo is not ignored
        ("joint:\n  - frame1: crank\n", "constraints"),  # an unknown list
        ("anchor:\n  frame1: crank\n", "anchor"),  # a mapping, not a list
        ("- frame1: crank\n", "constraints"),  # a list, not a mapping of lists
        ("anchor:\n  - point1: [0, 0, 0]\n", "anchor[0].frame1"),  # no link
        ("anchor:\n  - frame1: 3\n", "anchor[0].frame1"),
        ("anchor:\n  - frame1: crank\n    point1: [.nan, 0, 0]\n", "anchor[0].point1[0]"),
        ("anchor:\n  - frame1: crank\n    point1: [1.0e400, 0, 0]\n", "anchor[0].point1[0]"),
        ("anchor:\n  - frame1: crank\n    point1: [1" + "0" * 400 + ", 0, 0]\n", "anchor[0].point1[0]"),
        ("anchor:\n  - frame1: crank\n    point1: [0, 0]\n", "anchor[0].point1"),
        ("anchor:\n  - frame1: crank\n    point1: [2e6, 0, 0]\n", "anchor[0].point1[0]"),  # not kilometres
        ("contact:\n  - frame: crank\n    normal: [0, 0, 0]\n", "contact[0].normal"),
        ("contact:\n  - frame: crank\n    friction: -1\n", "contact[0].friction"),
        ("anchor:\n  - &a {frame1: crank}\n  - *a\n", "aliases"),  # no expansion bombs
        ("# nothing\n", "constraints"),
    ],
)
def test_a_hostile_file_is_refused_in_one_sentence_naming_where(text, named):
    with pytest.raises(InputError, match=re.escape(named)) as caught:
        read_constraints(text)
    assert "\n" not in str(caught.value)


def test_numbers_are_read_as_yaml_1_2_writes_them():
    (anchor,) = read_constraints("anchor:\n  - frame1: crank\n    point1: [1e-3, -2E+1, 7]\n")
    assert anchor.point1 == (1e-3, -20.0, 7.0)  # YAML 1.1 reads 1e-3 as a string


def test_a_missing_binary_or_huge_file_is_refused(tmp_path):
    with pytest.raises(InputError, match="No such file"):
        read_constraints(tmp_path / "missing.toml")
    binary = tmp_path / "binary.toml"
    binary.write_bytes(b"\xff\xfe[[anchor]]")
    with pytest.raises(InputError, match="UTF-8"):
        read_constraints(binary)
    huge = tmp_path / "huge.toml"
    huge.write_bytes(b"#" * (MAX_FILE_BYTES + 1))
    with pytest.raises(InputError, match="bytes"):
        read_constraints(huge)


def test_a_link_the_robot_does_not_have_is_refused_listing_its_links():
    (anchor,) = read_constraints("anchor:\n  - frame1: crank\n    frame2: nowhere\n")
    with pytest.raises(InputError, match=r"frame2 must be a link of robot 'four_bar' \('world', 'ground', 'crank'"):
        robodyn.load(str(EXAMPLES / "four_bar.urdf"), constraints=[anchor])


@pytest.mark.parametrize(
    "text",
    [
        "anchor:\n  - frame1: crank\nanchor:\n  - frame1: rocker\n",  # a list given twice: YAML keeps the last
        "anchor:\n  - frame1: crank\n    point1: [0, 0, 0]\n    point1: [0.1, 0, 0]\n",  # a key twice in an entry
    ],
)
def test_a_key_given_twice_is_refused_not_overwritten(text):
    with pytest.raises(InputError, match=r"given twice.*line [34]") as caught:
        read_constraints(text)
    assert "\n" not in str(caught.value)
