"""Joint limits in a contact run (robodyn.sim.contact_limits): a limit is a one-sided row of
the contact problem. A pendulum dropped onto its stop rests on it with the stop's torque
equal to gravity's (a physical law), never past it; the negative control (limits not
enforced) swings through."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import robodyn
from robodyn.sim.contact_limits import REACH, LimitRows
from robodyn.sim.contact_run import simulate_contact
from robodyn.sim.ground import ContactPoint, Ground, resolve_ground
from robodyn.sim.simulation import simulate_run

MASS, LEVER, UPPER = 1.3, 0.4, 0.6  # [kg], [m] to the centre of mass, [rad]
GRAVITY = (0.0, 0.0, -7.3)
PENDULUM = f"""<robot name="stop_pendulum">
  <link name="base"/>
  <link name="arm">
    <inertial><origin xyz="{LEVER} 0 0"/><mass value="{MASS}"/>
      <inertia ixx="0.002" iyy="0.03" izz="0.03" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="swing" type="revolute"><parent link="base"/><child link="arm"/>
    <axis xyz="0 1 0"/><limit lower="-1.5" upper="{UPPER}" effort="100" velocity="10"/></joint>
</robot>"""
FAR = Ground(height=-5.0)  # a contact run needs a ground: this one is never reached
TIP = [ContactPoint("tip", "arm", (2 * LEVER, 0.0, 0.0))]


def _drop(limits: str) -> robodyn.sim.contact_run.ContactSimulation:
    robot = robodyn.load(PENDULUM, gravity=GRAVITY)
    return simulate_contact(robot, ground=FAR, contacts=TIP, duration=0.6, dt=1e-3, q0=np.array([0.1]), limits=limits)


def test_a_pendulum_dropped_on_its_stop_rests_on_it_with_the_stop_carrying_gravitys_torque():
    run = _drop("enforce")
    q = run.trajectory.q[:, 0]
    assert q.max() - UPPER < 1e-9  # [rad]: never past the stop
    assert abs(q[-1] - UPPER) < 1e-9 and abs(run.trajectory.v[-1, 0]) < 1e-9  # resting on it
    gravity_torque = MASS * abs(GRAVITY[2]) * LEVER * math.cos(UPPER)  # pushes q up, into the stop
    assert run.limit_torques is not None
    assert abs(-run.limit_torques[-1, 0] / gravity_torque - 1) < 1e-9
    assert run.limit_torques[:250, 0].max() <= 0.0  # an upper stop only pushes down
    assert any("joint limits: enforced" in line for line in run.summary_lines())


def test_without_enforced_limits_the_same_pendulum_swings_through_its_stop():
    run = _drop("warn")
    assert run.trajectory.q[:, 0].max() > UPPER + 1.0 and run.limit_torques is None


def test_simulate_with_a_ground_and_enforced_limits_runs_the_limit_rows():
    robot = robodyn.load(PENDULUM, gravity=GRAVITY)
    _, run = simulate_run(robot, np.array([0.1]), np.zeros(1), 0.6, 1e-3, limits="enforce", ground=FAR, contacts=TIP)
    assert run.contact is not None and run.contact.limit_torques is not None
    assert np.array_equal(run.contact.limit_torques, _drop("enforce").limit_torques)


def test_limit_rows_are_the_finite_limits_signed_lower_up_upper_down():
    rows = LimitRows(robodyn.load(PENDULUM))
    assert rows.names == ["swing lower", "swing upper"]
    assert np.allclose(rows.gaps(np.array([0.2])), [1.7, 0.4])
    assert np.allclose(rows.torques(np.array([0.0, 2e-3]), 1e-3, 1), [-2.0])


def test_a_start_past_an_enforced_limit_is_refused_naming_q0_and_the_joint():
    robot = robodyn.load(PENDULUM, gravity=GRAVITY)
    with pytest.raises(robodyn.exceptions.InputError, match=r"q0.*'swing upper' 0.1 past"):
        simulate_run(robot, np.array([UPPER + 0.1]), np.zeros(1), 0.1, 1e-3, limits="enforce", ground=FAR, contacts=TIP)


def test_a_contact_run_refuses_an_unknown_limits_mode():
    with pytest.raises(robodyn.exceptions.InputError, match="limits"):
        _drop("clamp")


QUADRUPED = Path(__file__).parents[1] / "data" / "mjcf" / "contact_quadruped.xml"


def _mujoco_drop(path: Path, duration: float, dt: float):
    """MuJoCo's run of an MJCF file at ``dt`` with its contacts and joint limits stiffened
    to their rigid limit (``solref`` two steps, critically damped; ``solimp`` 0.99–0.9999;
    no contact margin), elliptic cones: its start and end (robodyn's coordinate order,
    joints by name), Σ normal force and the colliding geoms."""
    mujoco = pytest.importorskip("mujoco")
    model = mujoco.MjModel.from_xml_path(str(path))
    model.opt.timestep, model.opt.cone = dt, mujoco.mjtCone.mjCONE_ELLIPTIC
    for solref, solimp in ((model.geom_solref, model.geom_solimp), (model.jnt_solref, model.jnt_solimp)):
        solref[:] = (2 * dt, 1.0)
        solimp[:] = (0.99, 0.9999, 0.001, 0.5, 2.0)
    model.geom_margin[:] = 0.0
    data = mujoco.MjData(model)
    start = data.qpos.copy()
    for _ in range(round(duration / dt)):
        mujoco.mj_step(model, data)
    force, total = np.zeros(6), 0.0
    for index in range(data.ncon):
        mujoco.mj_contactForce(model, data, index, force)
        total += force[0]
    geoms = {model.body(model.geom_bodyid[data.contact[i].geom[1]]).name for i in range(data.ncon)}
    names = [model.joint(i).name for i in range(1, model.njnt)]
    return names, start, data.qpos.copy(), total, geoms


def _ours(robot: robodyn.Robot, names: list[str], qpos: np.ndarray) -> np.ndarray:
    """MuJoCo's free-joint qpos (w x y z, its joint order) as robodyn's q (x y z w, by name)."""
    joints = [qpos[7 + names.index(name)] for name in robot.joint_names[1:]]
    return np.concatenate([qpos[:3], qpos[4:7], qpos[3:4], joints])


@pytest.mark.slow
def test_a_quadruped_on_limited_hinges_comes_to_rest_on_its_stops_where_mujoco_rests_it():
    """Capsule legs splayed by the landing until their hip stops hold; MuJoCo's joint
    limits and contacts stiffened to their rigid limit."""
    dt = 1e-3
    names, start, theirs, their_total, their_links = _mujoco_drop(QUADRUPED, 1.0, dt)
    robot = robodyn.load(QUADRUPED)
    run = simulate_contact(
        robot, ground=resolve_ground(robot, "file"), duration=1.0, dt=dt, q0=_ours(robot, names, start), limits="enforce"
    )
    ours, theirs = run.trajectory.q[-1], _ours(robot, names, theirs)
    weight = robot.total_mass * 9.81
    assert abs(ours[2] - theirs[2]) < 5e-4 and np.abs(ours[:2] - theirs[:2]).max() < 5e-3  # [m]
    assert 2 * math.acos(min(abs(ours[3:7] @ theirs[3:7]), 1.0)) < 5e-3  # [rad]
    stops = {"fl_hip": 20, "fr_hip": 20, "hl_knee": -30, "hr_knee": -30}  # [deg]: each leg rests on one
    index = [robot.joint_names[1:].index(name) for name in stops]
    assert np.abs(ours[7:][index] - np.radians(list(stops.values()))).max() < 1e-9  # on them, not past
    assert np.abs(theirs[7:][index] - np.radians(list(stops.values()))).max() < 2e-3  # MuJoCo's: a little past
    lower, upper = robot.physical_limits()
    past = np.maximum(lower - run.trajectory.q[:, 7:], run.trajectory.q[:, 7:] - upper).max(axis=1)  # [rad]
    solved = run.converged[:-1] & (past[:-1] <= 1e-9)  # a step solved to tolerance from inside the limits
    assert past[1:][solved].max() <= 1e-9  # ends inside them
    assert past.max() < 2e-3  # the landing's steps where ADMM stopped short (the summary says how many)
    assert abs(run.normal_forces[-1].sum() / weight - 1) < 1e-6 and abs(their_total / weight - 1) < 1e-6
    active = {run.frames[i] for i in np.flatnonzero(run.active[-1])}
    assert active == their_links == {"fl_shin", "fr_shin", "hl_shin", "hr_shin"}


@pytest.mark.slow
def test_the_general_step_also_rests_the_quadruped_on_its_stops(monkeypatch):
    """The same drop through ``generic_step`` (a mimic robot's path: ``Robot``'s ``M``, not
    Pinocchio's ``M⁻¹``): round-off takes the landing elsewhere, to feet at the edge of
    their cones slipping by micrometres a second, which the polish must read as slipping
    (read as sticking, the run chattered 5e-3 rad off the stops, ADMM stopped short every step)."""
    from robodyn.sim import contact_run
    from robodyn.sim.contact import generic_step

    def general(robot, q, v, tau, dt, ground, points, *, settings, guess, limits, held):
        return generic_step(robot, q, v, tau, dt, ground, points, settings, guess, limits=limits, held=held)

    monkeypatch.setattr(contact_run, "contact_step", general)
    names, start, *_ = _mujoco_drop(QUADRUPED, 1e-3, 1e-3)
    robot = robodyn.load(QUADRUPED)
    run = simulate_contact(
        robot, ground=resolve_ground(robot, "file"), duration=1.0, dt=1e-3, q0=_ours(robot, names, start), limits="enforce"
    )
    stops = {"fl_hip": 20, "fr_hip": 20, "hl_knee": -30, "hr_knee": -30}  # [deg]
    index = [robot.joint_names[1:].index(name) for name in stops]
    assert np.abs(run.trajectory.q[-1, 7:][index] - np.radians(list(stops.values()))).max() < 1e-9
    assert np.abs(run.trajectory.v[-1]).max() < 1e-9  # at rest
    assert abs(run.normal_forces[-1].sum() / (robot.total_mass * 9.81) - 1) < 1e-6


_LINK = '<link name="{}"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>'
# an unlimited hinge first (no row), then a limited hinge and a limited slider
THREE = (
    '<robot name="three">'
    + "".join(_LINK.format(name) for name in "abcd")
    + '<joint name="c" type="continuous"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/></joint>'
    + '<joint name="j1" type="revolute"><parent link="b"/><child link="c"/><origin xyz="0.3 0 0"/><axis xyz="0 1 0"/>'
    + '<limit lower="-1" upper="0.5" effort="5" velocity="2"/></joint>'
    + '<joint name="j2" type="prismatic"><parent link="c"/><child link="d"/><origin xyz="0.3 0 0"/><axis xyz="1 0 0"/>'
    + '<limit lower="-0.2" upper="0.3" effort="5" velocity="2"/></joint></robot>'
)


@pytest.mark.parametrize("floating", [False, True])
def test_limit_rows_point_at_their_own_joints_coordinates_fixed_or_floating(floating):
    robot = robodyn.load(THREE, floating_base=floating)
    rows = LimitRows(robot)
    joints = [robot.model.joints[robot.model.getJointId(name)] for name in ("j1", "j2", "j1", "j2")]
    assert rows.names == ["j1 lower", "j2 lower", "j1 upper", "j2 upper"]
    assert rows.q_index.tolist() == [joint.idx_q for joint in joints]
    assert rows.v_index.tolist() == [joint.idx_v for joint in joints]
    assert rows.bound.tolist() == [-1.0, -0.2, 0.5, 0.3] and rows.sign.tolist() == [1.0, 1.0, -1.0, -1.0]
    q = robot.random_configuration(np.random.default_rng(3))
    q1, q2 = q[joints[0].idx_q], q[joints[1].idx_q]
    np.testing.assert_allclose(rows.gaps(q), [q1 + 1.0, q2 + 0.2, 0.5 - q1, 0.3 - q2], rtol=0, atol=1e-15)
    # the step's reach (module docstring): 2 dt (|v_j| + |v_free,j|) + REACH, j1 alone near
    dt, v, free = 1e-3, np.zeros(robot.nv), np.zeros(robot.nv)
    v[joints[0].idx_v], free[joints[0].idx_v] = -1.0, 3.0
    v[joints[0].idx_v - 1] = 1e3  # the unlimited hinge's speed is no limit's
    reach = 2 * dt * 4.0 + REACH
    for gap, expected in ((0.99 * reach, [2]), (1.01 * reach, [])):
        q[joints[0].idx_q], q[joints[1].idx_q] = 0.5 - gap, 0.05
        assert rows.near(q, v, free, dt).tolist() == expected
    # two rows near: two cones of three rows, each normal row last, signed
    expected_rows = np.zeros((6, robot.nv))
    expected_rows[2, joints[0].idx_v], expected_rows[5, joints[1].idx_v] = 1.0, -1.0
    assert np.array_equal(rows.jacobian(np.array([0, 3]), robot.nv), expected_rows)


def test_a_robot_without_finite_limits_has_no_rows():
    text = THREE.replace('type="revolute"', 'type="continuous"').replace('type="prismatic"', 'type="continuous"')
    robot = robodyn.load(text)
    rows = LimitRows(robot)
    q, v = robot.neutral_configuration(), np.ones(robot.nv)
    assert rows.names == [] and rows.gaps(q).shape == (0,) and rows.near(q, v, v, 1e-3).shape == (0,)
    assert rows.jacobian(rows.near(q, v, v, 1e-3), robot.nv).shape == (0, robot.nv)
    assert np.array_equal(rows.torques(np.zeros(0), 1e-3, robot.nv), np.zeros(robot.nv))
