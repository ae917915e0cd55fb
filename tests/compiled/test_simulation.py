"""Compiled simulation against robodyn.simulate, step for step; energy; zero-order hold; divergence."""

from __future__ import annotations

import numpy as np
import pytest

import robodyn
from robodyn.compiled import CompiledComputedTorque, CompiledPDGravity, compile, simulate_compiled
from robodyn.exceptions import InputError, SimulationError
from robodyn.sim.control import ComputedTorque, PDGravity, quintic_reference
from robodyn.sim.simulation import simulate
from tests.compiled_helpers import relative_error, shared_cache
from tests.conftest import ROOT

MIMIC_TREE = ROOT / "tests" / "data" / "compiled_mimic_tree.urdf"
#: Step-for-step agreement: both integrate the same formulas; the dynamics differ by ~1e-15
#: per evaluation (LDLᵀ of the compact M vs Pinocchio's ABA), which a chaotic double
#: pendulum amplifies over a few hundred steps.
STEP_TOLERANCE = 1e-9


@pytest.fixture(scope="module", autouse=True)
def cache():
    """The session's compile cache (never the user's)."""
    with shared_cache() as folder:
        yield folder


@pytest.fixture(scope="module")
def pendulum():
    robot = robodyn.load("double_pendulum")
    return robot, compile(robot)


@pytest.fixture(scope="module")
def tree():
    robot = robodyn.load(MIMIC_TREE)
    return robot, compile(robot)


def _same_run(run, trajectory, tolerance=STEP_TOLERANCE):
    assert run.q.shape == trajectory.q.shape
    np.testing.assert_array_equal(run.t, trajectory.t)
    for ours, theirs in ((run.q, trajectory.q), (run.v, trajectory.v), (run.a, trajectory.a), (run.tau, trajectory.tau)):
        assert relative_error(ours, theirs) <= tolerance


@pytest.mark.parametrize("integrator", ["rk4", "semi-implicit-euler"])
def test_passive_run_matches_python_simulate_step_for_step(tree, integrator):
    robot, compiled = tree
    q0, v0 = np.array([0.3, 0.1, -0.5]), np.array([0.2, -0.1, 0.4])
    run = simulate_compiled(compiled, q0, v0, 0.3, 1e-3, integrator=integrator)
    _same_run(run, simulate(robot, q0, v0, 0.3, 1e-3, integrator=integrator, engine="pinocchio"))


def test_negative_control_another_step_does_not_match(tree):
    robot, compiled = tree
    q0, v0 = np.array([0.3, 0.1, -0.5]), np.zeros(3)
    run = simulate_compiled(compiled, q0, v0, 0.3, 1e-3)
    with pytest.raises(AssertionError):
        _same_run(run, simulate(robot, q0, v0, 0.3, 1e-3, integrator="semi-implicit-euler", engine="pinocchio"))


def test_passive_rk4_conserves_energy_to_fourth_order(pendulum):
    robot, compiled = pendulum
    q0, v0 = np.array([1.2, -0.7]), np.array([0.5, 1.0])

    def drift(dt: float, integrator: str = "rk4") -> float:
        run = simulate_compiled(compiled, q0, v0, 2.0, dt, integrator=integrator, joint_friction=False)
        energy = robot.kinetic_energy(run.q, run.v) + robot.potential_energy(run.q)
        return float(np.abs(energy - energy[0]).max())

    swing = np.ptp(robot.potential_energy(simulate_compiled(compiled, q0, v0, 2.0, 1e-3, joint_friction=False).q))
    assert swing > 1.0  # it really moves
    coarse, fine = drift(2e-3), drift(1e-3)
    assert coarse < 1e-5 * swing
    assert 8 < coarse / fine < 32  # the energy error of RK4 falls as dt⁴
    euler = drift(1e-3, "semi-implicit-euler")
    assert 100 * fine < euler < 0.2 * swing  # first order: worse, yet bounded (symplectic)


@pytest.mark.parametrize("hold", [False, True])
def test_pd_gravity_matches_python_simulate(tree, hold):
    robot, compiled = tree
    target, kp, kd = np.array([0.5, 0.1, -1.0]), np.array([60.0, 200.0, 30.0]), 8.0
    q0, v0 = np.zeros(3), np.zeros(3)
    run = simulate_compiled(
        compiled, q0, v0, 0.4, 1e-3, controller=CompiledPDGravity(compiled, target, kp, kd), hold=hold, joint_friction=False
    )
    _same_run(run, simulate(robot, q0, v0, 0.4, 1e-3, controller=PDGravity(robot, target, kp, kd), hold=hold))


@pytest.mark.slow
def test_computed_torque_on_a_mismatched_model_matches_python_simulate(tree, tmp_path):
    robot, compiled = tree
    text = MIMIC_TREE.read_text(encoding="utf-8").replace('<mass value="1.1"/>', '<mass value="1.6"/>')
    path = tmp_path / "heavier.urdf"
    path.write_text(text, encoding="utf-8")
    model = robodyn.load(path)
    start, end = np.array([0.0, 0.0, 0.0]), np.array([0.8, 0.2, -1.2])
    controller = CompiledComputedTorque(compile(model), start, end, 0.3, kp=300.0, kd=35.0)
    run = simulate_compiled(compiled, start, np.zeros(3), 0.5, 1e-3, controller=controller, joint_friction=False)
    python = ComputedTorque(model, quintic_reference(start, end, 0.3), kp=300.0, kd=35.0)
    _same_run(run, simulate(robot, start, np.zeros(3), 0.5, 1e-3, controller=python))
    assert np.abs(run.q[-1] - end).max() > 1e-4  # the wrong model leaves an error ...
    assert np.abs(run.q[-1] - end).max() < 0.2  # ... that feedback keeps small


def test_python_controller_is_held_for_its_control_period(tree):
    robot, compiled = tree
    calls = []

    def controller(t, q, v):
        calls.append(t)
        return -20.0 * q - 2.0 * v + np.array([0.0, 5.0, 0.0])

    q0, v0 = np.array([0.3, 0.0, 0.2]), np.zeros(3)
    run = simulate_compiled(compiled, q0, v0, 0.2, 1e-3, controller=controller, control_period=5e-3, joint_friction=False)
    assert len(calls) == 40 and calls[1] == pytest.approx(5e-3)

    held = {}

    def sampled(t, q, v):  # the same zero-order hold, written for robodyn.simulate
        step = round(t / 1e-3)
        if step % 5 == 0:
            held["tau"] = controller(t, q, v)
        return held["tau"]

    _same_run(run, simulate(robot, q0, v0, 0.2, 1e-3, controller=sampled, hold=True))


def test_divergence_is_reported_like_python_simulate(pendulum):
    robot, compiled = pendulum
    q0, v0 = np.array([0.1, 0.2]), np.array([1e154, 0.0])
    with pytest.raises(SimulationError) as theirs:
        simulate(robot, q0, v0, 1.0, 1e-3, engine="pinocchio", joint_friction=False)
    with pytest.raises(SimulationError) as ours:
        simulate_compiled(compiled, q0, v0, 1.0, 1e-3, joint_friction=False)
    assert (ours.value.step, ours.value.joint) == (theirs.value.step, theirs.value.joint)


def test_bad_arguments_are_refused(pendulum):
    _, compiled = pendulum
    zero = np.zeros(2)
    with pytest.raises(InputError, match="integrator"):
        simulate_compiled(compiled, zero, zero, 1.0, 1e-3, integrator="euler", joint_friction=False)
    with pytest.raises(InputError, match="control_period"):
        simulate_compiled(
            compiled, zero, zero, 1.0, 1e-3, controller=lambda t, q, v: zero, control_period=2.5e-3, joint_friction=False
        )
    with pytest.raises(InputError, match=r"^q "):
        simulate_compiled(compiled, np.zeros(3), zero, 1.0, 1e-3, joint_friction=False)
    with pytest.raises(InputError, match="controller output"):
        simulate_compiled(compiled, zero, zero, 1.0, 1e-3, controller=lambda t, q, v: np.zeros(5), joint_friction=False)
    run = simulate_compiled(compiled, zero, zero, 0.0, 1e-3, joint_friction=False)
    assert run.q.shape == (1, 2)


def test_a_robot_with_joint_damping_is_damped_in_c_unless_the_rigid_body_motion_is_asked_for(pendulum):
    """The zoo's double pendulum has <dynamics damping>: the loop in C applies it (the
    Python engine's trajectory: tests/sim/test_joint_friction.py); joint_friction=False
    leaves it out."""
    robot, compiled = pendulum
    assert robot.joint_damping.any() and not robot.joint_friction.any()
    q0, zero = np.array([1.0, -0.5]), np.zeros(2)
    damped = simulate_compiled(compiled, q0, zero, 1.0, 1e-3)
    rigid = simulate_compiled(compiled, q0, zero, 1.0, 1e-3, joint_friction=False)
    assert rigid.q.shape == (1001, 2) and np.abs(damped.q - rigid.q).max() > 1e-3
