"""Joint damping and Coulomb friction in the simulation: MuJoCo's RK4 on the same URDF, the
work–energy balance, the stiction band, and the engines and flags that cannot honour them."""

from __future__ import annotations

import json

import numpy as np
import pytest

import robodyn
from robodyn.cli.app import main
from robodyn.exceptions import InputError

mujoco = pytest.importorskip("mujoco")

_INERTIAL = '<inertial><mass value="{m}"/><origin xyz="{c}"/><inertia ixx="{i[0]}" iyy="{i[1]}" izz="{i[2]}" ixy="{i[3]}" ixz="{i[4]}" iyz="{i[5]}"/></inertial>'


def link(name: str, mass: float, com: str, inertia: tuple) -> str:
    return f'<link name="{name}">{_INERTIAL.format(m=mass, c=com, i=inertia)}</link>'


#: A double pendulum with damping at both joints: the elbow's axis oblique, its origin turned.
DAMPED = (
    '<robot name="damped_pendulum"><link name="base"/>'
    + link("upper", 1.3, "0.02 0.01 -0.35", (0.05, 0.06, 0.02, 0.001, 0.002, 0.003))
    + link("lower", 0.7, "0 -0.02 -0.25", (0.02, 0.025, 0.01, 0.0, 0.001, 0.0))
    + '<joint name="shoulder" type="continuous"><parent link="base"/><child link="upper"/><axis xyz="0 1 0"/>'
    '<dynamics damping="0.4"/></joint>'
    '<joint name="elbow" type="continuous"><parent link="upper"/><child link="lower"/><origin xyz="0 0 -0.7" rpy="0.1 0 0"/>'
    '<axis xyz="0.3 1 0"/><dynamics damping="0.15"/></joint></robot>'
)


def coulomb_pendulum(friction: float, *, mimic: bool = False) -> str:
    """A pendulum with Coulomb friction only (``mimic``: a second link whose joint mimics the
    first with k = −1.5 and carries the friction)."""
    rod = link("rod", 1.0, "0 0 -0.5", (0.02, 0.02, 0.001, 0, 0, 0))
    if not mimic:
        joint = f'<joint name="pivot" type="continuous"><parent link="base"/><child link="rod"/><axis xyz="0 1 0"/><dynamics friction="{friction}"/></joint>'
        return f'<robot name="coulomb_pendulum"><link name="base"/>{rod}{joint}</robot>'
    tip = link("tip", 0.4, "0 0 -0.2", (0.003, 0.003, 0.0005, 0, 0, 0))
    return (
        f'<robot name="coulomb_mimic"><link name="base"/>{rod}{tip}'
        '<joint name="pivot" type="revolute"><parent link="base"/><child link="rod"/><axis xyz="0 1 0"/>'
        '<limit lower="-10" upper="10" effort="50" velocity="50"/></joint>'
        '<joint name="wrist" type="revolute"><parent link="rod"/><child link="tip"/><origin xyz="0 0 -1"/><axis xyz="0 1 0"/>'
        f'<limit lower="-10" upper="10" effort="50" velocity="50"/><mimic joint="pivot" multiplier="-1.5"/><dynamics friction="{friction}"/></joint>'
        "</robot>"
    )


def mujoco_rk4(urdf: str, q0: np.ndarray, duration: float, dt: float) -> np.ndarray:
    """MuJoCo's RK4 from rest at ``q0`` (its own URDF reader, damping from ``<dynamics>``)."""
    model = mujoco.MjModel.from_xml_string(urdf)
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    model.opt.timestep = dt
    data = mujoco.MjData(model)
    data.qpos[:] = q0
    for _ in range(round(duration / dt)):
        mujoco.mj_step(model, data)
    return data.qpos.copy()


def test_a_damped_double_pendulum_matches_mujoco_rk4():
    robot = robodyn.load(DAMPED)
    assert robot.joint_damping.tolist() == mujoco.MjModel.from_xml_string(DAMPED).dof_damping.tolist()
    q0, dt = np.array([1.2, -0.8]), 2e-3
    expected = mujoco_rk4(DAMPED, q0, 3.0, dt)
    trajectory = robodyn.simulate(robot, q0, np.zeros(2), 3.0, dt)
    assert np.abs(trajectory.q[-1] - expected).max() < 1e-6
    rigid = robodyn.simulate(robot, q0, np.zeros(2), 3.0, dt, joint_friction=False)
    assert np.abs(rigid.q[-1] - expected).max() > 0.1  # negative control: the damping matters


@pytest.mark.parametrize("integrator", ["rk4", "semi-implicit-euler"])
def test_damping_dissipates_the_integral_of_b_v_squared(integrator):
    robot = robodyn.load(DAMPED)
    trajectory = robodyn.simulate(robot, np.array([1.2, -0.8]), np.zeros(2), 2.0, 1e-3, integrator=integrator)
    energy = robot.kinetic_energy(trajectory.q, trajectory.v) + robot.potential_energy(trajectory.q)
    power = (robot.joint_damping * trajectory.v**2).sum(axis=1)
    dissipated = np.sum(0.5 * (power[1:] + power[:-1]) * np.diff(trajectory.t))
    assert dissipated > 1.0
    assert abs((energy[0] - energy[-1]) / dissipated - 1) < 2e-3


@pytest.mark.parametrize("mimic", [False, True], ids=["pendulum", "mimic_joint_friction"])
@pytest.mark.parametrize("integrator", ["rk4", "semi-implicit-euler"])
def test_a_coulomb_pendulum_from_horizontal_rests_in_its_stiction_band_having_lost_f_times_its_travel(integrator, mimic):
    friction = 0.8
    robot = robodyn.load(coulomb_pendulum(friction, mimic=mimic))
    duration = 6.0 if mimic else 5.0  # both at rest for their last second
    trajectory = robodyn.simulate(robot, np.array([np.pi / 2]), np.zeros(1), duration, 1e-3, integrator=integrator)
    energy = robot.kinetic_energy(trajectory.q, trajectory.v) + robot.potential_energy(trajectory.q)
    effective = robot.joint_friction[0]  # a mimic's friction k f acts on its source
    assert effective == pytest.approx(1.5 * friction if mimic else friction)
    travelled = np.abs(np.diff(trajectory.q[:, 0])).sum()  # the mimic joint travels 1.5 times as far
    assert travelled > 2.0  # it swung back and forth
    assert abs((energy[0] - energy[-1]) / (effective * travelled) - 1) < 0.02
    rest = trajectory.t > duration - 1.0
    assert (trajectory.v[rest] == 0).all() and (trajectory.q[rest] == trajectory.q[-1]).all()  # no creep
    assert abs(robot.gravity(trajectory.q[-1])[0]) <= effective  # inside the stiction band
    assert abs(robot.gravity(trajectory.q[-1])[0]) > 0.05 * effective  # not merely at the bottom
    rigid = robodyn.simulate(robot, np.array([np.pi / 2]), np.zeros(1), 5.0, 1e-3, integrator=integrator, joint_friction=False)
    rigid_energy = robot.kinetic_energy(rigid.q, rigid.v) + robot.potential_energy(rigid.q)
    assert np.abs(rigid.v[rigid.t > 4.0]).max() > 1.0 and abs(rigid_energy[-1] - rigid_energy[0]) < 0.05 * (
        energy[0] - energy[-1]
    )  # negative control


def test_a_joint_at_rest_holds_while_the_torques_on_it_stay_within_its_friction():
    """The shoulder's friction (30 N m) exceeds every torque the swinging elbow puts on it:
    it stays exactly where it was, and the elbow swings as it does with the shoulder locked
    there (another model: a fixed joint)."""
    urdf = DAMPED.replace('<dynamics damping="0.4"/>', '<dynamics friction="30"/>')
    robot = robodyn.load(urdf)
    q0 = np.array([0.4, 1.3])
    trajectory = robodyn.simulate(robot, q0, np.zeros(2), 1.5, 1e-3)
    assert (trajectory.q[:, 0] == 0.4).all() and (trajectory.v[:, 0] == 0).all()
    locked = robodyn.load(urdf, lock={"shoulder": 0.4})
    elbow = robodyn.simulate(locked, q0[1:], np.zeros(1), 1.5, 1e-3)
    assert np.ptp(elbow.q[:, 0]) > 1.0
    assert np.abs(trajectory.q[:, 1] - elbow.q[:, 0]).max() < 1e-9
    weaker = robodyn.simulate(robodyn.load(urdf.replace('friction="30"', 'friction="3"')), q0, np.zeros(2), 1.5, 1e-3)
    assert np.ptp(weaker.q[:, 0]) > 0.01  # negative control: a friction the elbow overcomes lets it slip


@pytest.mark.parametrize(("torque", "moves"), [(0.9, False), (1.1, True)])
def test_a_constant_torque_below_the_friction_does_not_move_the_joint_and_above_it_does(torque, moves):
    robot = robodyn.load(coulomb_pendulum(1.0))
    for integrator in ("rk4", "semi-implicit-euler"):
        trajectory = robodyn.simulate(
            robot, np.zeros(1), np.zeros(1), 0.5, 1e-3, controller=lambda t, q, v: np.array([torque]), integrator=integrator
        )
        assert (np.ptp(trajectory.q[:, 0]) > 1e-3) == moves


def test_the_compiled_engine_refuses_coulomb_friction_and_names_the_way_out(tmp_path, capsys):
    """Stick–slip has no loop in C (damping has: the test below)."""
    coulomb = DAMPED.replace('<dynamics damping="0.4"/>', '<dynamics damping="0.4" friction="0.3"/>')
    robot = robodyn.load(coulomb)
    with pytest.raises(InputError) as raised:
        robodyn.simulate(robot, np.zeros(2), np.zeros(2), 0.1, 1e-3, engine="compiled")
    assert "joint_friction=False" in str(raised.value) and "'shoulder'" in str(raised.value)
    path = tmp_path / "coulomb.urdf"
    path.write_text(coulomb, encoding="utf-8")
    assert main(["simulate", str(path), "--compiled", "--duration", "0.1"]) == 2
    error = capsys.readouterr().err
    assert "--no-joint-friction" in error and len(error.strip().splitlines()) == 1


def test_no_joint_friction_on_the_command_line_gives_the_rigid_body_motion(tmp_path, capsys):
    path = tmp_path / "coulomb.urdf"
    path.write_text(coulomb_pendulum(0.8), encoding="utf-8")
    summaries = {}
    for flags in ([], ["--no-joint-friction"]):
        assert main(["simulate", str(path), "--q0", "1.5707963", "--duration", "2", "--json", *flags]) == 0
        summaries[bool(flags)] = json.loads(capsys.readouterr().out)
    assert abs(summaries[True]["energy_change_J"]) < 1e-6
    assert summaries[False]["energy_change_J"] < -1.0


@pytest.fixture
def compile_cache():
    """The session's compile cache (never the user's)."""
    from tests.compiled_helpers import shared_cache

    with shared_cache() as folder:
        yield folder


def _engines_agree(robot, q0, v0, controller, duration=1.0):
    """The largest difference of q, v over the run between the two engines, and the compiled
    run's distance from the rigid-body motion (the damping's effect)."""
    runs = {
        engine: robodyn.simulate(robot, q0, v0, duration, 1e-3, controller=controller, limits="ignore", engine=engine)
        for engine in ("pinocchio", "compiled")
    }
    rigid = robodyn.simulate(
        robot, q0, v0, duration, 1e-3, controller=controller, limits="ignore", engine="compiled", joint_friction=False
    )
    python, compiled = runs["pinocchio"], runs["compiled"]
    difference = max(np.abs(python.q - compiled.q).max(), np.abs(python.v - compiled.v).max())
    return difference, np.abs(compiled.q - rigid.q).max()


@pytest.mark.parametrize("name", ["double_pendulum", "damped"])
def test_the_compiled_loop_damps_the_joints_as_the_pinocchio_engine_does(name, compile_cache, rng):
    """Passive, under a compiled PD law and under a Python controller (called at every
    stage): the same trajectory to 1e-9; negative control: the rigid-body motion departs.
    The compiled run also matches MuJoCo's RK4 (its own reader of <dynamics damping>)."""
    from robodyn.sim.control import PDGravity

    robot = robodyn.load(DAMPED if name == "damped" else name, gravity=[0.6, -0.4, -9.7])
    assert robot.joint_damping.all() and not robot.joint_friction.any()
    q0, v0 = np.array([1.2, -0.8]), 0.5 * rng.normal(size=2)
    for controller in (None, PDGravity(robot, np.array([0.3, 0.2]), kp=8.0, kd=1.0), lambda t, q, v: -0.2 * v):
        difference, damped = _engines_agree(robot, q0, v0, controller)
        assert difference <= 1e-9 and damped > 1e-3, (controller, difference, damped)
    if name == "damped":
        compiled = robodyn.simulate(robodyn.load(DAMPED), q0, np.zeros(2), 3.0, 2e-3, engine="compiled")
        assert np.abs(compiled.q[-1] - mujoco_rk4(DAMPED, q0, 3.0, 2e-3)).max() < 1e-6


@pytest.mark.slow
def test_the_compiled_loop_damps_the_pandas_fingers_as_the_pinocchio_engine_does(compile_cache, rng):
    """panda: damping 0.003 at the arm's joints, 0.6 at the mimic finger."""
    robot = robodyn.load("panda")
    q0, v0 = robot.random_configuration(rng), 0.3 * rng.normal(size=robot.nv)
    difference, damped = _engines_agree(robot, q0, v0, None, duration=0.5)
    assert difference <= 1e-9 and damped > 1e-4, (difference, damped)
