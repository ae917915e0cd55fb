"""equations_document: one entry point for every document, refusals before any derivation."""

from __future__ import annotations

import json

import pytest

from robodyn.equations import derive_equations
from robodyn.equations.document import FORMATS, equations_document
from robodyn.equations.output import render
from robodyn.exceptions import InputError, RobodynWarning


def test_the_equations_document_is_the_rendering_of_the_derived_equations():
    document = equations_document("rp_arm", format="json")
    assert document.content == render(derive_equations("rp_arm"), "json")
    assert document.description.startswith("closed form") and "operations" in document.description


@pytest.mark.parametrize("what", ["christoffel", "kinematics", "derivation", "lecture"])
def test_each_document_refuses_a_format_it_does_not_come_in_before_any_work(what, monkeypatch):
    import robodyn.equations.document as module

    monkeypatch.setattr(module, "derive_equations", lambda *a, **k: pytest.fail("derived before refusing"))
    wrong = next(f for f in ("c", "python", "pdf", "latex") if f not in FORMATS[what])
    with pytest.raises(InputError) as error:
        equations_document("rp_arm", what, format=wrong, frame="end_effector")
    assert error.value.argument == "format"


def test_the_lecture_is_refused_for_any_other_robot():
    with pytest.raises(InputError) as error:
        equations_document("ur5", "lecture")
    assert error.value.argument == "model"
    assert "lecture" in equations_document("rp_arm", "lecture").content


def test_kinematics_need_a_frame_and_give_the_frames_document():
    with pytest.raises(InputError) as error:
        equations_document("rp_arm", "kinematics")
    assert error.value.argument == "frame"
    document = equations_document("rp_arm", "kinematics", frame="end_effector", format="json")
    assert json.loads(document.content)["frame"] == "end_effector"


def test_the_equations_of_a_file_with_constraints_say_they_are_the_open_trees():
    from tests.conftest import ROOT

    four_bar = ROOT / "tests" / "data" / "constraints" / "four_bar.xml"
    with pytest.warns(RobodynWarning, match="open tree's; not in them: 1 equality constraint \\('loop'\\)"):
        equations_document(four_bar, "equations")
    import warnings

    with warnings.catch_warnings():  # negative control: a robot without constraints says nothing
        warnings.simplefilter("error", RobodynWarning)
        equations_document("rp_arm", "equations")
