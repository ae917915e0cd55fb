"""The run's limit report behind its whole-array screen: the same violations as
``JointLimits.violations`` wherever each limit binds, just binds or just misses."""

from __future__ import annotations

import numpy as np
import pytest

from robodyn.sim.engine import _violations
from robodyn.sim.limits import TOLERANCE, JointLimits
from tests.sim.test_limit_violations import arm, motion


@pytest.mark.parametrize("floating", [False, True])
@pytest.mark.parametrize("factor", [0.4, 0.6, 0.99, 1.01, 3.0])
def test_the_screen_reports_what_the_violations_report(floating, factor):
    """Each quantity pushed past its limit by ``factor`` tolerances (below, at and above the
    reported edge, and under the screen's half tolerance), one at a time; a motion within
    every limit reports nothing (negative control: the pushed ones report)."""
    robot = arm(floating=floating)
    edge = factor * TOLERANCE
    cases = [
        (np.array([0.0, 0.5 + edge * 1.5]), np.zeros(2), None),  # slide past its upper stop
        (np.array([0.0, -1.0 - edge * 2.0]), np.zeros(2), np.zeros((2, 2))),  # past the lower stop
        (np.zeros(2), np.array([0.0, -3.0 - edge * 4.0]), None),  # hinge speed, signed
        (np.zeros(2), np.zeros(2), np.array([[0.0, 0.0], [30.0 + edge * 31.0, -7.0 - edge * 8.0]])),  # efforts
    ]
    reported = 0
    for slide, speed, tau in cases:
        trajectory = motion(robot, slide, speed, tau)
        expected = JointLimits(robot).violations(trajectory)
        assert _violations(robot, trajectory) == expected
        reported += len(expected)
    assert (reported > 0) == (factor > 1.0)
    calm = motion(robot, np.array([0.0, 0.2]), np.array([0.0, 2.9]), np.array([[0.0, 0.0], [29.0, 6.9]]))
    assert _violations(robot, calm) == [] == JointLimits(robot).violations(calm)


def test_an_empty_trajectory_breaks_no_limit():
    robot = arm()
    empty = motion(robot, np.zeros(0), np.zeros(0), np.zeros((0, 2)))
    assert _violations(robot, empty) == [] == JointLimits(robot).violations(empty)
