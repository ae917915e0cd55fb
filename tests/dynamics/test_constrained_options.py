"""Issue 39, the new physics crossed with every load option: constrained forward dynamics
(``v̇``, ``λ``) and the centroidal momentum against the reference given the same options, a
batch's rows against single calls, on a pairwise-covering set of (robot, gravity, floating
base, armature, lock, thread count, batch size) — each pair of values of any two options
in at least one case, not the full product (288 combinations). Each case's non-default
gravity and armature also serve as negative controls: the reference without them
disagrees, so the agreement is not one the option cannot change."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest

import robodyn
import robodyn.reference as reference
from robodyn.constraints import PointAnchor, PointContact
from robodyn.reference import constraints as reference_constraints
from tests.conftest import random_states
from tests.dynamics.test_centroidal import to_reference
from tests.pairwise import pairwise, uncovered_pairs

DATA = Path(__file__).resolve().parent.parent / "data"
#: Tilted gravity: in no plane of the mechanisms, and not along any of their axes.
OBLIQUE = (1.2, -9.7, 0.5)

#: Each robot: its file, its constraints, its armature, the joint a lock holds and where.
ROBOTS = {
    # the mimic arm (wrist = −1.5 elbow + 0.2): its tip pinned, its upper link on an
    # oblique frictionless plane
    "mimic_arm": (
        DATA / "mimic_arm.urdf",
        [
            PointAnchor("tip", (0.1, 0.02, 0.03), None, (0.3, 0.1, 0.2)),
            PointContact("upper", (0.05, 0.0, 0.0), normal=(0.3, -0.2, 1.0), friction=0.0, plane_point=(0, 0, 0.1)),
        ],
        {"shoulder": 0.3, "wrist": 0.2},  # the mimic joint's own armature included
        ("shoulder", 0.4),
    ),
    # a closed 3-D loop (the coupler's tip on the rocker's)
    "four_bar_3d": (
        DATA / "constraints" / "four_bar_3d.urdf",
        [PointAnchor("coupler", (0.33, 0.0, 0.0), "rocker", (0.28, 0.0, 0.0), name="loop")],
        {"crank_joint": 0.3, "rocker_joint": 0.2},
        ("coupler_joint", -0.7),
    ),
}

FACTORS: dict[str, list] = {
    "robot": list(ROBOTS),
    "gravity": [None, OBLIQUE],
    "floating_base": [False, True],
    "armature": [False, True],
    "lock": [False, True],
    "threads": [1, 2, 3],
    "batch": [1, 5, 7],
}


def valid(case: dict) -> bool:
    """The mimic arm's root link is massless: floating, its base's rotation is its shoulder's
    (a singular mass matrix, refused); with the shoulder locked the base carries the upper arm."""
    return not (case.get("robot") == "mimic_arm" and case.get("floating_base") and case.get("lock") is False)


CASES = pairwise(FACTORS, valid)


def load_options(case: dict) -> dict:
    """The options ``robodyn.load`` and ``robodyn.reference.load`` share for a case."""
    _, _, armature, (joint, value) = ROBOTS[case["robot"]]
    options: dict = {"floating_base": case["floating_base"]}
    if case["gravity"] is not None:
        options["gravity"] = case["gravity"]
    if case["armature"]:
        options["armature"] = armature
    if case["lock"]:
        options["lock"] = {joint: value}
    return options


def reference_terms(robot, model, constraints, q, v, tau):
    """The reference's ``v̇`` (in the robot's joint order), ``λ`` and centroidal momentum."""
    q_ref, v_ref = to_reference(robot, model, q, v)
    _, tau_ref = to_reference(robot, model, q, tau)
    a_ref, lam_ref = reference_constraints.constrained_forward_dynamics(model, q_ref, v_ref, tau_ref, constraints)
    base = 6 if robot.floating_base else 0
    theirs = model.joint_names[1 if base else 0 :]
    order = [theirs.index(name) for name in robot.joint_names[1 if base else 0 :]]
    a_mine = np.concatenate([a_ref[..., :base], a_ref[..., base:][..., order]], axis=-1)
    return a_mine, lam_ref, model.centroidal_momentum(q_ref, v_ref)


def test_the_pairwise_set_covers_every_pair_of_the_valid_combinations():
    every = [dict(zip(FACTORS, values, strict=True)) for values in itertools.product(*FACTORS.values())]
    possible = {(a, repr(c[a]), b, repr(c[b])) for c in every if valid(c) for a, b in itertools.combinations(FACTORS, 2)}
    missing = {(a, repr(x), b, repr(y)) for a, x, b, y in uncovered_pairs(CASES, FACTORS)}
    assert not (missing & possible)
    assert len(CASES) <= 14 and all(valid(case) for case in CASES)


@pytest.mark.parametrize("case", CASES, ids=lambda case: "-".join(f"{key}={value}" for key, value in case.items()))
def test_constrained_dynamics_and_momentum_agree_with_the_reference_under_every_option(case):
    source, constraints, _, _ = ROBOTS[case["robot"]]
    options = load_options(case)
    robot = robodyn.load(source, constraints=constraints, threads=case["threads"], **options)
    model = reference.load(source, **options)
    q, v, tau = random_states(robot, np.random.default_rng(39 + len(CASES)), case["batch"])
    a, lam = robot.constrained_forward_dynamics(q, v, tau)
    momentum = robot.centroidal_momentum(q, v)
    assert a.shape == (case["batch"], robot.nv) and lam.shape == (case["batch"], len(lam[0]))
    a_ref, lam_ref, momentum_ref = reference_terms(robot, model, constraints, q, v, tau)
    scale = max(1.0, float(np.abs(a_ref).max()), float(np.abs(lam_ref).max()))
    np.testing.assert_allclose(a, a_ref, rtol=0, atol=1e-8 * scale)
    np.testing.assert_allclose(lam, lam_ref, rtol=0, atol=1e-8 * scale)
    np.testing.assert_allclose(momentum, momentum_ref, rtol=0, atol=1e-12 * max(1.0, float(np.abs(momentum).max())))
    for row in {0, case["batch"] // 2, case["batch"] - 1}:  # a row of the batch is its single call
        a_one, lam_one = robot.constrained_forward_dynamics(q[row], v[row], tau[row])
        np.testing.assert_allclose(a_one, a[row], rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(lam_one, lam[row], rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(robot.centroidal_momentum(q[row], v[row]), momentum[row], rtol=0, atol=1e-13)
    # negative controls: the reference without this case's gravity or armature disagrees
    for dropped in ("gravity", "armature"):
        if dropped in options:
            other = reference.load(source, **{key: value for key, value in options.items() if key != dropped})
            a_other, lam_other, _ = reference_terms(robot, other, constraints, q[:2], v[:2], tau[:2])
            assert max(np.abs(a[:2] - a_other).max(), np.abs(lam[:2] - lam_other).max()) > 1e-4 * scale, dropped


FEET = ["FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"]
TILTED = np.array([1.5, -0.8, -9.6])


def test_contact_inverse_dynamics_obeys_newton_and_euler_under_tilted_gravity_and_armature():
    """solo12 on four sticking feet, gravity tilted, 7 random states at rest (``v = 0``) with
    random accelerations, three threads: the feet's forces sum to ``m c̈ − m g`` and their
    moment about the centre of mass is ``ḣ_G`` (``m c̈`` and ``ḣ_G``: the centroidal momentum
    matrix times ``a``); armature changes the joints' torques by ``armature · a`` and not
    the forces (the base's rows carry none). Negative controls: the default gravity, or the
    moment about the origin, break the laws."""
    feet = [PointContact(foot, friction=0.7) for foot in FEET]
    armature = {
        f"{leg}_{part}": 0.01 * (i + 1)
        for i, (leg, part) in enumerate(itertools.product(("FL", "FR", "HL", "HR"), ("HAA", "HFE", "KFE")))
    }
    robot = robodyn.load("solo12", gravity=TILTED, threads=3, armature=armature, constraints=feet)
    bare = robodyn.load("solo12", gravity=TILTED)
    rng = np.random.default_rng(7)
    q, _, a = random_states(robot, rng, 7)
    v = np.zeros_like(a)
    tau, lam = robot.contact_inverse_dynamics(q, v, a)
    tau_bare, lam_bare = bare.contact_inverse_dynamics(q, v, a, feet)
    mass = robot.total_mass
    rate = np.einsum("nij,nj->ni", robot.centroidal_momentum_matrix(q), a)  # (m c̈, ḣ_G) at v = 0
    forces = lam.reshape(7, 4, 3)
    weight = mass * float(np.linalg.norm(TILTED))
    np.testing.assert_allclose(forces.sum(axis=1), rate[:, :3] - mass * TILTED, rtol=0, atol=1e-9 * weight)
    com = robot.center_of_mass(q)
    points = np.array([[robot.frame_position(qi, foot) for foot in FEET] for qi in q])
    moment = np.cross(points - com[:, None], forces).sum(axis=1)
    np.testing.assert_allclose(moment, rate[:, 3:], rtol=0, atol=1e-9 * weight)
    np.testing.assert_allclose(lam, lam_bare, rtol=0, atol=1e-9 * weight)
    np.testing.assert_allclose(
        tau - tau_bare, np.concatenate([np.zeros((7, 6)), a[:, 6:] * robot.joint_armature[6:]], axis=1), atol=1e-9
    )
    assert np.all(tau[:, :6] == 0.0)
    tau_one, lam_one = robot.contact_inverse_dynamics(q[5], v[5], a[5])
    np.testing.assert_allclose(tau_one, tau[5], rtol=0, atol=1e-12 * weight)
    np.testing.assert_allclose(lam_one, lam[5], rtol=0, atol=1e-12 * weight)
    # negative controls
    default = np.array([0.0, 0.0, -9.81])
    assert np.abs(forces.sum(axis=1) - (rate[:, :3] - mass * default)).max() > 0.1 * mass
    about_origin = np.cross(points, forces).sum(axis=1)
    assert np.abs(about_origin - rate[:, 3:]).max() > 0.01 * weight
