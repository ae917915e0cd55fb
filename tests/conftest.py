"""Shared fixtures: the URDFs of ``urdf/``, a few zoo robots, seeded random states."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parent.parent
URDF_FILES = sorted((ROOT / "urdf").glob("*.urdf"))
#: Zoo robots used by the fast tier: a spread of joint types and sizes.
FAST_ZOO = ["panda", "ur5", "double_pendulum_continuous", "so100", "z1"]


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(20261123)


def random_state(robot, rng: np.random.Generator, count: int | None = None):
    """A configuration within limits and random velocity and acceleration."""
    q = robot.random_configuration(rng, count)
    shape = (robot.nv,) if count is None else (count, robot.nv)
    return q, rng.normal(size=shape), rng.normal(size=shape)
