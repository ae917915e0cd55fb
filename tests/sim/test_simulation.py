"""simulate(engine="compiled") gives the Pinocchio engine's trajectory, or refuses in one line.

Also here:

- Simulation and control against physical laws and hand calculations.
"""

from __future__ import annotations

import re
import shutil

import numpy as np
import pytest

import robodyn
from robodyn.dynamics.loading import rebuild
from robodyn.dynamics.payload import attach_payload
from robodyn.exceptions import InputError
from robodyn.sim.control import ComputedTorque, PDGravity, TaskSpace, quintic_reference
from robodyn.sim.experiment import controller_model
from robodyn.sim.simulation import ExternalWrench, SimulationError, simulate
from robodyn.trajectory import Trajectory
from robodyn.urdf.models import pendulum_urdf
from tests.conftest import ROOT

pytestmark = pytest.mark.skipif(shutil.which("cc") is None and shutil.which("gcc") is None, reason="no C compiler")


def _laws(robot, q0):
    target = q0 + 0.3
    return {
        "passive": None,
        "pd": PDGravity(rebuild(robot), target),
        "computed-torque": ComputedTorque(rebuild(robot), quintic_reference(q0, target, 0.4)),
    }


@pytest.mark.parametrize("name", ["ur5", "rp_arm"])
@pytest.mark.parametrize("law", ["passive", "pd", "computed-torque"])
@pytest.mark.parametrize("integrator", ["rk4", "semi-implicit-euler"])
def test_compiled_engine_equals_the_pinocchio_engine(name, law, integrator):
    robot = robodyn.load(name)
    q0 = robot.default_configuration()
    controller = _laws(robot, q0)[law]
    options = {"controller": controller, "integrator": integrator, "limits": "ignore"}
    python = robodyn.simulate(robot, q0, np.zeros(robot.nv), 0.5, 1e-3, **options)
    compiled = robodyn.simulate(robot, q0, np.zeros(robot.nv), 0.5, 1e-3, engine="compiled", **options)
    scale = max(1.0, np.abs(python.q).max())
    np.testing.assert_allclose(compiled.q, python.q, atol=1e-9 * scale)
    np.testing.assert_allclose(compiled.tau, python.tau, atol=1e-8 * max(1.0, np.abs(python.tau).max()))
    assert compiled.joint_names == python.joint_names and len(compiled) == len(python)


def test_a_python_controller_is_held_every_control_period():
    robot = robodyn.load("rp_arm")
    q0 = robot.default_configuration()
    law = TaskSpace(rebuild(robot), robot.end_effector, np.array([0.7, 0.0, 0.7]))
    held = robodyn.simulate(robot, q0, np.zeros(2), 0.2, 1e-3, controller=law, hold=True, limits="ignore")
    compiled = robodyn.simulate(
        robot, q0, np.zeros(2), 0.2, 1e-3, controller=law, engine="compiled", control_period=1e-3, limits="ignore"
    )
    np.testing.assert_allclose(compiled.q, held.q, atol=1e-9)


def test_refusals_are_one_line_robodyn_errors():
    robot = robodyn.load("rp_arm")
    q0 = robot.default_configuration()
    with pytest.raises(InputError, match="engine"):
        robodyn.simulate(robot, q0, np.zeros(2), 0.1, 1e-3, engine="warp")
    with pytest.raises(InputError, match="enforce"):
        robodyn.simulate(robot, q0, np.zeros(2), 0.1, 1e-3, engine="compiled", limits="enforce")
    wrench = ExternalWrench(robot.end_effector, np.array([1.0, 0, 0, 0, 0, 0]))
    with pytest.raises(InputError, match="wrench"):
        robodyn.simulate(robot, q0, np.zeros(2), 0.1, 1e-3, engine="compiled", external=[wrench])
    floating = robodyn.load("solo12")  # compiled frame controllers model fixed bases
    task = TaskSpace(floating, "FL_FOOT", np.zeros(3))
    with pytest.raises(InputError, match="floating base under TaskSpace"):
        robodyn.simulate(
            floating, floating.default_configuration(), np.zeros(floating.nv), 0.1, 1e-3, engine="compiled", controller=task
        )


def test_compiled_runs_warn_about_limits_like_the_python_engine():
    robot = robodyn.load("rp_arm")
    q0 = robot.default_configuration()
    with pytest.warns(robodyn.JointLimitWarning) as python:
        robodyn.simulate(robot, q0, np.zeros(2), 1.0, 1e-3)
    with pytest.warns(robodyn.JointLimitWarning) as compiled:
        robodyn.simulate(robot, q0, np.zeros(2), 1.0, 1e-3, engine="compiled")
    assert str(python[0].message) == str(compiled[0].message)


GANTRY = ROOT / "tests" / "data" / "gantry.urdf"


def total_energy(robot, trajectory):
    return robot.kinetic_energy(trajectory.q, trajectory.v) + robot.potential_energy(trajectory.q)


def test_passive_double_pendulum_conserves_energy_with_rk4():
    robot = robodyn.load("pendulum")
    trajectory = simulate(robot, np.array([1.0, -1.0]), np.zeros(2), 10.0, 1e-3, integrator="rk4")
    energy = total_energy(robot, trajectory)
    assert np.abs(energy - energy[0]).max() / abs(energy[0]) < 1e-6
    assert np.ptp(trajectory.q[:, 0]) > 1.0  # it really swung


def test_semi_implicit_euler_keeps_energy_error_bounded():
    """Symplectic: on a (single) pendulum the energy error oscillates, it does not grow."""
    robot = robodyn.load(pendulum_urdf(1))
    trajectory = simulate(robot, np.array([2.0]), np.zeros(1), 20.0, 1e-3, integrator="semi-implicit-euler")
    energy = total_energy(robot, trajectory)
    error = np.abs(energy - energy[0]) / abs(energy[0])
    assert error.max() < 1e-2
    assert error[-5000:].max() < 1.2 * error[:5000].max()


def test_free_fall_of_a_prismatic_joint_is_exact():
    """The gantry's vertical slider falls as z = −g t²/2 (RK4 is exact for a quadratic)."""
    robot = robodyn.load(GANTRY)
    trajectory = simulate(robot, np.zeros(2), np.zeros(2), 0.3, 1e-3, limits="ignore")
    np.testing.assert_allclose(trajectory.q[:, 1], -0.5 * 9.81 * trajectory.t**2, atol=1e-12)
    np.testing.assert_allclose(trajectory.q[:, 0], 0.0, atol=1e-15)


def test_computed_torque_with_a_perfect_model_tracks_to_numerical_precision():
    robot = robodyn.load("ur5")
    start, end = np.zeros(6), np.array([0.5, -0.8, 1.0, 0.3, -0.4, 0.6])
    reference = quintic_reference(start, end, 1.0)
    controller = ComputedTorque(controller_model(robot), reference)
    trajectory = simulate(robot, start, np.zeros(6), 1.5, 1e-3, controller=controller)
    errors = [np.abs(q - reference(t)[0]).max() for t, q in zip(trajectory.t, trajectory.q, strict=True)]
    assert max(errors) < 1e-8


def test_pd_with_gravity_compensation_settles_at_the_target():
    robot = robodyn.load("rp_arm")
    target = np.array([0.6, 0.15])
    trajectory = simulate(robot, np.zeros(2), np.zeros(2), 6.0, 1e-3, controller=PDGravity(controller_model(robot), target))
    np.testing.assert_allclose(trajectory.q[-1], target, atol=1e-6)
    np.testing.assert_allclose(trajectory.v[-1], 0.0, atol=1e-6)


def test_pd_sags_by_the_unmodelled_payload_weight_over_the_stiffness():
    """Model mismatch: the controller does not know the payload; the arm sags by ΔG / Kp."""
    robot = robodyn.load("rp_arm")
    plant = attach_payload(robot, "end_effector", 1.0)
    target = np.array([0.0, 0.1])
    trajectory = simulate(
        plant, target, np.zeros(2), 8.0, 1e-3, controller=PDGravity(controller_model(robot), target, kp=2000.0, kd=200.0)
    )
    final = trajectory.q[-1]
    missing = plant.gravity(final) - robot.gravity(final)
    np.testing.assert_allclose(target - final, missing / 2000.0, rtol=1e-6, atol=1e-10)


def test_task_space_control_reaches_the_target():
    robot = robodyn.load("rp_arm")
    target = np.array([0.7, 0.0, 0.7])
    controller = TaskSpace(controller_model(robot), "end_effector", target)
    trajectory = simulate(robot, np.zeros(2), np.zeros(2), 4.0, 1e-3, controller=controller, limits="enforce")
    assert np.linalg.norm(robot.frame_position(trajectory.q[-1], "end_effector") - target) < 1e-8


def test_task_space_control_of_a_redundant_arm_reaches_the_target():
    robot = robodyn.load("ur5")
    start = np.array([0.0, -1.0, 1.0, -0.5, 0.5, 0.0])
    target = robot.frame_position(start, "tool0") + np.array([0.1, -0.05, 0.08])
    controller = TaskSpace(controller_model(robot), "tool0", target)
    trajectory = simulate(robot, start, np.zeros(6), 4.0, 1e-3, controller=controller)
    assert np.linalg.norm(robot.frame_position(trajectory.q[-1], "tool0") - target) < 1e-6


def test_payload_held_still_adds_the_hand_calculated_static_torque():
    """A mass m at the tip, r = l1 + q2 + l2 from the shoulder: Δtau = (m g r cos q1, m g sin q1)."""
    robot = robodyn.load("rp_arm")
    mass = 1.7
    loaded = attach_payload(robot, "end_effector", mass)
    for q1, q2 in [(0.0, 0.0), (0.7, 0.2), (-1.2, 0.05)]:
        q = np.array([q1, q2])
        added = loaded.inverse_dynamics(q, np.zeros(2), np.zeros(2)) - robot.inverse_dynamics(q, np.zeros(2), np.zeros(2))
        reach = 0.5 + q2 + 0.4
        np.testing.assert_allclose(added, [mass * 9.81 * reach * np.cos(q1), mass * 9.81 * np.sin(q1)], atol=1e-12)
        # Held with exactly that torque, the loaded arm does not move.
        hold = loaded.gravity(q)
        trajectory = simulate(loaded, q, np.zeros(2), 0.5, 1e-3, controller=lambda t, q_, v_, hold=hold: hold)
        np.testing.assert_allclose(trajectory.q[-1], q, atol=1e-12)


def test_external_force_that_cancels_the_weight_leaves_the_slider_still():
    robot = robodyn.load(GANTRY)
    lift = ExternalWrench("tool", [0.0, 0.0, 9.81 * 1.0])  # the tool weighs 1 kg
    trajectory = simulate(robot, np.zeros(2), np.zeros(2), 0.5, 1e-3, external=[lift])
    np.testing.assert_allclose(trajectory.q[:, 1], 0.0, atol=1e-12)
    # Inverse dynamics: the motor needs to push only what the force does not.
    assert robot.inverse_dynamics(np.zeros(2), np.zeros(2), np.zeros(2))[1] - robot.wrench_torques(
        np.zeros(2), "tool", lift.value(0.0)
    )[1] == pytest.approx(0.0, abs=1e-12)


def test_time_varying_external_force():
    robot = robodyn.load(GANTRY)
    push = ExternalWrench("carriage", lambda t: np.array([4.0 * t, 0.0, 0.0]))  # along x, on 4 kg in all
    trajectory = simulate(robot, np.zeros(2), np.zeros(2), 1.0, 1e-3, external=[push], limits="ignore")
    # x'' = t  =>  x = t³ / 6
    np.testing.assert_allclose(trajectory.q[:, 0], trajectory.t**3 / 6, atol=1e-12)


def test_divergence_stops_with_when_and_where():
    robot = robodyn.load("rp_arm")
    wild = PDGravity(controller_model(robot), np.array([0.5, 0.1]), kp=1e9, kd=0.0)
    with pytest.raises(SimulationError, match=r"diverged at t = .* s \(step \d+\): joint 'joint\d'"):
        simulate(robot, np.zeros(2), np.zeros(2), 1.0, 0.01, controller=wild, integrator="semi-implicit-euler")


def test_bad_arguments_are_input_errors():
    robot = robodyn.load("rp_arm")
    with pytest.raises(InputError, match="integrator"):
        simulate(robot, np.zeros(2), np.zeros(2), 1.0, 1e-3, integrator="euler")
    with pytest.raises(InputError, match="dt and duration"):
        simulate(robot, np.zeros(2), np.zeros(2), 1.0, 0.0)
    with pytest.raises(InputError, match="q must be"):
        simulate(robot, np.zeros(3), np.zeros(2), 1.0, 1e-3)


@pytest.mark.parametrize("suffix", [".csv", ".npz"])
def test_trajectory_round_trips_through_files(tmp_path, suffix):
    robot = robodyn.load("rp_arm")
    trajectory = simulate(robot, np.array([0.3, 0.1]), np.zeros(2), 0.05, 1e-3)
    path = trajectory.save(tmp_path / f"motion{suffix}")
    again = Trajectory.load(path)
    for field in ("t", "q", "v", "a", "tau"):
        np.testing.assert_array_equal(getattr(again, field), getattr(trajectory, field))
    assert again.joint_names == robot.joint_names and again.robot == "rp_arm"


def test_unreadable_trajectory_is_a_robodyn_error(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("not,a\ntrajectory,file\n")
    with pytest.raises(robodyn.RobodynError):
        Trajectory.load(bad)


#: dm_control's manipulator finger in small: 7e-8 kg m² about its hinge, damping 0.01 N m s/rad
#: (the rate b / I ≈ 1.4e5 1/s: RK4 needs dt under ~2e-5 s).
LIGHT_FINGER = """<mujoco><compiler angle="radian"/><worldbody>
<body name="hand" pos="0 0 1"><joint name="wrist" axis="0 1 0" damping="0.5"/>
  <geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.02" mass="0.3"/>
  <body name="finger" pos="0.2 0 0"><joint name="fingertip" axis="0 1 0" damping="0.01"/>
    <inertial pos="0.005 0 0" mass="1e-3" diaginertia="4.5e-8 4.5e-8 4.5e-8"/></body>
</body></worldbody></mujoco>"""


def test_a_divergence_from_damping_on_a_light_body_names_the_cause_and_the_step_that_holds(tmp_path):
    """The run is warned about at its start and its error says why and which step would do;
    at that step it stays finite (the negative control: the default step diverges)."""
    path = tmp_path / "finger.xml"
    path.write_text(LIGHT_FINGER)
    robot = robodyn.load(path)
    q0 = np.array([0.3, 0.2])
    warned = pytest.warns(robodyn.RobodynWarning, match=r"largest stable step .*'fingertip'.*damping on light links")
    advice = r"diverged at .*damping on light links\): use dt <= (\S+) s \(e\.g\. (\S+) s\)\.$"
    with warned, pytest.raises(SimulationError, match=advice) as error:
        simulate(robot, q0, np.zeros(2), 0.1, 1e-3, limits="ignore")
    found = re.search(advice, str(error.value))
    assert found is not None
    step, typed = float(found[1]), float(found[2])
    assert 1e-5 < step < 3e-5 and typed <= step
    calm = simulate(robot, q0, np.zeros(2), 0.1, typed, limits="ignore")  # the suggested step divides 0.1 s
    assert np.isfinite(calm.q).all()
