"""A constraints file (YAML): the four-bar's loop read into the value written in Python,
every kind of table, and hostile files refused in one sentence naming the table and key:
a list that is no list, each refusal's whole sentence, the bounds just within and just past."""

from __future__ import annotations

import pickle
import re
from pathlib import Path

import numpy as np
import pytest
import yaml

import robodyn
from robodyn.constraints import FrameAnchor, PointAnchor, PointContact, files
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


WELD = "weld:\n  - frame1: crank\n"


@pytest.mark.parametrize("value", ["0", "false", "{}", "''", "1.5", "crank"])
def test_a_list_given_as_a_scalar_or_mapping_is_refused_not_read_as_empty(value):
    with pytest.raises(InputError, match=r"anchor must be a list of anchor entries \(each a '- ' item\)"):
        read_constraints(f"anchor: {value}\n" + WELD)


def test_an_empty_list_or_a_list_left_empty_adds_nothing():
    assert len(read_constraints("anchor: []\ncontact:\n" + WELD)) == 1


E = "a YAML file of anchor, weld and contact lists (docs/constraints.md)"
A = "anchor:\n  - frame1: crank\n"


@pytest.mark.parametrize(
    ("text", "sentence"),
    [
        ("- 1\n", f"constraints must be {E}, got '<text>': list."),
        ("joint: []\nzoo: []\n" + A, f"constraints must be {E}, got '<text>': an unknown list 'joint'."),
        ("# nothing\n", f"constraints must be {E}, got '<text>': no constraint."),
        ("anchor:\n  - 3\n", "anchor[0] must be a mapping of the keys name, frame1, point1, frame2, point2, got 3."),
        ("weld:\n  - [1]\n", "weld[0] must be a mapping of the keys name, frame1, origin1, frame2, origin2, got [1]."),
        (
            "contact:\n  - frame: crank\n    zz: 1\n    aa: 2\n",
            "contact[0].aa must be one of the keys name, frame, point, normal, friction, plane_point, got an unknown key.",
        ),
        ("anchor:\n  - frame1: crank\n    " + "k" * 50 + ": 1\n", "anchor[0]." + "k" * 40 + " must be one of"),
        ("weld:\n  - origin1: [0, 0, 0, 0, 0, 0]\n", "weld[0].frame1 must be given (a link name), got nothing."),
        ("contact:\n  - point: [0, 0, 0]\n", "contact[0].frame must be given (a link name), got nothing."),
        ("anchor:\n  - frame1: [crank]\n", "anchor[0].frame1 must be a string (a link name), got ['crank']."),
        ("anchor:\n  - frame1: crank\n    name: 7\n", "anchor[0].name must be a string, got 7."),
        ("anchor:\n  - frame1: crank\n    point1: [0, true, 0]\n", "anchor[0].point1[1] must be a number, got True."),
        ("anchor:\n  - frame1: crank\n    point1: [0, 0, x]\n", "anchor[0].point1[2] must be a number, got 'x'."),
        ("contact:\n  - frame: crank\n    friction: '1'\n", "contact[0].friction must be a number, got '1'."),
        (
            "contact:\n  - frame: crank\n    friction: 1000001\n",
            "contact[0].friction must be a number within ±1e+06, got 1000001.",
        ),
        (
            "contact:\n  - frame: crank\n    friction: 1.0e7\n",
            "contact[0].friction must be a finite number within ±1e+06, got 10000000.0.",
        ),
        (
            "contact:\n  - frame: crank\n    friction: .inf\n",
            "contact[0].friction must be a finite number within ±1e+06, got inf.",
        ),
        ("contact:\n  - frame: crank\n    friction: 1" + "0" * 60 + "\n", "within ±1e+06, got 1" + "0" * 39 + "."),
        ("anchor:\n  - frame1: crank\n    point1: [0, 0]\n", "anchor[0].point1 must be 3 finite numbers in [m], got (0.0, 0.0)."),
        (
            "anchor:\n  - &a {frame1: crank}\n  - *a\n",
            f"constraints must be {E}, got '<text>': aliases (*name) are not accepted.",
        ),
        ("anchor: 1\n", "anchor must be a list of anchor entries (each a '- ' item), got '<text>': int."),
        ("weld: {}\n", "weld must be a list of weld entries (each a '- ' item), got '<text>': dict."),
        (
            "anchor:\n  - frame1: crank\n    " + "k" * 50 + ": 0\n    " + "k" * 50 + ": 1\n",
            "the key '" + "k" * 39 + " is given twice",
        ),
        ("l" * 50 + ": []\n", f"got '<text>': an unknown list '{'l' * 40}'."),
        (
            "anchor:\n  - frame1: crank\n    point1: [0, 0, '" + "x" * 100 + "']\n",
            "point1[2] must be a number, got '" + "x" * 79 + ".",
        ),
        ("anchor:\n  - frame1: [" + "c" * 100 + "]\n", "frame1 must be a string (a link name), got ['" + "c" * 78 + "."),
        ("anchor:\n  - [" + "c" * 100 + "]\n", ", point2, got ['" + "c" * 78 + "."),
        ("anchor:\n  - frame1: crank\n    point1: 0\n    point1: 1\n", "the key 'point1' is given twice"),
        ("anchor:\n  - frame1: crank\n    3: 0\n    3: 1\n", "the key 3 is given twice"),
    ],
)
def test_each_refusal_is_its_own_whole_sentence(text, sentence):
    with pytest.raises(InputError) as caught:
        read_constraints(text)
    assert sentence in str(caught.value)
    assert str(caught.value).startswith(sentence) or "\n" not in str(caught.value)


@pytest.mark.parametrize("bad", [3, b"anchor:\n", None])
def test_a_source_that_is_neither_a_path_nor_text_is_refused(bad):
    with pytest.raises(InputError, match=re.escape(f"constraints must be a path or YAML text, got {bad!r}.")):
        read_constraints(bad)


def test_the_bounds_accept_what_is_just_within_them(tmp_path, monkeypatch):
    big = 10**6
    (anchor,) = read_constraints(f"anchor:\n  - frame1: crank\n    point1: [{big}, -{big}, {float(big)}]\n")
    assert anchor.point1 == (1e6, -1e6, 1e6)
    limit, most = 1000, 5  # smaller bounds (read when called): the same comparisons, quicker
    monkeypatch.setattr(files, "MAX_FILE_BYTES", limit)
    monkeypatch.setattr(files, "MAX_CONSTRAINTS", most)
    text = A + "#" * (limit - len(A))
    assert len(read_constraints(text)) == 1
    with pytest.raises(
        InputError, match=re.escape(f"constraints must be text of at most {limit} characters, got {limit + 1} characters.")
    ):
        read_constraints(text + "#")
    path = tmp_path / "c.yaml"
    path.write_text(text)
    assert len(read_constraints(path)) == 1 and len(read_constraints(str(path))) == 1
    path.write_text(text + "#")
    with pytest.raises(
        InputError, match=re.escape(f"constraints must be a file of at most {limit} bytes, got '{path}': {limit + 1} bytes.")
    ):
        read_constraints(path)
    entries = "anchor:\n" + "  - frame1: crank\n" * (most - 1) + "weld:\n  - frame1: crank\n"
    assert len(read_constraints(entries)) == most
    with pytest.raises(InputError, match=re.escape(f"constraints must be at most {most} constraints, got '<text>': more.")):
        read_constraints(entries + "  - frame1: rocker\n")
    for table, key in (("anchor", "frame1"), ("contact", "frame")):  # the last list alone past the bound too
        with pytest.raises(InputError, match=re.escape(f"at most {most} constraints")):
            read_constraints(f"{table}:\n" + f"  - {key}: crank\n" * (most + 1))


def test_files_are_named_in_their_refusals_and_a_path_may_hold_a_newline(tmp_path):
    odd = tmp_path / "a\nb.yaml"
    odd.write_text(A)
    assert len(read_constraints(str(odd))) == 1  # a file, though its name holds a newline
    bad = tmp_path / "bad.yaml"
    bad.write_text("anchor: [\n")
    with pytest.raises(InputError, match=re.escape(f"constraints must be {E}, got '{bad}': while parsing")):
        read_constraints(bad)
    with pytest.raises(
        InputError, match=re.escape(f"constraints must be {E} in UTF-8, got '{tmp_path / 'badx'}': not UTF-8 text.")
    ):
        (tmp_path / "badx").write_bytes(b"anchor: \xff\n")
        read_constraints(tmp_path / "badx")
    with pytest.raises(InputError, match=re.escape(f"constraints must be {E}, got '{tmp_path}': Is a directory.")):
        read_constraints(tmp_path)
    with pytest.raises(
        InputError, match=re.escape(f"constraints must be {E}, got '{tmp_path / 'no'}': No such file or directory.")
    ):
        read_constraints(str(tmp_path / "no"))
    deep = tmp_path / ("d" * 150) / ("e" * 150)
    deep.mkdir(parents=True)
    (deep / "x.yaml").write_text("- 1\n")
    with pytest.raises(InputError) as caught:
        read_constraints(deep / "x.yaml")
    assert f"got '{str(deep / 'x.yaml')[:200]}': list." in str(caught.value)


def test_a_value_refused_by_the_constraint_itself_is_named_where_in_the_file():
    with pytest.raises(InputError, match=re.escape("contact[1].normal must be")):
        read_constraints("contact:\n  - frame: crank\n  - frame: crank\n    normal: [0, 0, 0]\n")


def test_an_unreadable_name_and_a_long_yaml_error_are_one_sentence(tmp_path):
    with pytest.raises(InputError, match=re.escape(f"constraints must be {E}, got 'a\\x00b': unreadable.")):
        read_constraints("a\x00b")  # a NUL byte: no such file can exist (ValueError, no strerror)
    with pytest.raises(
        InputError, match=re.escape("constraints must be a path or YAML text, got " + repr(list(range(40)))[:80] + ".")
    ):
        read_constraints(list(range(40)))  # type: ignore[arg-type]
    text = "anchor:\n  - frame1: crank\n    point1: [0, 0, 0\n" + "#" * 300 + "\n"
    with pytest.raises(yaml.YAMLError) as own:
        yaml.safe_load(text)
    reason = " ".join(str(own.value).split())
    assert len(reason) > 160
    with pytest.raises(InputError) as caught:
        read_constraints(text)
    assert str(caught.value) == f"constraints must be {E}, got '<text>': {reason[:160]}."
