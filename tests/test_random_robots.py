"""Property: on random valid kinematic trees, Pinocchio and the reference agree."""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings

from robodyn.verify.check import check_robot
from tests.random_robots import random_urdfs


def assert_agree(urdf: str) -> None:
    report = check_robot(urdf, samples=4, seed=0)
    assert report.passed, {name: c.max_rel for name, c in report.comparisons.items()}


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(random_urdfs)
def test_random_trees_agree(urdf):
    assert_agree(urdf)


@pytest.mark.slow
@settings(max_examples=1000, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(random_urdfs)
def test_many_random_trees_agree(urdf):
    assert_agree(urdf)
