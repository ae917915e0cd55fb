"""Constraints as values: rows, refusals in one line, pickling, printing, records of a file,
and ``robodyn.load(constraints=)``."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

import robodyn
from robodyn.cli.report import info_dict, info_text
from robodyn.constraints import FrameAnchor, PointAnchor, PointContact, as_constraints, from_equalities, total_rows
from robodyn.constraints.records import equality_notes
from robodyn.exceptions import InputError
from robodyn.urdf.equality import EqualityRecord
from tests.constraints.linkages import DATA, load_linkage, loop


def test_each_kind_states_its_rows():
    assert PointAnchor("a").rows == 3
    assert FrameAnchor("a").rows == 6
    assert PointContact("a", friction=0.8).rows == 3
    assert PointContact("a", friction=0.0).rows == 1
    assert total_rows([PointAnchor("a"), FrameAnchor("b"), PointContact("c", friction=0)]) == 10


def test_a_constraint_is_a_picklable_printable_value():
    constraints = (loop("four_bar"), FrameAnchor("x", (0.1, 0, 0, 0, 0, 0.2), None, None, name="weld"), PointContact("foot"))
    assert pickle.loads(pickle.dumps(constraints)) == constraints
    text = "\n".join(str(c) for c in constraints)
    assert "point (0.35, 0, 0) of link 'coupler' held on (0.3, 0, 0) of link 'rocker'" in text
    assert "the neutral configuration" in text and "sticking" in text


def test_a_contact_normal_is_normalised_and_a_negative_friction_refused():
    assert PointContact("f", normal=(0, 0, 2)).normal == (0.0, 0.0, 1.0)
    with pytest.raises(InputError, match="friction"):
        PointContact("f", friction=-0.1)
    with pytest.raises(InputError, match="normal"):
        PointContact("f", normal=(0, 0, 0))


@pytest.mark.parametrize(
    "make",
    [
        lambda: PointAnchor("a", (1, 2)),
        lambda: PointAnchor("a", (1, float("nan"), 2)),
        lambda: PointAnchor(""),
        lambda: FrameAnchor(3),
    ],
)
def test_malformed_numbers_and_names_are_refused_by_name(make):
    with pytest.raises(InputError) as error:
        make()
    assert "\n" not in str(error.value)


def test_a_link_the_robot_does_not_have_is_refused_in_one_line_listing_its_links():
    with pytest.raises(InputError) as error:
        robodyn.load(DATA / "four_bar.urdf", constraints=[PointAnchor("coupler", (0.35, 0, 0), "rocker\x1b[31m")])
    message = str(error.value)
    assert "constraints[0].frame2" in message and "'crank'" in message and "'rocker'" in message
    assert "\n" not in message and "\x1b" not in message


def test_not_a_constraint_is_refused():
    with pytest.raises(InputError, match=r"constraints\[1\]"):
        as_constraints([PointAnchor("a"), "b"])


def test_load_adds_constraints_and_a_pickled_robot_keeps_them():
    robot = load_linkage("four_bar")
    assert robot.constraints == (loop("four_bar"),)
    again = pickle.loads(pickle.dumps(robot))
    assert again.constraints == robot.constraints
    q = np.array([0.3, 1.0, 2.0])
    assert np.array_equal(again.constraint_residual(q), robot.constraint_residual(q))


def test_info_lists_the_constraints():
    robot = load_linkage("four_bar")
    text = info_text(robot)
    # at q = 0 every bar lies on the ground line: the loop's rows have rank 1 there
    assert "constraints (3 rows; 2 redundant at the neutral configuration" in text
    assert "held on (0.3, 0, 0) of link 'rocker'" in text
    assert info_dict(robot)["constraints"][0]["rows"] == 3 and info_dict(robot)["constraint_rank_at_neutral"] == 1


def test_equality_records_become_anchors():
    records = (
        EqualityRecord("connect", "loop", "coupler", "rocker", (0.35, 0.0, 0.0)),
        EqualityRecord("weld", None, "crank", None, relpose=(0.1, 0.2, 0.3, 0.0, 0.0, 0.0, 1.0)),
        EqualityRecord("weld", "w", "crank", "rocker", torquescale=0.5),
        EqualityRecord("connect", "off", "coupler", None, active=False),
    )
    connect, weld, weld_reference = from_equalities(records)
    assert connect == PointAnchor("coupler", (0.35, 0, 0), "rocker", None, name="loop")
    assert weld.frame2 is None and np.allclose(weld.origin2, (0.1, 0.2, 0.3, 0.0, 0.0, np.pi))
    assert weld_reference.origin2 is None
    notes = equality_notes(records)
    assert len(notes) == 2 and "inactive" in notes[1] and "torquescale" in notes[0]


def test_a_connect_record_holds_the_point_where_it_is_at_the_neutral_configuration():
    (anchor,) = from_equalities([EqualityRecord("connect", None, "coupler", "rocker", (0.35, 0.0, 0.0))])
    robot = robodyn.load(DATA / "four_bar.urdf", constraints=[anchor])
    assert np.allclose(robot.constraint_residual(robot.neutral_configuration()), 0.0, atol=1e-15)
    assert not np.allclose(robot.constraint_residual(np.array([0.4, -0.2, 0.1])), 0.0, atol=1e-3)


def test_what_of_a_files_equalities_is_not_modelled_is_reported_or_refused(monkeypatch):
    from dataclasses import replace

    from robodyn.dynamics import loading
    from robodyn.exceptions import RobodynWarning, URDFError

    resolve = loading.resolve_source
    records = (
        EqualityRecord("connect", "loop", "coupler", "rocker", (0.35, 0.0, 0.0)),
        EqualityRecord("connect", "spare", "coupler", None, active=False),
    )
    monkeypatch.setattr(loading, "resolve_source", lambda *a, **k: replace(resolve(*a, **k), equalities=records))
    with pytest.warns(RobodynWarning, match="'spare'.*inactive"):
        robot = robodyn.load(DATA / "four_bar.urdf")
    assert robot.constraints == (PointAnchor("coupler", (0.35, 0, 0), "rocker", None, name="loop"),)
    with pytest.raises(URDFError, match="inactive"):
        robodyn.load(DATA / "four_bar.urdf", strict=True)
