"""Contact simulation against physical laws: a box at rest, on slopes, sliding to a stop; solo12 standing."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import robodyn
from robodyn.exceptions import InputError, RobodynError
from robodyn.sim import contact
from robodyn.sim.contact import ContactSettings
from robodyn.sim.contact_run import free_fall_note, simulate_contact
from robodyn.sim.ground import ContactPoint, Ground, contact_points
from robodyn.trajectory.columns import contact_columns
from robodyn.viz.recording import motion_commands

DATA = Path(__file__).parents[1] / "data" / "contact"
G = 9.81
MASS = 2.5  # tests/data/contact/box.urdf
HALF_HEIGHT = 0.05


@pytest.fixture(scope="module")
def box() -> robodyn.Robot:
    return robodyn.load(DATA / "box.urdf", floating_base=True)


def _on_slope(box: robodyn.Robot, ground: Ground, lift: float = 0.0, v0: np.ndarray | None = None) -> np.ndarray:
    """The box resting flat on ``ground`` (its bottom face on the plane, raised by ``lift``)."""
    n = np.array(ground.normal)
    angle = math.atan2(n[0], n[2])
    q = box.neutral_configuration()
    q[:3] = ground.point + (HALF_HEIGHT + lift) * n
    q[3:7] = (0.0, math.sin(angle / 2), 0.0, math.cos(angle / 2))  # x, y, z, w: about y
    return q


def _energy(box: robodyn.Robot, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    return np.array([box.kinetic_energy(qi, vi) + box.potential_energy(qi) for qi, vi in zip(q, v, strict=True)])


def test_a_box_dropped_flat_comes_to_rest_carrying_its_weight(box):
    ground = Ground(friction=0.5)
    run = simulate_contact(box, ground=ground, duration=0.5, dt=1e-3, q0=_on_slope(box, ground, lift=0.2))
    total = run.normal_forces.sum(axis=1)
    assert abs(total[-1] / (MASS * G) - 1) < 1e-6
    assert run.active[-1].sum() == 4  # the four bottom corners
    assert -run.gaps.min() < 1e-9  # speculative contact: no penetration on a flat landing
    assert np.abs(run.trajectory.v[-1]).max() < 1e-9
    landed = int(np.argmax(total > 0))
    energy = _energy(box, run.trajectory.q, run.trajectory.v)[landed:]
    assert np.all(np.diff(energy) <= 1e-9 * MASS * G)  # never increases after the impact
    assert energy[0] - energy[-1] > 0.5 * MASS * G * 0.19  # the impact took the fall's energy


def test_a_box_on_a_slope_below_the_friction_angle_stays_put(box):
    ground = Ground.tilted(math.radians(20), friction=0.5)  # atan(0.5) = 26.6°
    q0 = _on_slope(box, ground)
    run = simulate_contact(box, ground=ground, duration=0.3, dt=1e-3, q0=q0)
    assert np.abs(run.trajectory.q[-1, :3] - q0[:3]).max() < 1e-9
    total = run.forces[-1].sum(axis=0)
    assert np.allclose(total, (0, 0, MASS * G), rtol=0, atol=1e-6 * MASS * G)  # the plane carries the weight


@pytest.mark.parametrize(("degrees", "friction"), [(35.0, 0.5), (20.0, 0.0), (5.0, 0.0)])
def test_a_box_above_the_friction_angle_slides_with_g_sin_minus_mu_g_cos(box, degrees, friction):
    theta = math.radians(degrees)
    ground = Ground.tilted(theta, friction=friction)
    run = simulate_contact(box, ground=ground, duration=0.2, dt=1e-3, q0=_on_slope(box, ground))
    along = np.array([math.cos(theta), 0.0, -math.sin(theta)])  # down the slope
    position = run.trajectory.q[:, :3] @ along
    t = run.trajectory.t
    acceleration = np.polyfit(t[10:], position[10:], 2)[0] * 2
    expected = G * (math.sin(theta) - friction * math.cos(theta))
    assert abs(acceleration / expected - 1) < 1e-3
    assert abs(run.trajectory.q[:, :3] @ np.array(ground.normal) - HALF_HEIGHT).max() < 1e-9  # stays on the plane


def test_a_dropped_friction_row_breaks_the_slope_law(box, monkeypatch):
    theta, friction = math.radians(35.0), 0.5
    ground = Ground.tilted(theta, friction=friction)
    original = contact._local_jacobian
    monkeypatch.setattr(contact, "_local_jacobian", lambda axes, linear: original(axes, linear) * [[0.0], [1.0], [1.0]])
    run = simulate_contact(box, ground=ground, duration=0.2, dt=1e-3, q0=_on_slope(box, ground))
    along = np.array([math.cos(theta), 0.0, -math.sin(theta)])
    acceleration = np.polyfit(run.trajectory.t[10:], (run.trajectory.q[:, :3] @ along)[10:], 2)[0] * 2
    assert abs(acceleration / (G * (math.sin(theta) - friction * math.cos(theta))) - 1) > 0.1


def test_a_block_sliding_with_friction_stops_after_v_squared_over_two_mu_g(box):
    ground, speed, mu = Ground(friction=0.4), 1.5, 0.4
    v0 = np.zeros(box.nv)
    v0[0] = speed  # the base's linear velocity is in its own frame: flat, that is world x
    run = simulate_contact(box, ground=ground, duration=0.5, dt=1e-4, q0=_on_slope(box, ground), v0=v0)
    distance = run.trajectory.q[-1, 0]
    assert abs(distance / (speed**2 / (2 * mu * G)) - 1) < 1e-3
    assert abs(run.trajectory.v[-1]).max() < 1e-9


def test_a_floating_robot_with_no_ground_says_its_base_falls_freely(box):
    assert free_fall_note(box, None) == "no ground: the base falls freely"
    assert free_fall_note(box, Ground()) is None


@pytest.fixture(scope="module")
def solo_standing():
    robot = robodyn.load("solo12")
    feet = ["FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"]
    q0 = robot.neutral_configuration()
    gaps, _ = contact.contact_kinematics(robot, q0, Ground(), contact_points(robot, feet).points)
    q0[2] = -gaps.min() + 0.05  # feet 5 cm above the ground
    target = q0[7:].copy()

    def hold(t, q, v):
        tau = np.zeros(robot.nv)
        tau[6:] = 5.0 * (target - q[7:]) - 0.1 * v[6:]
        return tau

    ground = Ground(friction=0.8)
    return robot, ground, simulate_contact(robot, ground=ground, contacts=feet, controller=hold, duration=0.6, q0=q0)


def test_solo12_dropped_on_its_feet_settles_carrying_its_weight_inside_the_cones(solo_standing):
    robot, ground, run = solo_standing
    normal = run.normal_forces
    assert abs(normal[-1].sum() / (robot.total_mass * G) - 1) < 1e-6
    assert run.active[-1].all()
    tangential = np.linalg.norm(run.forces - normal[..., None] * np.array(ground.normal), axis=2)
    assert np.all(tangential <= ground.friction * normal + 1e-9 * robot.total_mass * G)
    assert np.abs(run.trajectory.v[-1]).max() < 1e-6
    assert -run.gaps.min() < 1e-6


def test_a_contact_run_saves_its_forces_as_columns_trajectory_readers_skip(box, tmp_path):
    ground = Ground(friction=0.5)
    run = simulate_contact(box, ground=ground, duration=0.05, dt=1e-3, q0=_on_slope(box, ground, lift=0.001))
    path = run.save(tmp_path / "box.csv")
    again = robodyn.Trajectory.load(path)
    assert np.array_equal(again.q, run.trajectory.q)
    lines = path.read_text().splitlines()
    header = next(csv.reader([lines[1]]))
    assert "f[box.box0.corner0].z" in header and "contact[box.box0.corner7]" in header
    forces, active = contact_columns(header, np.loadtxt(lines[2:], delimiter=","), run.contacts)
    assert np.array_equal(forces, run.forces) and np.array_equal(active, run.active)
    with pytest.raises(InputError, match="csv"):
        run.save(tmp_path / "box.npz")


def test_a_recording_draws_the_contact_forces_as_arrows(solo_standing, tmp_path):
    robot, _, run = solo_standing
    arrows = run.force_arrows()
    assert [arrow.frame for arrow in arrows] == ["FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"]
    total = sum(arrow.value(run.trajectory.t[-1]) for arrow in arrows)
    assert np.allclose(total, run.forces[-1].sum(axis=0))
    assert not arrows[0].value(0.0).any()  # in the air at the start
    commands, _, _ = motion_commands(robot, run.trajectory, forces=arrows)
    paths = [str(command.get("path", "")) for command in commands]
    assert any("force03" in path for path in paths) and not any("force04" in path for path in paths)  # one a foot


def test_a_mimic_arm_resting_its_tip_on_a_table_balances_gravity_with_the_contact_force():
    """Mimic joints (robodyn's M, which Pinocchio's constraint algorithms refuse), oblique gravity."""
    arm = robodyn.load(DATA.parent / "mimic_arm.urdf", gravity=(0.4, -0.3, -7.5))
    tip = ContactPoint("fingertip", "tip", (0.1, 0.0, 0.0))
    height = contact.contact_kinematics(arm, np.zeros(arm.nq), Ground(), (tip,))[0][0]
    ground = Ground(height=height - 0.03, friction=0.6)
    run = simulate_contact(
        arm, ground=ground, contacts=[tip], duration=1.0, q0=np.zeros(arm.nq), controller=lambda t, q, v: -0.5 * v
    )
    q, force = run.trajectory.q[-1], run.forces[-1, 0]
    _, jacobian = contact.contact_kinematics(arm, q, ground, (tip,))
    assert run.active[-1].all() and np.abs(run.trajectory.v[-1]).max() < 1e-9
    assert np.abs(arm.gravity(q) - jacobian.T @ (ground.frame() @ force)).max() < 1e-9  # G(q) = Jᵀ f at rest
    tangential = np.linalg.norm(force[:2])
    assert tangential <= 0.6 * force[2]


@pytest.mark.parametrize(
    ("arguments", "named"),
    [
        ({"dt": 0.0}, "dt"),
        ({"duration": -1.0}, "duration"),
        ({"ground": "floor"}, "ground"),
        ({"controller": lambda t, q, v: np.zeros(3)}, "controller"),
        ({"q0": np.zeros((2, 7))}, "q0"),
        ({"contacts": []}, "contacts"),
    ],
)
def test_impossible_contact_runs_are_refused_by_name(box, arguments, named):
    options = {"ground": Ground(), "duration": 0.01, "dt": 1e-3} | arguments
    with pytest.raises(RobodynError, match=named):
        simulate_contact(box, **options)


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore:anymal:UserWarning")  # its file's base inertia (reported by loading)
def test_anymal_stands_on_its_four_collision_sphere_feet():
    robot = robodyn.load("anymal")
    feet = tuple(point for point in contact_points(robot, "collision").points if point.radius > 0)
    assert [point.link for point in feet] == ["LF_FOOT", "RF_FOOT", "LH_FOOT", "RH_FOOT"]
    q0 = robot.neutral_configuration()
    q0[2] = -contact.contact_kinematics(robot, q0, Ground(), feet)[0].min() + 0.05
    target = q0[7:].copy()

    def hold(t, q, v):
        tau = np.zeros(robot.nv)
        tau[6:] = 200.0 * (target - q[7:]) - 5.0 * v[6:]
        return tau

    run = simulate_contact(robot, ground=Ground(friction=0.8), contacts=feet, controller=hold, duration=2.0, q0=q0)
    assert abs(run.normal_forces[-1].sum() / (robot.total_mass * G) - 1) < 1e-6
    assert np.abs(run.gaps[-1]).max() < 1e-9  # each sphere resting on the plane


def test_the_polished_steps_agree_with_pinocchios_admm_alone_at_a_tight_tolerance():
    """solo12 landing from a bent pose with μ = 0.5 (feet slipping up to 0.5 m/s)."""
    robot = robodyn.load("solo12")
    feet = ["FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"]
    q0 = robot.neutral_configuration()
    q0[2], q0[7:] = 0.37, q0[7:] + 0.1 * np.sin(np.arange(12))
    target = q0[7:].copy()

    def hold(t, q, v):
        return np.r_[np.zeros(6), 5.0 * (target - q[7:]) - 0.1 * v[6:]]

    options = {"ground": Ground(friction=0.5), "contacts": feet, "controller": hold, "duration": 0.3, "q0": q0}
    polished = simulate_contact(robot, **options)
    alone = simulate_contact(robot, **options, settings=ContactSettings(polish=False, tolerance=1e-12, max_iterations=5000))
    assert polished.slip[polished.active].max() > 0.1  # slipping, not only sticking
    assert np.abs(polished.trajectory.q - alone.trajectory.q).max() < 1e-8
    assert np.abs(polished.forces - alone.forces).max() < 1e-5 * np.abs(polished.forces).max()


def test_steps_whose_solver_stopped_early_are_said_in_the_summary(box):
    ground = Ground(friction=0.5)
    tight = ContactSettings(polish=False, tolerance=1e-14, max_iterations=2)
    run = simulate_contact(box, ground=ground, duration=0.3, q0=_on_slope(box, ground, lift=0.05), settings=tight)
    assert not run.converged.all()
    assert any("their forces are approximate" in line for line in run.summary_lines())
    exact = simulate_contact(box, ground=ground, duration=0.3, q0=_on_slope(box, ground, lift=0.05))
    assert exact.converged.all() and not any("approximate" in line for line in exact.summary_lines())


def test_a_box_thrown_tumbling_loses_energy_at_every_step_and_rests_on_a_face(box):
    q0 = box.neutral_configuration()
    q0[2], q0[3:7] = 0.3, pin.Quaternion(pin.rpy.rpyToMatrix(0.35, 0.2, 0.1)).coeffs()
    v0 = np.zeros(6)
    v0[3] = 1.0  # spinning about its x axis
    run = simulate_contact(box, ground=Ground(friction=0.5), duration=1.5, q0=q0, v0=v0)
    energy = _energy(box, run.trajectory.q, run.trajectory.v)
    landed = int(np.argmax(run.normal_forces.sum(axis=1) > 0))
    assert np.diff(energy[landed:]).max() < 1e-9  # [J]: 5.5e-11 measured, 6.1 J dissipated
    assert run.slip[run.active].max() > 0.1  # it slid and rolled over edges on the way
    assert run.active[-1].sum() == 4 and abs(run.normal_forces[-1].sum() / (MASS * G) - 1) < 1e-6
    assert run.trajectory.q[-1, 2] == pytest.approx(HALF_HEIGHT, abs=1e-9)


def test_a_mimic_arm_driven_into_its_elbow_stop_stays_on_it_when_limits_are_enforced():
    """The mimic arm (the general step) driven by 5 N m into its elbow's upper limit (2 rad),
    its fingertip a contact point far above the ground: enforced, the elbow stops exactly at
    2 rad and rests there, each step keeping last step's modes (no ADMM iteration); warned
    (the negative control), it swings past the stop."""
    arm = robodyn.load(DATA.parent / "mimic_arm.urdf", gravity=(0.4, -0.3, -7.5))
    tip, elbow = ContactPoint("fingertip", "tip", (0.1, 0.0, 0.0)), arm.joint_names.index("elbow")

    def drive(t, q, v):
        return np.where(np.arange(arm.nv) == elbow, 5.0, 0.0) - 0.5 * v

    options = {"ground": Ground(height=-5.0), "contacts": [tip], "duration": 0.3, "q0": np.array([0.0, 1.8]), "controller": drive}
    held = simulate_contact(arm, limits="enforce", **options)
    assert abs(held.trajectory.q[:, elbow].max() - 2.0) < 1e-12 and abs(held.trajectory.q[-1, elbow] - 2.0) < 1e-12
    assert (held.iterations[-20:] == 0).all()
    assert simulate_contact(arm, limits="warn", **options).trajectory.q[:, elbow].max() > 2.5


def test_a_pendulum_resting_on_its_stop_keeps_last_steps_modes_without_admm():
    """The stepper's path (no mimic joint): once the stop pendulum of
    tests/sim/test_contact_limits.py rests on its stop, each step is last step's modes kept,
    the stop's impulse warm-started (no ADMM iteration), and the stop carries gravity."""
    from tests.sim.test_contact_limits import _drop

    run = _drop("enforce")
    assert (run.iterations[-50:] == 0).all() and abs(run.trajectory.v[-1, 0]) < 1e-9
