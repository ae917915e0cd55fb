"""The derivation with multipliers: the RP arm whose tip slides on the wall x = c — the
closed-form wall force against robodyn's numeric λ (moving), against the free-body diagram
(at rest), and refusals."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

import robodyn
from robodyn.constraints import FrameAnchor, PointAnchor, PointContact
from robodyn.equations.constrained_derivation import derive_constrained, to_latex, to_text
from robodyn.equations.constrained_document import constrained_dict
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


def test_a_state_of_another_size_than_the_joints_is_refused(derivation):
    for q, v, tau in (
        ([0.1, 0.2, 0.3], [0.0, 0.0], [0.0, 0.0]),
        ([0.1, 0.2], [0.0], [0.0, 0.0]),
        ([0.1, 0.2], [0.0, 0.0], [1.0]),
    ):
        with pytest.raises(ValueError):
            derivation.multipliers(q, v, tau)
    assert derivation.multipliers([0.1, 0.2], [0.0, 0.0], [0.0, 0.0]).shape == (1,)


def test_no_constraint_or_something_else_is_refused_before_any_algebra():
    refusals = {
        "constraints must be at least one constraint, got none.": [],
        "constraints must be a PointAnchor, FrameAnchor, PointContact or a list of them, got 42.": 42,
        "constraints[0] must be a PointAnchor, FrameAnchor or PointContact, got 'x'.": ["x"],
    }
    for sentence, given in refusals.items():
        with pytest.raises(InputError) as refused:
            derive_constrained("rp_arm", given)
        assert str(refused.value) == sentence


def test_the_steps_are_printed(derivation):
    text = to_text(derivation)
    for step in ("step 7: Φ(q) = 0", "step 8: J = ∂Φ/∂q", "step 10: λ ="):
        assert step in text
    assert "-cos(q_joint1)" in text  # ∂Φ/∂q2 of Φ = c − (l1 + q2 + l2) cos q1
    assert r"\lambda &=" in to_latex(derivation)


def test_a_sticking_contact_is_refused_saying_what_is_not_derived_and_where_the_open_tree_is():
    with pytest.raises(InputError, match=r"tangential rows hold a velocity.*not derived.*without constraints, the open tree"):
        derive_constrained("rp_arm", PointContact("link2", friction=0.5))
    with pytest.raises(InputError, match="constraints"):
        derive_constrained("rp_arm", PointContact("nowhere", friction=0.0))
    sticking = [
        ([WALL, PointContact("link2", friction=0.5)], "constraints[1]", "0.5"),
        (PointContact("link2", friction=0.8), "constraint", "0.8"),
    ]
    for given, name, friction in sticking:
        with pytest.raises(InputError) as refused:
            derive_constrained("rp_arm", given)
        assert str(refused.value) == (
            f"{name} must be a PointAnchor, a FrameAnchor (weld) or a frictionless PointContact: a sticking contact's "
            "tangential rows hold a velocity, not a position, and are not derived (with friction 0 its normal row is; "
            f"without constraints, the open tree's derivation), got a point contact with friction {friction}."
        )


# A loop between two bodies: an arm's tip held on a carriage's pin (oblique slider), gravity
# not the default. Its z row is 0 = 0 (planar), so 2 rows on 2 joints: λ in closed form.
TWO_BODIES = Path(__file__).resolve().parents[1] / "data" / "constraints" / "two_body_loop.urdf"
PIN = PointAnchor("arm", (0.4, 0.0, 0.0), "carriage", (0.0, 0.05, 0.0), name="pin")
GRAVITY = (0.7, -9.6, 1.1)


@pytest.fixture(scope="module")
def loop_derivation():
    return derive_constrained(TWO_BODIES, PIN, gravity=GRAVITY)


def numeric_terms(robot, derivation, q, v, tau):
    """The derivation's Φ, J, J̇ q̇, q̈ and λ against robodyn's numeric ones (largest relative gaps)."""
    order = [robot.joint_names.index(name) for name in derivation.steps.joint_names]
    kept = list(derivation.kept)
    a, lam = robot.constrained_forward_dynamics(q, v, tau)
    values = (q[order], v[order], tau[order])
    qdd, lam_derived = derivation.solve(*values)
    pairs = {
        "phi": (derivation._numbers(derivation.phi, *values).ravel(), robot.constraint_residual(q)[kept]),
        "J": (derivation._numbers(derivation.J, *values), robot.constraint_jacobian(q)[kept][:, order]),
        "Jdot_qd": (derivation._numbers(derivation.Jdot_qd, *values).ravel(), robot.constraint_drift(q, v)[kept]),
        "qdd": (qdd, a[order]),
        "lambda": (lam_derived, lam),
        "lambda closed form": (derivation.multipliers(*values), lam),
    }
    return {key: np.abs(x - y).max() / max(1.0, np.abs(y).max()) for key, (x, y) in pairs.items()}


@pytest.mark.slow
def test_a_loop_between_two_bodies_is_the_numeric_dynamics_and_a_wrong_sign_is_caught(loop_derivation, rng):
    from dataclasses import replace

    robot = robodyn.load(str(TWO_BODIES), constraints=[PIN], gravity=GRAVITY)
    assert loop_derivation.lam is not None and loop_derivation.dropped == (("pin", "z", "N"),)
    wrong_sign = replace(loop_derivation, J=-loop_derivation.J, lam=None)  # M q̈ + … = τ − Jᵀ λ
    no_drift = replace(loop_derivation, Jdot_qd=0 * loop_derivation.Jdot_qd, lam=None)
    for _ in range(4):
        q, v, tau = rng.uniform(-1.0, 1.0, 2), rng.normal(size=2), rng.normal(scale=3.0, size=2)
        assert max(numeric_terms(robot, loop_derivation, q, v, tau).values()) <= 1e-9
        assert numeric_terms(robot, wrong_sign, q, v, tau)["lambda"] > 1e-3  # the checks can fail
        assert numeric_terms(robot, no_drift, q, v, tau)["qdd"] > 1e-3
    text, latex = to_text(loop_derivation), to_latex(loop_derivation)
    assert "rows pin.z: 0 = 0 for every q" in text and "step 10: λ = " in text
    assert r"\lambda &=" in latex and r"\begin{pmatrix} M & -J^\top" in latex and "q_{1}" in latex


# A weld: the RP arm's second link held where it is at the neutral configuration, the welded
# frame offset and turned in the link, gravity not the default. The arm moves in the x–z
# plane: rows x, z and my are derived (3 rows on 2 joints: the KKT system), y, mx, mz are
# 0 = 0.
WELD = FrameAnchor("link2", (0.1, 0.02, 0.0, 0.0, 0.0, 0.3), name="weld")


def sine_of(log: np.ndarray) -> np.ndarray:
    """``sin θ a`` of a rotation vector ``θ a`` (how the derivation shows a weld's rotation rows)."""
    angle = np.linalg.norm(log)
    return log if angle == 0 else np.sin(angle) * log / angle


@pytest.mark.slow
def test_a_weld_is_derived_its_rotation_rows_by_the_angular_velocity_jacobian_as_the_numeric_one(rng):
    from dataclasses import replace

    derivation = derive_constrained("rp_arm", WELD, gravity=GRAVITY)
    robot = robodyn.load("rp_arm", constraints=[WELD], gravity=GRAVITY)
    assert [derivation.labels[i][1] for i in derivation.kept] == ["x", "z", "my"]
    assert [derivation.labels[i][1] for i in derivation.angular] == ["my"]
    # the negative control: the rotation row's J as ∂/∂q of the Φ shown (sin θ a), right only where Φ = 0
    q_symbols = sp.Matrix(derivation.steps.q)
    derivative = replace(derivation, J=derivation.phi.jacobian(q_symbols))
    order = [robot.joint_names.index(name) for name in derivation.steps.joint_names]
    zero = np.zeros(2)
    assert numeric_terms(robot, derivative, zero, zero, zero)["J"] < 1e-12
    for _ in range(3):
        q, v, tau = rng.uniform(-1.0, 1.0, 2), rng.normal(size=2), rng.normal(scale=3.0, size=2)
        terms = numeric_terms(robot, derivation, q, v, tau)
        assert max(value for key, value in terms.items() if key != "phi") <= 1e-9
        flipped = replace(derivation, J=-derivation.J, lam=None)  # the check can fail: M q̈ + … = τ − Jᵀ λ
        assert numeric_terms(robot, flipped, q, v, tau)["lambda"] > 1e-3
        residual = robot.constraint_residual(q)
        shown = np.concatenate([residual[:3], sine_of(residual[3:])])[list(derivation.kept)]
        derived = derivation._numbers(derivation.phi, q[order], v[order], tau[order]).ravel()
        assert np.abs(derived - shown).max() <= 1e-9
        assert numeric_terms(robot, derivative, q, v, tau)["J"] > 1e-3  # the check can fail
        assert numeric_terms(robot, replace(derivation, J=-derivation.J), q, v, tau)["lambda"] > 1e-3
    text, latex = to_text(derivation), to_latex(derivation)
    assert "rows weld.y, weld.mx, weld.mz: 0 = 0 for every q" in text
    assert "except rows weld.my: the relative angular velocity's Jacobian" in text and "R₁(q) R₂(q)ᵀ" in text
    assert r"\omega_1 - \omega_2" in latex and r"R_1 R_2^\top" in latex
    assert constrained_dict(derivation)["angular_rows"] == ["weld.my"]
    # the fixed base's link is the world: a weld to it is the same weld
    to_base = derive_constrained("rp_arm", FrameAnchor("link2", WELD.origin1, "base_link", name="weld"), gravity=GRAVITY)
    assert to_base.kept == derivation.kept and to_base.angular == derivation.angular
    for ours, theirs in ((to_base.phi, derivation.phi), (to_base.J, derivation.J), (to_base.Jdot_qd, derivation.Jdot_qd)):
        assert sp.simplify(ours - theirs) == sp.zeros(*theirs.shape)


@pytest.mark.slow
def test_a_constraint_given_twice_shares_the_wall_force_equally_and_is_stated_as_the_kkt_system(rng):
    # the Delassus matrix is singular for every q: no closed form (it raised sympy's
    # NonInvertibleMatrixError before), λ the least-norm solution of the KKT system
    again = PointContact("end_effector", normal=(-1.0, 0.0, 0.0), friction=0.0, plane_point=(0.8, 0.0, 0.0), name="again")
    twice = derive_constrained("rp_arm", [WALL, again])
    assert twice.lam is None and "step 10: λ (2 rows) and q̈ solve that system" in to_text(twice)
    robot = robodyn.load("rp_arm", constraints=[WALL])
    for _ in range(3):
        q, v, tau = robot.random_configuration(rng), rng.normal(size=2), rng.normal(scale=5.0, size=2)
        a, lam = robot.constrained_forward_dynamics(q, v, tau)
        qdd, shared = twice.solve(q, v, tau)
        assert np.abs(qdd - a).max() <= 1e-9 * max(1.0, np.abs(a).max())
        assert np.abs(shared - lam[0] / 2).max() <= 1e-9 * max(1.0, abs(lam[0]))
        assert not np.allclose(shared, [lam[0], 0.0], atol=1e-3 * abs(lam[0]))  # the check can fail: all on one


@pytest.mark.slow
def test_a_constraint_no_configuration_satisfies_is_refused_naming_its_row():
    floor = PointContact("base_link", normal=(0.0, 0.0, 1.0), friction=0.0, plane_point=(0.0, 0.0, 0.25), name="floor")
    with pytest.raises(InputError) as refused:
        derive_constrained("rp_arm", [WALL, floor])  # the fixed base's point is 0.25 m below the plane for every q
    assert str(refused.value) == (
        "constraints must be constraints some configuration satisfies, got row floor.n of Φ is the constant -0.25 m for every q."
    )


@pytest.mark.slow
def test_a_weld_between_two_moving_links_takes_their_relative_angular_velocity(rng):
    from dataclasses import replace

    # the four-bar's coupler welded to its crank (the loop left open): ω₁ − ω₂ is the coupler
    # joint's speed alone, against robodyn's numeric J and λ (a sum ω₁ + ω₂ would not be)
    four_bar = Path(__file__).resolve().parents[1] / "data" / "constraints" / "four_bar.urdf"
    weld = FrameAnchor("coupler", (0.1, 0.0, 0.0, 0.0, 0.0, 0.0), "crank", name="elbow")
    derivation = derive_constrained(four_bar, weld, gravity=GRAVITY)
    robot = robodyn.load(str(four_bar), constraints=[weld], gravity=GRAVITY)
    assert [derivation.labels[i][1] for i in derivation.angular]  # a rotation row is kept
    for _ in range(2):
        q, v, tau = rng.uniform(-1.0, 1.0, 3), rng.normal(size=3), rng.normal(scale=3.0, size=3)
        terms = numeric_terms(robot, derivation, q, v, tau)
        assert max(value for key, value in terms.items() if key != "phi") <= 1e-9
        flipped = replace(derivation, J=-derivation.J, lam=None)  # the check can fail: M q̈ + … = τ − Jᵀ λ
        assert numeric_terms(robot, flipped, q, v, tau)["lambda"] > 1e-3
