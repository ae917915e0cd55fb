"""Issue 42, the whole-body controller on contacts: solo12 standing on four sticking feet
(simulated as bilateral contacts; the measured forces are the constraints' ``λ``). Laws:
the feet carry ``m g`` at rest, every foot force stays inside its friction cone, the base
returns to its pose after a kick, a commanded 2 cm sideways shift of the centre of mass is
reached; the negative control drops the cone from the QP and its forces leave the cone."""

from __future__ import annotations

from functools import cache
from pathlib import Path

import numpy as np
import pytest

import robodyn
from robodyn.constraints import PointContact
from robodyn.exceptions import InputError
from robodyn.sim.constrained import simulate_constrained
from robodyn.sim.whole_body import Stand, friction_cone_margin, support_margin, support_polygon

FEET = ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")
DATA = Path(__file__).parents[1] / "data" / "contact"
LEGS = np.array([0.0, 0.8, -1.6, 0.0, 0.8, -1.6, 0.0, -0.8, 1.6, 0.0, -0.8, 1.6])
GRAVITY = 9.81


@cache
def standing(friction: float = 0.7) -> tuple[robodyn.Robot, np.ndarray, tuple[PointContact, ...]]:
    """solo12 with its feet on the ground ``z = 0``, at rest, base level at 0.3 m above them."""
    robot = robodyn.load("solo12")
    q = robot.floating_configuration([0.0, 0.0, 0.3], [0.0, 0.0, 0.0], LEGS)
    height = np.mean([robot.frame_position(q, foot)[2] for foot in FEET])
    q = robot.floating_configuration([0.0, 0.0, 0.3 - height], [0.0, 0.0, 0.0], LEGS)
    feet = tuple(PointContact(foot, friction=friction, plane_point=(0, 0, 0)) for foot in FEET)
    return robot, q, feet


def kicked(robot: robodyn.Robot) -> np.ndarray:
    v = np.zeros(robot.nv)
    v[:6] = [0.05, -0.03, 0.02, 0.1, 0.2, -0.1]  # projected onto the feet's constraints by the simulation
    return v


def test_at_rest_the_qps_forces_carry_the_weight_inside_the_cones_and_are_what_the_robot_feels():
    robot, q, feet = standing()
    control = Stand(robot, feet, robot.center_of_mass(q), np.eye(3), q)
    zero = np.zeros(robot.nv)
    acceleration, _, forces = control.solve(q, zero)
    weight = robot.total_mass * GRAVITY
    assert abs(forces.reshape(4, 3)[:, 2].sum() - weight) <= 1e-6 * weight
    assert (friction_cone_margin(feet, forces) > 0).all()
    assert np.abs(acceleration).max() <= 1e-6
    # the torques it returns, applied to the robot on its feet: the forces the QP planned
    felt_acceleration, multipliers = robot.constrained_forward_dynamics(q, zero, control(0.0, q, zero), feet)
    np.testing.assert_allclose(multipliers, forces, atol=1e-6 * weight)
    assert np.abs(felt_acceleration).max() <= 1e-6


def test_a_short_kicked_stand_keeps_every_foot_force_inside_its_cone():
    robot, q, feet = standing()
    control = Stand(robot, feet, robot.center_of_mass(q), np.eye(3), q)
    run = simulate_constrained(robot, q, kicked(robot), constraints=feet, duration=0.1, dt=2e-3, tau=control)
    assert friction_cone_margin(feet, run.multipliers).min() > 0
    assert run.residual.max() <= 1e-12


def test_without_the_cone_in_the_qp_the_forces_leave_the_cone():
    """Negative control: a hard sideways push of the centre of mass on slippery ground
    (μ = 0.1): the QP with the cones keeps the forces inside them, the one without does not."""
    robot, q, feet = standing(friction=0.1)
    target = robot.center_of_mass(q) + np.array([0.0, 0.05, 0.0])
    zero = np.zeros(robot.nv)
    with_cone = Stand(robot, feet, target, np.eye(3), q).solve(q, zero)[2]
    without = Stand(robot, feet, target, np.eye(3), q, margin=None).solve(q, zero)[2]
    assert friction_cone_margin(feet, with_cone).min() >= -1e-9
    assert friction_cone_margin(feet, without).min() < -0.1


@pytest.mark.slow
def test_solo12_kicked_returns_to_its_pose_and_carries_its_weight_at_rest():
    robot, q, feet = standing()
    control = Stand(robot, feet, robot.center_of_mass(q), np.eye(3), q)
    run = simulate_constrained(robot, q, kicked(robot), constraints=feet, duration=2.0, dt=2e-3, tau=control)
    last = run.trajectory.q[-1]
    assert np.abs(last[:3] - q[:3]).max() < 1e-6
    attitude = robot.floating_configuration([0, 0, 0], [0, 0, 0], LEGS)[3:7]
    assert 2 * np.arccos(min(1.0, abs(float(last[3:7] @ attitude)))) < 1e-6
    weight = robot.total_mass * GRAVITY
    assert abs(run.multipliers[-1].reshape(4, 3)[:, 2].sum() - weight) <= 1e-6 * weight
    assert friction_cone_margin(feet, run.multipliers).min() > 0


@pytest.mark.slow
def test_a_two_centimetre_sideways_shift_of_the_centre_of_mass_is_reached():
    robot, q, feet = standing()
    target = robot.center_of_mass(q) + np.array([0.0, 0.02, 0.0])
    control = Stand(robot, feet, target, np.eye(3), q)
    run = simulate_constrained(robot, q, constraints=feet, duration=2.0, dt=2e-3, tau=control)
    assert np.abs(robot.center_of_mass(run.trajectory.q[-1]) - target).max() < 1e-4
    assert friction_cone_margin(feet, run.multipliers).min() > 0


def test_a_fixed_robot_or_a_contact_that_slides_is_refused():
    robot, q, feet = standing()
    with pytest.raises(InputError, match="model"):
        Stand(robodyn.load("ur5"), feet, np.zeros(3), np.eye(3), np.zeros(6))
    sliding = [PointContact("FL_FOOT", friction=0.0)]
    with pytest.raises(InputError, match="contacts"):
        Stand(robot, sliding, np.zeros(3), np.eye(3), q)
    with pytest.raises(InputError, match="orientation"):
        Stand(robot, feet, np.zeros(3), 2 * np.eye(3), q)


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("com", "north"),
        ("com", [0.0, np.nan, 0.0]),
        ("orientation", "up"),
        ("kp", -1.0),
        ("kd", "x"),
        ("weights", (1.0, -1.0, 0.0)),
        ("margin", 2.0),
        ("torque_limit", [1.0, 2.0]),
    ],
)
def test_hostile_targets_and_gains_are_refused_in_one_sentence(field, value):
    robot, q, feet = standing()
    arguments = {"com": np.zeros(3), "orientation": np.eye(3)}
    options = {}
    if field in arguments:
        arguments[field] = value
    else:
        options[field] = value
    with pytest.raises(InputError, match=field):
        Stand(robot, feet, arguments["com"], arguments["orientation"], q, **options)


def test_the_support_polygon_is_the_feet_seen_from_above_and_a_target_outside_it_is_refused():
    robot, q, feet = standing()
    polygon = support_polygon(robot, q, feet)
    feet_xy = np.array([robot.frame_position(q, foot)[:2] for foot in FEET])
    assert len(polygon) == 4
    assert all(np.abs(polygon - foot).sum(axis=1).min() < 1e-12 for foot in feet_xy)
    area = 0.5 * np.sum(polygon[:, 0] * np.roll(polygon[:, 1], -1) - np.roll(polygon[:, 0], -1) * polygon[:, 1])
    assert area > 0  # counter-clockwise seen from above
    half_width = feet_xy[:, 1].max()
    centre = robot.center_of_mass(q)
    assert support_margin(robot, q, feet, centre) == pytest.approx(min(half_width - centre[1], half_width + centre[1]), abs=1e-3)
    assert support_margin(robot, q, feet, centre + np.array([0.0, 2 * half_width, 0.0])) < 0
    with pytest.raises(InputError, match="outside"):
        Stand(robot, feet, centre + np.array([0.0, 2 * half_width, 0.0]), np.eye(3), q)
    with pytest.raises(InputError, match="polygon"):
        Stand(robot, feet[:2], centre, np.eye(3), q)


def push_run(margin: float | None):
    """solo12 standing, pushed sideways at its base with 8 N from 0.1 s to 0.3 s (the
    controller does not know): 1.2 s at 2 ms."""
    robot, q, feet = standing()
    control = Stand(robot, feet, robot.center_of_mass(q), np.eye(3), q, margin=margin)
    push = np.array([0.0, 8.0, 0.0, 0.0, 0.0, 0.0])

    def pushed(t: float, qi: np.ndarray, vi: np.ndarray) -> np.ndarray:
        tau = control(t, qi, vi)
        return tau + robot.wrench_torques(qi, "base_link", push) if 0.1 <= t < 0.3 else tau

    return robot, q, feet, simulate_constrained(robot, q, constraints=feet, duration=1.2, dt=2e-3, tau=pushed)


@pytest.mark.slow  # two 1.2 s runs, about a minute
def test_a_pushed_robot_recovers_with_its_feet_inside_their_cones_and_without_the_cone_they_would_slip():
    """With sticking (bilateral) feet, a foot slips exactly where its force would have to
    leave its cone. (20 N, the issue's push, is more than solo12's feet can carry sideways:
    μ m g = 0.7 × 2.5 kg × 9.81 = 17 N.)"""
    robot, q, feet, run = push_run(0.9)
    assert friction_cone_margin(feet, run.multipliers).min() > 0
    moved = np.abs(robot.center_of_mass(run.trajectory.q) - robot.center_of_mass(q)).max()
    assert moved > 0.01  # the push did move it
    assert np.abs(robot.center_of_mass(run.trajectory.q[-1]) - robot.center_of_mass(q)).max() < 1e-4
    _, _, _, loose = push_run(None)
    assert friction_cone_margin(feet, loose.multipliers).min() < -0.1


@pytest.mark.slow
def test_anymal_under_tilted_gravity_stands_and_its_feet_carry_minus_m_g():
    """Another quadruped (30 kg), gravity (0.3, −0.2, −9.7): the feet's forces sum to
    ``−m g`` at rest (a sideways part the friction carries), inside their cones."""
    robot = robodyn.load("anymal", gravity=(0.3, -0.2, -9.7))
    legs = np.array([0.0, 0.6, -1.0, 0.0, -0.6, 1.0, 0.0, 0.6, -1.0, 0.0, -0.6, 1.0])
    names = ("LF_FOOT", "LH_FOOT", "RF_FOOT", "RH_FOOT")
    q = robot.floating_configuration([0.0, 0.0, 0.6], [0.0, 0.0, 0.0], legs)
    height = np.mean([robot.frame_position(q, foot)[2] for foot in names])
    q = robot.floating_configuration([0.0, 0.0, 0.6 - height], [0.0, 0.0, 0.0], legs)
    feet = [PointContact(foot, friction=0.8) for foot in names]
    control = Stand(robot, feet, robot.center_of_mass(q), np.eye(3), q)
    run = simulate_constrained(robot, q, kicked(robot), constraints=feet, duration=2.0, dt=2e-3, tau=control)
    weight = robot.total_mass * np.linalg.norm(robot.gravity_vector)
    total = run.multipliers[-1].reshape(4, 3).sum(axis=0)
    assert np.abs(total + robot.total_mass * robot.gravity_vector).max() <= 1e-6 * weight
    assert np.abs(run.trajectory.q[-1, :3] - q[:3]).max() < 1e-6
    assert friction_cone_margin(feet, run.multipliers).min() > 0


def push_on_the_ground(margin: float | None):
    """solo12 on the ground (unilateral contacts, Coulomb μ = 0.7: docs/contact.md), pushed
    sideways at the base with 8 N from 0.1 s to 0.3 s by ``robodyn.simulate``'s external
    wrench (the sequel's push: the controller does not know)."""
    from robodyn.sim.ground import Ground
    from robodyn.sim.simulation import simulate_run

    robot, q, feet = standing()
    control = Stand(robot, feet, robot.center_of_mass(q), np.eye(3), q, margin=margin)
    push = robodyn.ExternalWrench("base_link", lambda t: np.array([0.0, 8.0, 0.0]) if 0.1 <= t < 0.3 else np.zeros(3))
    trajectory, run = simulate_run(
        robot,
        q,
        np.zeros(robot.nv),
        1.2,
        1e-3,
        controller=control,
        ground=Ground(friction=0.7),
        contacts=list(FEET),
        external=[push],
    )
    soles = np.array([[robot.frame_position(qi, foot)[:2] for foot in FEET] for qi in trajectory.q[::10]])
    return robot, q, run.contact, float(np.abs(soles - soles[0]).max())


@pytest.mark.slow  # two 1.2 s contact runs, about 15 s
def test_on_real_ground_a_pushed_robot_recovers_without_a_foot_slipping_and_without_the_cone_a_foot_slips():
    robot, q, run, travelled = push_on_the_ground(0.9)
    assert run.active.all() and run.converged.all()
    assert np.where(run.active, run.slip, 0.0).max() < 1e-9  # [m/s]
    assert travelled < 1e-5  # [m]
    assert np.abs(robot.center_of_mass(run.trajectory.q[-1]) - robot.center_of_mass(q)).max() < 1e-4
    _, _, loose, slid = push_on_the_ground(None)
    assert np.where(loose.active, loose.slip, 0.0).max() > 0.1 and slid > 5e-3


def _independent_margin(points: np.ndarray, up: np.ndarray, point: np.ndarray) -> float:
    """The signed distance of ``point`` inside the hull of ``points`` seen along ``up``, by
    SciPy's hull in a basis of the plane normal to ``up`` of this test's own choosing."""
    from scipy.spatial import ConvexHull

    first = np.cross(up, [0.3, 0.5, 0.7])
    first /= np.linalg.norm(first)
    basis = np.stack([first, np.cross(up, first)])
    flat, target = points @ basis.T, basis @ point
    corners = flat[ConvexHull(flat).vertices]  # counter-clockwise
    edges = np.roll(corners, -1, axis=0) - corners
    cross = edges[:, 0] * (target - corners)[:, 1] - edges[:, 1] * (target - corners)[:, 0]
    return float(np.min(cross / np.linalg.norm(edges, axis=1)))


@pytest.mark.parametrize("turned", [False, True])
@pytest.mark.parametrize("gravity", [(0.0, 0.0, -9.81), (-9.81, 0.0, 0.0), (0.0, 9.81, 0.0), (-3.0, 1.0, -9.0)])
def test_the_support_polygon_and_margin_are_scipys_hull_seen_along_any_gravity(gravity, turned):
    """Six feet on a floating box (one inside the others' hull, one on an edge): the
    polygon is their hull seen along gravity (four corners: neither the inner foot nor the
    one on an edge), counter-clockwise, in world x, y for gravity along −z; the margin of
    points in and out is SciPy's hull's signed distance in a basis of this test's own; three
    feet make a polygon too (a triangle). Gravity along ±x and ±y takes the axes' other seed.
    Off the world's axes the foot on an edge is so only to round-off (kept or not): the margins alone."""
    box = robodyn.load(DATA / "box.urdf", floating_base=True, gravity=gravity)
    q = box.neutral_configuration()
    if turned:  # the feet's world points are no local ones
        q[3:7] = [0.1, -0.2, 0.3, np.sqrt(1 - 0.14)]
    up = -np.asarray(gravity) / np.linalg.norm(gravity)
    seed = np.cross(up, [0.6, 0.0, 0.8])
    axes = np.stack([seed / np.linalg.norm(seed), np.cross(up, seed / np.linalg.norm(seed))])  # in the feet's plane
    if gravity == (0.0, 0.0, -9.81):
        axes = np.eye(3)[:2]  # world x, y
    flat = [(0.2, 0.1), (-0.2, 0.1), (-0.2, -0.1), (0.25, -0.15), (0.0, 0.0), (0.0, 0.1)]  # the last two inside, on an edge
    world = np.array([np.array(xy) @ axes - 0.05 * up for xy in flat])
    local = (world - box.frame_position(q, "box")) @ _rotation_of(q)  # Rᵀ (p − o), a row each
    feet = tuple(PointContact("box", tuple(point)) for point in local)
    polygon = support_polygon(box, q, feet)
    assert turned or gravity != (0.0, 0.0, -9.81) or len(polygon) == 4  # (exactly on an edge only there)
    area = 0.5 * np.sum(polygon[:, 0] * np.roll(polygon[:, 1], -1) - np.roll(polygon[:, 0], -1) * polygon[:, 1])
    assert area > 0  # counter-clockwise
    if gravity == (0.0, 0.0, -9.81):
        assert all(np.abs(polygon - xy).sum(axis=1).min() < 1e-12 for xy in world[:4, :2])
    for point in ([0.01, 0.02, 0.3], [0.5, -0.1, 0.0], [-0.1, 0.3, -0.2]):
        margin = support_margin(box, q, feet, np.array(point))
        assert abs(margin - _independent_margin(world, up, np.array(point))) < 1e-12
        three = support_margin(box, q, feet[:3], np.array(point))
        assert abs(three - _independent_margin(world[:3], up, np.array(point))) < 1e-12


def _rotation_of(q: np.ndarray) -> np.ndarray:
    import pinocchio as pin

    return pin.Quaternion(q[6], q[3], q[4], q[5]).toRotationMatrix()


def test_the_contact_tangents_are_unit_orthogonal_and_right_handed_about_any_normal():
    """The cones' tangent rows (``_tangents``): for a floor, walls along x and y, and an
    oblique plane, two unit vectors normal to ``n`` and to each other with ``t₁ × t₂ = n``."""
    from robodyn.sim.whole_body import _tangents

    for normal in (
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 0.0],
        [0.0, -1.0, 0.0],
        np.array([0.3, -0.2, 0.9]) / np.linalg.norm([0.3, -0.2, 0.9]),
    ):
        tangents = _tangents(np.asarray(normal, float))
        assert np.abs(tangents @ tangents.T - np.eye(2)).max() < 1e-15 and np.abs(tangents @ normal).max() < 1e-15
        assert np.abs(np.cross(*tangents) - normal).max() < 1e-15


def test_an_orientation_that_is_no_rotation_is_refused_in_one_sentence_and_a_rotation_is_kept():
    robot, q, feet = standing()
    centre, start = robot.center_of_mass(q), "orientation must be a rotation matrix (3, 3), got "
    ragged = [[1.0] * 40, [2.0]]
    for value, received in (
        ("eye", "'eye'"),
        (ragged, repr(ragged)[:80]),
        (1.001 * np.eye(3), "an array of shape (3, 3), not a rotation"),
        (np.diag([1.0, 1.0, -1.0]), "an array of shape (3, 3), not a rotation"),  # a reflection
        (np.eye(3) + np.diag([5e-9, 0.0], 1), "an array of shape (3, 3), not a rotation"),  # R Rᵀ off by 5e-9
        (np.eye(2), "an array of shape (2, 2), not a rotation"),
    ):
        with pytest.raises(InputError) as caught:
            Stand(robot, feet, centre, value, q)
        assert str(caught.value) == start + received + "." and caught.value.argument == "orientation"
    turned = _rotation_of(np.r_[np.zeros(3), 0.1, -0.2, 0.3, np.sqrt(1 - 0.14)])
    assert np.abs(Stand(robot, feet, centre, turned.tolist(), q).orientation - turned).max() == 0.0


def test_a_call_keeps_the_qps_contact_forces_which_carry_the_weight_and_prints_nothing(capfd):
    robot, q, feet = standing()
    control = Stand(robot, feet, robot.center_of_mass(q), np.eye(3), q)
    tau = control(0.0, q, np.zeros(robot.nv))
    forces = control.last_forces.reshape(-1, 3)
    assert abs(forces[:, 2].sum() / (robot.total_mass * 9.81) - 1) < 1e-6 and np.abs(tau[:6]).max() == 0.0
    assert capfd.readouterr() == ("", "")  # the solver's log stays off


def test_the_qps_acceleration_makes_the_centre_of_mass_and_attitude_follow_their_pd_laws():
    """solo12 moving (its base turned 0.1 rad, every joint and the base with a velocity), the
    posture's weight 0: the QP's ``v̇`` gives ``c̈ = Kp (c_d − c) − Kd ċ`` and
    ``ω̇ = Kp log(R_d Rᵀ) − Kd ω`` (world axes), both read by central differences of the
    motion ``q ⊕ (v t + v̇ t²/2)`` (the centre of mass and the base's rotation, not the QP's
    rows); the feet, moving, do not accelerate. Negative control: the laws with ``+Kd`` are
    off by ``2 Kd ċ``, ``2 Kd ω``."""
    import pinocchio as pin

    robot, q, feet = standing()
    start = robot.floating_configuration(list(q[:3]), [0.05, -0.08, 0.04], list(q[7:]))
    v = np.r_[0.03, -0.02, 0.01, 0.2, -0.1, 0.15, np.linspace(-0.3, 0.3, robot.nv - 6)]
    target = robot.center_of_mass(q) + np.array([0.01, -0.005, 0.004])
    stand = Stand(robot, feet, target, np.eye(3), q, kp=100.0, kd=20.0, weights=(1.0, 1.0, 0.0))
    acceleration = stand.solve(start, v)[0]
    h = 1e-4

    def at(t: float) -> np.ndarray:
        return pin.integrate(robot.model, start, v * t + 0.5 * acceleration * t**2)

    centres = [robot.center_of_mass(at(t)) for t in (-h, 0.0, h)]
    velocity, com_acceleration = (centres[2] - centres[0]) / (2 * h), (centres[2] - 2 * centres[1] + centres[0]) / h**2
    rotations = [_rotation_of(at(t)) for t in (-h, 0.0, h)]
    ahead, behind = pin.log3(rotations[2] @ rotations[1].T), pin.log3(rotations[1] @ rotations[0].T)
    omega, omega_dot = (ahead + behind) / (2 * h), (ahead - behind) / h**2
    com_law = 100.0 * (target - centres[1]) - 20.0 * velocity
    attitude_law = 100.0 * pin.log3(rotations[1].T) - 20.0 * omega
    assert np.abs(com_acceleration - com_law).max() < 1e-5 * np.abs(com_law).max()
    assert np.abs(omega_dot - attitude_law).max() < 1e-5 * np.abs(attitude_law).max()
    assert np.abs(com_acceleration - (com_law + 40.0 * velocity)).max() > 0.1 * np.abs(com_law).max()  # the negative control
    for foot in FEET:  # the feet do not accelerate (Jc v̇ + J̇c v = 0), though they move
        points = [robot.frame_position(at(t), foot) for t in (-h, 0.0, h)]
        assert np.abs(points[2] - 2 * points[1] + points[0]).max() / h**2 < 1e-5 < np.abs(points[2] - points[0]).max() / (2 * h)
    assert np.abs(omega_dot - (attitude_law + 40.0 * omega)).max() > 0.1 * np.abs(attitude_law).max()


def test_torque_limits_that_bind_hold_exactly_on_both_sides_and_slack_ones_leave_the_stand_at_rest():
    """solo12 at rest with every joint limited to half the largest torque the unlimited QP
    asks: the torques reach the limit on both sides and never pass it (the tasks then give
    way: the base accelerates); limited to twice that torque (slack), the QP holds the robot
    at rest as without limits."""
    robot, q, feet = standing()
    centre, rest = robot.center_of_mass(q), np.zeros(robot.nv)
    largest = np.abs(Stand(robot, feet, centre, np.eye(3), q).solve(q, rest)[1]).max()
    acceleration, torques, _ = Stand(robot, feet, centre, np.eye(3), q, torque_limit=0.5 * largest).solve(q, rest)
    ratio = torques / (0.5 * largest)
    assert ratio.max() <= 1 + 1e-9 and ratio.min() >= -1 - 1e-9  # never past it
    assert ratio.max() > 1 - 1e-6 and ratio.min() < -1 + 1e-6  # reached on both sides
    assert np.abs(acceleration).max() > 1.0  # the tasks gave way
    slack = Stand(robot, feet, centre, np.eye(3), q, torque_limit=2.0 * largest).solve(q, rest)
    assert np.abs(slack[0]).max() < 1e-6 and np.abs(slack[1]).max() < 2.0 * largest


def test_a_qp_without_solution_is_refused_in_one_sentence_naming_the_state():
    """Feet of friction 0.01 and torques of at most 1 mN m: no force in the cones carries
    solo12 (the negative control: the same feet with the model's torques can)."""
    robot, q, feet = standing(0.01)
    rest = np.zeros(robot.nv)
    with pytest.raises(InputError) as caught:
        Stand(robot, feet, robot.center_of_mass(q), np.eye(3), q, torque_limit=1e-3).solve(q, rest)
    assert str(caught.value) == (
        "q must be a state from which the contacts can carry the robot within their cones and torque limits, "
        "got a QP PrimalInfeasible (a leg stretched, a push beyond friction)."
    )
    assert np.abs(Stand(robot, feet, robot.center_of_mass(q), np.eye(3), q).solve(q, rest)[0]).max() < 1e-6


def test_without_clarabel_the_stand_names_the_extra_to_install(monkeypatch):
    import sys

    from robodyn.exceptions import MissingExtraError

    robot, q, feet = standing()
    stand = Stand(robot, feet, robot.center_of_mass(q), np.eye(3), q)
    for module in ("clarabel", "scipy.sparse"):
        with monkeypatch.context() as patch:
            patch.setitem(sys.modules, module, None)  # its import fails
            with pytest.raises(MissingExtraError) as caught:
                stand.solve(q, np.zeros(robot.nv))
        assert str(caught.value) == (
            f"the whole-body controller's QP need {module!r}, which is not installed: the 'robodyn[ident]' extra "
            "(pip install '.[ident]' in a clone of robodyn)."
        )
