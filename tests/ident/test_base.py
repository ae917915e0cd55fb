"""Base parameters: counts (the RP arm against the hand derivation), τ reproduced, rank at
fresh states, stability across draws, the symbolic expressions."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

import robodyn
from robodyn.dynamics.regressor import inertial_parameters, regressor
from robodyn.exceptions import IdentificationError
from robodyn.ident import base_parameters
from robodyn.ident.base import random_states
from tests.dynamics.test_regressor import MIMIC_URDF


def fresh_states(robot, count=40, seed=12345):
    return random_states(robot, count, np.random.default_rng(seed))


def test_rp_arm_matches_the_hand_derivation():
    # docs/identification.md: tau of the rigid RP arm depends on the standard parameters only
    # through Iyy1 + Iyy2 (both links turn about the same axis), the first moments of link 1
    # perpendicular to the axis (mx1, mz1), and m2, mx2, mz2.
    robot = robodyn.load("rp_arm")
    base = base_parameters(robot)
    assert base.count == 6
    symbols = {name: sp.Symbol(name, real=True) for name in base.standard_names}
    s = lambda name: symbols[name]  # noqa: E731
    expected = [
        s("mx[link1]"),
        s("mz[link1]"),
        s("Iyy[link1]") + s("Iyy[link2]"),
        s("m[link2]"),
        s("mx[link2]"),
        s("mz[link2]"),
    ]
    assert [sp.simplify(e - x) for e, x in zip(base.expressions(), expected, strict=True)] == [0] * 6
    # In the lecture's terms: m1 l1/2, m2, m2 c2 and Iz1 + m1 l1²/4 + Iz2 + m2 c2² are identifiable.
    l1, c2, m1, m2 = 0.5, 0.2, 2.0, 1.0
    assert base.values[0] == pytest.approx(m1 * l1 / 2)
    assert base.values[4] == pytest.approx(m2 * c2)
    Iz1, Iz2 = m1 * (l1**2 + 0.05**2) / 12, m2 * (0.4**2 + 0.05**2) / 12
    assert base.values[2] == pytest.approx(Iz1 + m1 * l1**2 / 4 + Iz2 + m2 * c2**2)


def test_null_space_leaves_tau_unchanged_and_base_directions_do_not():
    robot = robodyn.load("rp_arm")
    base = base_parameters(robot)
    q, v, a = fresh_states(robot)
    Y = regressor(robot, q, v, a)
    _, _, vt = np.linalg.svd(base.mapping)
    null = vt[base.count :]  # directions that keep every base parameter
    assert np.abs(Y @ null.T).max() < 1e-12 * np.abs(Y).max()
    for row in np.linalg.pinv(base.mapping).T:  # a change of one base parameter moves tau
        assert np.abs(Y @ row).max() > 1e-3


@pytest.mark.parametrize(
    ("source", "options", "count"),
    [
        ("rp_arm", {}, 6),
        ("double_pendulum", {}, 6),  # the planar 2R arm: ZZ1R, MX1R, MY1, ZZ2, MX2, MY2
        ("ur5", {}, 36),
        ("panda", {"lock": {"panda_finger_joint1": 0.013}}, 43),  # Gaz et al. (2019) find 43 too
    ],
)
def test_counts_reproduce_tau_and_rank_at_fresh_states(source, options, count):
    robot = robodyn.load(source, **options)
    base = base_parameters(robot)
    assert base.count == count
    q, v, a = fresh_states(robot)
    tau = robot.inverse_dynamics(q, v, a)
    Yb = base.regressor(q, v, a)
    assert Yb.shape == (40, robot.nv, count)
    assert np.abs(Yb @ base.values - tau).max() <= 1e-10 * np.abs(tau).max()
    assert np.linalg.matrix_rank(Yb.reshape(-1, count), tol=1e-8 * np.abs(Yb).max()) == count
    np.testing.assert_allclose(base.mapping @ inertial_parameters(robot), base.values)


def test_mimic_and_friction():
    robot = robodyn.load(MIMIC_URDF)
    base = base_parameters(robot, friction=True)
    q, v, a = fresh_states(robot)
    tau = robot.inverse_dynamics(q, v, a)
    assert np.abs(base.regressor(q, v, a) @ base.values - tau).max() <= 1e-10 * np.abs(tau).max()
    assert base.names[-4:] == ["fv[j1]", "fv[j2]", "fc[j1]", "fc[j2]"]  # friction is always identifiable
    assert base.count - 4 == base_parameters(robot).count


def test_stable_across_seeds():
    robot = robodyn.load("ur5")
    first, second = base_parameters(robot, seed=0), base_parameters(robot, seed=10, samples=150)
    assert first.count == second.count and first.names == second.names
    np.testing.assert_allclose(first.mapping, second.mapping, atol=1e-8)


def test_one_body_of_a_six_joint_arm_has_ten_identifiable_parameters():
    robot = robodyn.load("ur5")
    base = base_parameters(robot, bodies=["wrist_3_link"])
    assert base.count == 10 and base.names[0] == "m[wrist_3_link]"
    q, v, a = fresh_states(robot)
    tau = robot.inverse_dynamics(q, v, a)
    np.testing.assert_allclose(
        base.regressor(q, v, a) @ base.values + base.known_torque(q, v, a), tau, atol=1e-10 * np.abs(tau).max()
    )


def test_negative_controls():
    robot = robodyn.load("ur5")
    base = base_parameters(robot)
    q, v, a = fresh_states(robot)
    tau = robot.inverse_dynamics(q, v, a)
    wrong = base.values.copy()
    wrong[base.names.index("m[upper_arm_link]") if "m[upper_arm_link]" in base.names else 5] *= 1.01
    assert np.abs(base.regressor(q, v, a) @ wrong - tau).max() > 1e-6 * np.abs(tau).max()
    # Fewer stacked rows than parameters cannot show the rank: refused.
    with pytest.raises(robodyn.InputError, match="samples"):
        base_parameters(robot, samples=3)
    with pytest.raises(robodyn.InputError, match="bodies"):
        base_parameters(robot, bodies=["no_such_link"])
    with pytest.raises(robodyn.InputError, match="tolerance"):
        base_parameters(robot, tolerance=0.5)


def test_symbolic_refused_for_large_robots():
    robot = robodyn.load("panda")  # 8 joints
    with pytest.raises(IdentificationError, match="symbolic"):
        base_parameters(robot, bodies=["panda_link7"]).expressions()


def test_rendering_escapes_hostile_names():
    import json

    from robodyn.ident.render import render_base_parameters

    hostile = robodyn.rp_arm_urdf().replace('"link2"', '"l&#x202E;2$\\input{x}_%"')
    robot = robodyn.load(hostile)
    base = base_parameters(robot)
    text = render_base_parameters(base, "text")
    assert "\u202e" not in text and "\\u202e" in text and "Iyy[link1] + Iyy[l" in text
    latex = render_base_parameters(base, "latex")
    assert "\\input{x}" not in latex and r"\textbackslash{}input\{x\}\_\%" in latex
    data = json.loads(render_base_parameters(base, "json"))
    assert data["count"] == 6 and any("\u202e" in p["name"] for p in data["base_parameters"])
    with pytest.raises(robodyn.InputError, match="format"):
        render_base_parameters(base, "html")
