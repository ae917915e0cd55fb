"""The push-out of a penetrating contact (docs/contact.md): a point ``d`` below the ground
leaves the step at ``β d / dt`` along the normal, ``β = 0.2`` by default (Baumgarte)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import robodyn
from robodyn.sim.contact import ContactSettings, contact_step
from robodyn.sim.ground import Ground, contact_points

BOX = Path(__file__).parents[1] / "data" / "contact" / "box.urdf"
HALF_HEIGHT = 0.05  # the box's bottom face below its origin, in [m]
DEPTH, DT = 4e-4, 1e-3


@pytest.fixture(scope="module")
def box() -> robodyn.Robot:
    return robodyn.load(BOX, floating_base=True, gravity=(0.0, 0.0, -3.0))


@pytest.mark.parametrize(("settings", "beta"), [(None, 0.2), (ContactSettings(baumgarte=0.5), 0.5)], ids=["default", "given"])
def test_a_penetrating_box_at_rest_leaves_at_beta_times_its_depth_per_step(box, settings, beta):
    """The closed rows solve ``J v⁺ = −β g / dt`` with the gap ``g = −d``: the resting box
    rises at ``β d / dt`` whatever its weight (the given β is the control that it is β)."""
    ground = Ground(height=0.1, friction=0.8)
    q = box.neutral_configuration()
    q[2] = ground.height + HALF_HEIGHT - DEPTH
    points = contact_points(box, "collision").points
    step = contact_step(box, q, np.zeros(box.nv), np.zeros(box.nv), DT, ground, points, settings=settings)
    assert np.allclose(step.gaps[step.gaps < 0], -DEPTH, atol=1e-12)  # the bottom four corners
    assert step.v[2] == pytest.approx(beta * DEPTH / DT, rel=1e-6)
    assert np.abs(step.v[[0, 1, 3, 4, 5]]).max() < 1e-9
