"""The derivation with multipliers: the RP arm whose tip slides on the wall x = c — the
closed-form wall force against robodyn's numeric λ (moving), against the free-body diagram
(at rest), and refusals."""

from __future__ import annotations

import math

import numpy as np
import pytest

import robodyn
from robodyn.constraints import FrameAnchor, PointContact
from robodyn.equations.constrained_derivation import derive_constrained, to_latex, to_text
from robodyn.exceptions import InputError
from robodyn.urdf.models import RPArmParameters

WALL = PointContact("end_effector", normal=(-1.0, 0.0, 0.0), friction=0.0, plane_point=(0.8, 0.0, 0.0), name="wall")


@pytest.fixture(scope="module")
def derivation():
    return derive_constrained("rp_arm", WALL)


def test_the_closed_form_wall_force_is_the_numeric_one_while_moving(derivation, rng):
    robot = robodyn.load("rp_arm", constraints=[WALL])
    for _ in range(5):
        q, v, tau = robot.random_configuration(rng), rng.normal(size=2), rng.normal(scale=5.0, size=2)
        lam = robot.constrained_forward_dynamics(q, v, tau)[1]
        assert abs(derivation.multipliers(q, v, tau)[0] - lam[0]) <= 1e-9 * max(1.0, abs(lam[0]))


def test_the_closed_form_at_rest_is_the_free_body_diagrams_force(derivation):
    p, g, push, q1 = RPArmParameters(), 9.81, 7.0, 0.6
    reach = 0.8 / math.cos(q1)
    q2 = reach - p.l1 - p.l2
    gravity = np.array([(p.m1 * g * p.l1 / 2 + p.m2 * g * (p.l1 + q2 + p.l2 / 2)) * math.cos(q1), p.m2 * g * math.sin(q1)])
    tau = gravity - np.array([push * reach * math.sin(q1), -push * math.cos(q1)])
    assert abs(derivation.multipliers([q1, q2], [0.0, 0.0], tau)[0] - push) < 1e-12 * push


def test_the_steps_are_printed(derivation):
    text = to_text(derivation)
    for step in ("step 7: Φ(q) = 0", "step 8: J = ∂Φ/∂q", "step 10: λ ="):
        assert step in text
    assert "-cos(q_joint1)" in text  # ∂Φ/∂q2 of Φ = c − (l1 + q2 + l2) cos q1
    assert r"\lambda &=" in to_latex(derivation)


def test_a_constraint_whose_jacobian_is_not_the_derivative_of_its_rows_is_refused():
    with pytest.raises(InputError, match="constraint"):
        derive_constrained("rp_arm", FrameAnchor("link2"))
    with pytest.raises(InputError, match="constraints"):
        derive_constrained("rp_arm", PointContact("nowhere", friction=0.0))
