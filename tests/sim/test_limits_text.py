"""What a limit violation says, in text and JSON, and the one-line warning that lists them."""

from __future__ import annotations

from robodyn.sim.limits import LimitViolation, warning_text

POSITION = LimitViolation("elbow", "position", "upper", 0.25, 0.61, 0.5, "rad")
EFFORT = LimitViolation("shoulder", "effort", "magnitude", 0.1, -90.0, -87.0, "N m")


def test_a_violation_says_joint_quantity_worst_value_limit_and_first_time():
    assert POSITION.text() == "elbow position 0.61 rad beyond 0.5 rad from t = 0.25 s"
    assert EFFORT.text() == "shoulder effort -90 N m beyond ±87 N m from t = 0.1 s"  # a magnitude: ±


def test_a_violation_as_json_names_every_field():
    assert EFFORT.as_dict() == {
        "joint": "shoulder",
        "quantity": "effort",
        "side": "magnitude",
        "first_time_s": 0.1,
        "worst": -90.0,
        "limit": -87.0,
        "unit": "N m",
    }
    assert LimitViolation("j", "velocity", "magnitude", 0.1 + 0.2, 3.0, 2.0, "rad/s").as_dict()["first_time_s"] == 0.3


def test_the_warning_lists_four_in_full_and_counts_the_rest():
    assert warning_text("arm<x>", [POSITION]) == f"arm<x>: 1 joint limit violation: {POSITION.text()}"
    four = [POSITION, EFFORT, POSITION, EFFORT]
    assert warning_text("arm", four) == "arm: 4 joint limit violations: " + "; ".join(v.text() for v in four)
    six = [*four, POSITION, EFFORT]
    assert warning_text("arm", six) == "arm: 6 joint limit violations: " + "; ".join(v.text() for v in four) + "; and 2 more"
    assert warning_text("arm", six, shown=5).endswith(f"{POSITION.text()}; and 1 more")
