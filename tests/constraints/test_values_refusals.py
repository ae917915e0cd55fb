"""Issue 39, the constraint values' behaviour the linkage tests do not cross (killing
mutmut's survivors in ``robodyn/constraints/values.py``): each refusal's whole sentence —
the argument it names, what it expects, the value shown cut at 80 characters —, numbers
stored as tuples of Python floats whatever sequence they came in (so that equal
constraints are equal and hash alike), text and booleans refused as numbers, and the
printed form of each kind (named or not, on a link or on the world, sticking or sliding)."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

from robodyn.constraints import FrameAnchor, PointAnchor, PointContact, as_constraints, check_frames
from robodyn.exceptions import InputError

LONG = list(range(40))  # its repr is 150 characters
LONG_SHOWN = repr(LONG)[:80]


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda: PointAnchor("a", (1, 2)), "point1 must be 3 finite numbers in [m], got (1, 2)."),
        (lambda: PointAnchor("a", 5), "point1 must be 3 finite numbers in [m], got 5."),
        (lambda: PointAnchor("a", LONG), f"point1 must be 3 finite numbers in [m], got {LONG_SHOWN}."),
        (lambda: PointAnchor("a", [None] * 30), f"point1 must be 3 finite numbers in [m], got {repr([None] * 30)[:80]}."),
        (
            lambda: PointAnchor("a", (0, 0, 0), "b", (1, 2, float("inf"))),
            "point2 must be 3 finite numbers in [m], got (1, 2, inf).",
        ),
        (lambda: PointAnchor(""), "frame1 must be a link name (a non-empty string), got ''."),
        (lambda: PointAnchor("a", (0, 0, 0), 3), "frame2 must be a link name (a non-empty string) or None, got 3."),
        (lambda: PointAnchor(b"x" * 100), f"frame1 must be a link name (a non-empty string), got {repr(b'x' * 100)[:80]}."),
        (lambda: FrameAnchor(None), "frame1 must be a link name (a non-empty string), got None."),
        (lambda: FrameAnchor("a", frame2=""), "frame2 must be a link name (a non-empty string) or None, got ''."),
        (lambda: FrameAnchor("a", (1, 2, 3)), "origin1 must be 6 finite numbers in [m] and [rad], got (1, 2, 3)."),
        (
            lambda: FrameAnchor("a", origin2=(0,) * 7),
            "origin2 must be 6 finite numbers in [m] and [rad], got (0, 0, 0, 0, 0, 0, 0).",
        ),
        (lambda: PointContact(7), "frame must be a link name (a non-empty string), got 7."),
        (lambda: PointContact("f", (1, 2)), "point must be 3 finite numbers in [m], got (1, 2)."),
        (lambda: PointContact("f", plane_point=(0, 0)), "plane_point must be 3 finite numbers in [m], got (0, 0)."),
        (
            lambda: PointContact("f", normal=(0, float("nan"), 1)),
            "normal must be 3 finite numbers in world axes, got (0, nan, 1).",
        ),
        (lambda: PointContact("f", normal=(0, 0, 0)), "normal must be a non-zero vector, got (0.0, 0.0, 0.0)."),
        (lambda: PointContact("f", normal=(1e-12, 0, 0)), "normal must be a non-zero vector, got (1e-12, 0.0, 0.0)."),
        (lambda: PointContact("f", friction=float("nan")), "friction must be 1 finite numbers in [1], got (nan,)."),
        (lambda: PointContact("f", friction=-0.25), "friction must be a finite number >= 0 (Coulomb's μ), got -0.25."),
        # text and booleans are not numbers (they were read as such: "123" was the point (1, 2, 3))
        (lambda: PointAnchor("a", "123"), "point1 must be 3 finite numbers in [m], got '123'."),
        (lambda: PointAnchor("a", (1, "2", 3)), "point1 must be 3 finite numbers in [m], got (1, '2', 3)."),
        (lambda: PointContact("f", friction=True), "friction must be 1 finite numbers in [1], got (True,)."),
        (lambda: PointContact("f", friction="0.5"), "friction must be 1 finite numbers in [1], got ('0.5',)."),
        (
            lambda: as_constraints("abc"),
            "constraints must be a PointAnchor, FrameAnchor, PointContact or a list of them, got 'abc'.",
        ),
        (lambda: as_constraints(5, "extra"), "extra must be a PointAnchor, FrameAnchor, PointContact or a list of them, got 5."),
        (
            lambda: as_constraints("x" * 100),
            f"constraints must be a PointAnchor, FrameAnchor, PointContact or a list of them, got {repr('x' * 100)[:80]}.",
        ),
        (
            lambda: as_constraints([PointAnchor("a"), "y" * 100]),
            f"constraints[1] must be a PointAnchor, FrameAnchor or PointContact, got {repr('y' * 100)[:80]}.",
        ),
    ],
)
def test_each_refusal_is_one_sentence_naming_the_argument_what_it_expects_and_the_value(make, message):
    with pytest.raises(InputError) as error:
        make()
    assert str(error.value) == message


def test_a_link_the_robot_lacks_is_refused_listing_thirty_links_and_how_many_more():
    anchor = PointAnchor("l0", (0, 0, 0), "ghost")
    with pytest.raises(InputError) as error:
        check_frames([PointContact("l1"), anchor], ["l0", "l1"], "arm")
    assert str(error.value) == "constraints[1].frame2 must be a link of robot 'arm' ('l0', 'l1'), got 'ghost'."
    links = [f"l{i}" for i in range(33)]
    with pytest.raises(InputError) as error:
        check_frames([anchor], links, "big")
    listed = ", ".join(f"'l{i}'" for i in range(30))
    assert str(error.value) == f"constraints[0].frame2 must be a link of robot 'big' ({listed} and 3 more), got 'ghost'."
    with pytest.raises(InputError) as error:
        check_frames([anchor], links[:30], "thirty")
    assert str(error.value) == f"constraints[0].frame2 must be a link of robot 'thirty' ({listed}), got 'ghost'."
    check_frames([anchor, PointAnchor("l2")], ["l0", "ghost", "l2"], "ok")  # every link known: no refusal


@pytest.mark.parametrize("sequence", [list, np.array, lambda values: (np.float32(values[0]), *values[1:])])
def test_numbers_are_stored_as_tuples_of_floats_whatever_sequence_they_came_in(sequence):
    made = [
        PointAnchor("a", sequence([1, 2, 3]), "b", sequence([4, 5, 6])),
        FrameAnchor("a", sequence([1, 2, 3, 0, 0, 1]), "b", sequence([0, 0, 1, 1, 0, 0])),
        PointContact("f", sequence([1, 2, 3]), plane_point=sequence([0, 0, 2]), friction=1),
    ]
    plain = [
        PointAnchor("a", (1.0, 2.0, 3.0), "b", (4.0, 5.0, 6.0)),
        FrameAnchor("a", (1.0, 2.0, 3.0, 0.0, 0.0, 1.0), "b", (0.0, 0.0, 1.0, 1.0, 0.0, 0.0)),
        PointContact("f", (1.0, 2.0, 3.0), plane_point=(0.0, 0.0, 2.0), friction=1.0),
    ]
    assert made == plain and [hash(c) for c in made] == [hash(c) for c in plain]
    assert pickle.loads(pickle.dumps(made)) == plain
    for constraint in made:
        for field in ("point1", "point2", "origin1", "origin2", "point", "plane_point", "normal"):
            value = getattr(constraint, field, None)
            if value is not None:
                assert type(value) is tuple and all(type(x) is float for x in value), field
    assert type(made[2].friction) is float


def test_the_printed_form_names_the_kind_its_rows_and_its_ends():
    assert str(PointAnchor("tip", (0.1, 0, 0), None, (1, 2, 3.5), name="pin")) == (
        "point anchor 'pin' (3 rows): point (0.1, 0, 0) of link 'tip' held on (1, 2, 3.5) of the world"
    )
    assert str(PointAnchor("tip")) == (
        "point anchor (3 rows): point (0, 0, 0) of link 'tip' held on the world (where it is at the neutral configuration)"
    )
    assert str(FrameAnchor("a", (0, 0, 0.5, 0, 0, 1), "b", (1, 0, 0, 0, 0, 0), name="weld")) == (
        "frame anchor 'weld' (6 rows, a weld): frame (0, 0, 0.5, 0, 0, 1) of link 'a' held on (1, 0, 0, 0, 0, 0) of link 'b'"
    )
    assert str(FrameAnchor("a", frame2="b")) == (
        "frame anchor (6 rows, a weld): frame (0, 0, 0, 0, 0, 0) of link 'a' held on link 'b' "
        "(where it is at the neutral configuration)"
    )
    assert str(PointContact("foot", (0, 0, -0.02), normal=(0, 0, 2), friction=0.5, plane_point=(0, 0, 0.1), name="f")) == (
        "point contact 'f' (3 rows, sticking, bilateral at this layer, μ = 0.5): point (0, 0, -0.02) of link 'foot' "
        "on the plane through (0, 0, 0.1) with normal (0, 0, 1)"
    )
    assert str(PointContact("tip", normal=(-1, 0, 0), friction=0)) == (
        "point contact (1 row, frictionless sliding, μ = 0): point (0, 0, 0) of link 'tip' "
        "on the plane through (0, 0, 0) with normal (-1, 0, 0)"
    )
