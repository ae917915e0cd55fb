"""The controllers' transients, asserted against independent integrations.

- ``PDGravity`` and ``ComputedTorque``: the simulated closed loop (Pinocchio plant, RK4)
  against ``scipy.integrate.solve_ivp`` of the same control law written here in terms of
  the independent reference's dynamics, sample by sample over the whole trajectory.
- ``ComputedTorque`` with a perfect model: the joint error obeys ``ë + Kd ė + Kp e = 0``,
  whose solution is a matrix exponential.
- ``TaskSpace`` with a perfect model and a Jacobian of full row rank: the task error obeys
  ``ë + Kd ė + Kp e = 0`` too (the ``J̇ v`` term is what makes it so: with the wrong sign
  the transient is off although the final error is the same).
- Zero-order hold (``hold=True``) against a step computed by hand on a gantry whose
  dynamics are written down from its URDF.
- On damped plants (the panda; a floating body with damped arms) computed torque with
  ``compensate_damping`` keeps its closed-loop law; negative control: the rigid-body law.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.linalg import expm

import robodyn
import robodyn.reference
from robodyn.exceptions import InputError
from robodyn.sim.control import ComputedTorque, PDGravity, TaskSpace, quintic_reference

DATA = Path(__file__).parents[1] / "data"
OBLIQUE = DATA / "robots" / "oblique.urdf"
GRIPPER = DATA / "robots" / "mimic_gripper.urdf"
GANTRY = DATA / "gantry.urdf"
DT = 1e-3


def _reference_plant(path):
    """The reference's closed-loop right-hand side pieces, in the Robot's joint order."""
    robot = robodyn.load(path)
    model = robodyn.reference.load(path)
    order = [model.joint_names.index(name) for name in robot.joint_names]

    def to_ref(x):
        out = np.empty_like(x)
        out[order] = x
        return out

    def terms(q, v):
        q_r, v_r = to_ref(q), to_ref(v)
        mass = model.mass_matrix(q_r)[np.ix_(order, order)]
        return mass, model.coriolis_forces(q_r, v_r)[order], model.gravity(q_r)[order]

    return robot, terms


def _solve(terms, law, q0, v0, times):
    n = len(q0)

    def rhs(t, x):
        q, v = x[:n], x[n:]
        mass, cv, g = terms(q, v)
        return np.concatenate([v, np.linalg.solve(mass, law(t, q, v, mass, cv, g) - cv - g)])

    solution = solve_ivp(
        rhs, (times[0], times[-1]), np.concatenate([q0, v0]), method="DOP853", rtol=1e-10, atol=1e-12, t_eval=times
    )
    assert solution.success
    return solution.y[:n].T, solution.y[n:].T


def _linear_error(e0, de0, kp, kd, times):
    """Solution of ë + kd ė + kp e = 0 (scalar gains, vector e) at the given times."""
    n = len(e0)
    system = np.block([[np.zeros((n, n)), np.eye(n)], [-kp * np.eye(n), -kd * np.eye(n)]])
    start = np.concatenate([e0, de0])
    return np.array([(expm(system * t) @ start)[:n] for t in times])


@pytest.mark.parametrize("path", [OBLIQUE, pytest.param(GRIPPER, marks=pytest.mark.slow)], ids=["oblique", "mimic_gripper"])
def test_pd_gravity_transient_matches_an_independent_integration(path):
    robot, terms = _reference_plant(path)
    rng = np.random.default_rng(2)
    q0 = robot.random_configuration(rng) * 0.5
    v0 = rng.normal(size=robot.nv) * 0.5
    target = robot.random_configuration(rng) * 0.5
    # Gains scaled to each joint's inertia: a transient of about 10 rad/s on every joint.
    inertia = np.diag(robot.mass_matrix(q0))
    kp, kd = 100.0 * inertia, 8.0 * inertia
    trajectory = robodyn.simulate(robot, q0, v0, 0.6, DT, controller=PDGravity(robot, target, kp, kd), joint_friction=False)

    def law(t, q, v, mass, cv, g):
        return kp * (target - q) - kd * v + g

    q_ref, v_ref = _solve(terms, law, q0, v0, trajectory.t)
    span = np.max(np.abs(trajectory.q - trajectory.q[-1]))
    assert span > 0.1  # a real transient, not a robot at rest
    np.testing.assert_allclose(trajectory.q, q_ref, atol=1e-6 * span)
    np.testing.assert_allclose(trajectory.v, v_ref, atol=1e-5 * np.max(np.abs(v_ref)))


def _computed_torque_run():
    robot = robodyn.load(OBLIQUE)
    rng = np.random.default_rng(4)
    q0 = robot.random_configuration(rng) * 0.5
    v0 = rng.normal(size=robot.nv)
    reference = quintic_reference(q0 + 0.2, robot.random_configuration(rng) * 0.5, 0.4)
    kp, kd = 100.0, 12.0
    trajectory = robodyn.simulate(
        robot, q0, v0, 0.6, DT, controller=ComputedTorque(robot, reference, kp, kd), joint_friction=False
    )
    return robot, q0, v0, reference, kp, kd, trajectory


def test_computed_torque_error_follows_the_closed_loop_law():
    """Perfect model: the tracking error is the linear second-order system's, whole trajectory."""
    _, q0, v0, reference, kp, kd, trajectory = _computed_torque_run()
    desired = np.array([reference(t)[0] for t in trajectory.t])
    q_d0, v_d0, _ = reference(0.0)
    exact = _linear_error(q_d0 - q0, v_d0 - v0, kp, kd, trajectory.t)
    assert np.max(np.abs(exact)) > 0.1
    np.testing.assert_allclose(desired - trajectory.q, exact, atol=1e-6)


@pytest.mark.slow
def test_computed_torque_transient_matches_an_independent_integration():
    _, terms = _reference_plant(OBLIQUE)
    _, q0, v0, reference, kp, kd, trajectory = _computed_torque_run()

    def law(t, q, v, mass, cv, g):
        q_d, v_d, a_d = reference(t)
        return mass @ (a_d + kd * (v_d - v) + kp * (q_d - q)) + cv + g

    q_ref, v_ref = _solve(terms, law, q0, v0, trajectory.t)
    np.testing.assert_allclose(trajectory.q, q_ref, atol=1e-6)
    np.testing.assert_allclose(trajectory.v, v_ref, atol=1e-5)


def _task_space_deviation(path, frame, speed, *, flip_bias=False):
    """Largest deviation of the simulated task error from the closed-loop law's, relative to
    the largest error of the law (TaskSpace with a perfect model, starting fast)."""
    robot = robodyn.load(path)
    if flip_bias:  # the negative control: J̇ v with the wrong sign
        original = robot.frame_bias_acceleration
        robot.frame_bias_acceleration = lambda q, v, frame: -original(q, v, frame)
    rng = np.random.default_rng(6)
    q0 = robot.random_configuration(rng) * 0.4
    v0 = rng.normal(size=robot.nv) * speed
    start = robot.frame_position(q0, frame)
    target = start + np.array([0.03, -0.02, 0.025])
    kp, kd = 60.0, 12.0
    jacobian = robot.frame_jacobian(q0, frame)[:3]
    assert np.linalg.svd(jacobian, compute_uv=False)[-1] > 0.05  # full row rank: the task is reachable
    # the control's patched method lives in Python: the compiled engine (auto's choice once the
    # robot is in the compile cache) would run the controller's C twin without it
    engine = "pinocchio" if flip_bias else "auto"
    trajectory = robodyn.simulate(
        robot, q0, v0, 1.0, 2 * DT, controller=TaskSpace(robot, frame, target, kp, kd), joint_friction=False, engine=engine
    )
    error = target - robot.frame_position(trajectory.q, frame)
    exact = _linear_error(target - start, -jacobian @ v0, kp, kd, trajectory.t)
    size = np.max(np.abs(exact))
    assert np.max(np.abs(exact[-1])) < 0.05 * size  # the law settles within the run
    return np.max(np.abs(error - exact)) / size


#: (robot, frame): the gripper's frame is on the mimic finger (its Jacobian goes through the mimic map).
TASKS = [(OBLIQUE, "end_effector", 2.0), (GRIPPER, "right", 0.3)]


@pytest.mark.parametrize(("path", "frame", "speed"), TASKS, ids=["oblique", "mimic_gripper"])
def test_task_space_error_follows_the_closed_loop_law(path, frame, speed):
    """ë + kd ė + kp e = 0 for the task error e = target − p(q), over the whole transient
    (the arm starts moving fast, so the J̇ v term is large)."""
    assert _task_space_deviation(path, frame, speed) < 2e-4


@pytest.mark.parametrize(
    ("path", "frame", "speed"), [TASKS[0], pytest.param(*TASKS[1], marks=pytest.mark.slow)], ids=["oblique", "mimic_gripper"]
)
def test_task_space_with_the_wrong_bias_sign_fails_the_law(path, frame, speed):
    """The negative control of the test above: J̇ v with the wrong sign is far off."""
    assert _task_space_deviation(path, frame, speed, flip_bias=True) > 1e-2


@pytest.mark.slow
def test_a_diverging_task_space_loop_ends_with_a_robodyn_error():
    from robodyn.exceptions import RobodynError

    robot = robodyn.load(GRIPPER)
    rng = np.random.default_rng(6)
    q0 = robot.random_configuration(rng) * 0.4
    v0 = rng.normal(size=robot.nv) * 1.0
    target = robot.frame_position(q0, "right") + np.array([0.03, -0.02, 0.025])
    with np.errstate(all="ignore"), pytest.raises(RobodynError, match=r"stopped at t = .* the controller failed"):
        robodyn.simulate(robot, q0, v0, 1.0, DT, controller=TaskSpace(robot, "right", target, 60.0, 12.0))


# ------------------------------------------------------------------------------------
# Zero-order hold
# ------------------------------------------------------------------------------------
#: The gantry's dynamics from its URDF: x carries the carriage (3 kg) and the tool (1 kg),
#: z the tool alone, on perpendicular axes; gravity acts on z only.
GANTRY_MASS = np.diag([4.0, 1.0])
GANTRY_GRAVITY = np.array([0.0, 1.0 * 9.81])


def _gantry_law(t, q, v):
    return np.array([40.0 * t - 3.0 * q[0], 9.81 + 5.0 * np.sin(20.0 * t) - 2.0 * v[1]])


def test_gantry_dynamics_are_what_the_hand_computation_assumes():
    robot = robodyn.load(GANTRY)
    q = np.array([0.2, -0.1])
    np.testing.assert_allclose(robot.mass_matrix(q), GANTRY_MASS, atol=1e-12)
    np.testing.assert_allclose(robot.gravity(q), GANTRY_GRAVITY, atol=1e-12)
    np.testing.assert_allclose(robot.nonlinear_effects(q, np.array([1.0, 2.0])), GANTRY_GRAVITY, atol=1e-12)


@pytest.mark.parametrize("integrator", ["rk4", "semi-implicit-euler"])
def test_zero_order_hold_is_a_constant_torque_each_step(integrator):
    """With hold, each step applies τ(t_k, q_k, v_k) throughout: constant acceleration, so
    RK4 is exact (q += v dt + a dt²/2, v += a dt) and semi-implicit Euler is v += a dt,
    q += v_new dt."""
    robot = robodyn.load(GANTRY)
    q0, v0, dt, steps = np.array([0.1, -0.05]), np.array([0.2, 0.0]), 0.02, 25
    trajectory = robodyn.simulate(robot, q0, v0, steps * dt, dt, controller=_gantry_law, hold=True, integrator=integrator)
    q, v = q0.copy(), v0.copy()
    for k in range(steps):
        tau = _gantry_law(k * dt, q, v)
        np.testing.assert_allclose(trajectory.tau[k], tau, atol=1e-12)
        a = np.linalg.solve(GANTRY_MASS, tau - GANTRY_GRAVITY)
        if integrator == "rk4":
            q, v = q + v * dt + 0.5 * a * dt * dt, v + a * dt
        else:
            v = v + a * dt
            q = q + v * dt
        np.testing.assert_allclose(trajectory.q[k + 1], q, atol=1e-12)
        np.testing.assert_allclose(trajectory.v[k + 1], v, atol=1e-12)


def test_without_hold_the_controller_is_continuous():
    """The negative control: without hold, RK4 follows the continuous-time law (solve_ivp),
    which differs from the held one by far more than the integration error."""
    robot = robodyn.load(GANTRY)
    q0, v0, dt, steps = np.array([0.1, -0.05]), np.array([0.2, 0.0]), 0.02, 25
    continuous = robodyn.simulate(robot, q0, v0, steps * dt, dt, controller=_gantry_law)
    held = robodyn.simulate(robot, q0, v0, steps * dt, dt, controller=_gantry_law, hold=True)

    def rhs(t, x):
        q, v = x[:2], x[2:]
        return np.concatenate([v, np.linalg.solve(GANTRY_MASS, _gantry_law(t, q, v) - GANTRY_GRAVITY)])

    exact = solve_ivp(rhs, (0, steps * dt), np.concatenate([q0, v0]), rtol=1e-11, atol=1e-13, t_eval=continuous.t).y
    np.testing.assert_allclose(continuous.q, exact[:2].T, atol=1e-6)
    assert np.max(np.abs(held.v - continuous.v)) > 1e-2


def test_task_space_damps_the_motion_the_task_leaves_free():
    """The oblique arm's last joint turns its frame about the frame's origin: that motion is
    the null space, where the law is a_tool = −joint_damping v_tool, so v_tool(t) decays as
    exp(−joint_damping t) exactly (perfect model), however the task moves."""
    robot = robodyn.load(OBLIQUE)
    q0 = np.array([0.3, -0.4, 0.1, 0.5])
    assert np.allclose(robot.frame_jacobian(q0, "end_effector")[:3, 3], 0.0)
    v0 = np.array([0.5, -0.3, 0.2, 2.0])
    target = robot.frame_position(q0, "end_effector") + np.array([0.02, 0.01, -0.02])
    controller = TaskSpace(robot, "end_effector", target, 60.0, 12.0, joint_damping=4.0)
    trajectory = robodyn.simulate(robot, q0, v0, 0.5, 2 * DT, controller=controller, joint_friction=False)
    np.testing.assert_allclose(trajectory.v[:, 3], 2.0 * np.exp(-4.0 * trajectory.t), atol=1e-6)


def test_quintic_reference_is_a_rest_to_rest_motion_with_consistent_derivatives():
    start, end, duration = np.array([0.2, -1.0]), np.array([1.4, 0.5]), 0.8
    reference = quintic_reference(start, end, duration)
    h = 1e-5
    for t in np.linspace(0.01, duration - 0.01, 9):
        q_d, v_d, a_d = reference(t)
        np.testing.assert_allclose(v_d, (reference(t + h)[0] - reference(t - h)[0]) / (2 * h), atol=1e-7)
        np.testing.assert_allclose(a_d, (reference(t + h)[1] - reference(t - h)[1]) / (2 * h), atol=1e-5)
    for t, position in ((0.0, start), (-1.0, start), (duration, end), (2 * duration, end)):
        q_d, v_d, a_d = reference(t)
        np.testing.assert_allclose(q_d, position, atol=1e-15)
        assert not v_d.any() and not a_d.any()
    np.testing.assert_allclose(reference(duration / 2)[0], (start + end) / 2, atol=1e-15)  # symmetric in time


def test_task_space_damped_least_squares_bounds_the_command():
    """Damped least squares: ‖J⁺ x‖ ≤ ‖x‖ / (2 √damping) for every Jacobian, so the command
    stays bounded however close to singular the arm is (here damping = σ_min²: the bound is
    reached, and a Gram matrix J Jᵀ − damping I would be singular)."""
    robot = robodyn.load(OBLIQUE)
    q = np.array([0.3, -0.4, 0.1, 0.5])
    jacobian = robot.frame_jacobian(q, "end_effector")[:3]
    u, sigma, _ = np.linalg.svd(jacobian)
    damping = sigma[-1] ** 2
    target = robot.frame_position(q, "end_effector") + 0.01 * u[:, -1]  # along the weakest direction
    controller = TaskSpace(robot, "end_effector", target, 50.0, 10.0, damping=damping)
    zero = np.zeros(robot.nv)
    command = robot.forward_dynamics(q, zero, controller(0.0, q, zero))
    desired = 50.0 * 0.01
    assert np.linalg.norm(command) == pytest.approx(desired / (2 * np.sqrt(damping)), rel=1e-6)


SOLO_TARGET = np.array([0.1, 0.8, -1.6, -0.1, 0.8, -1.6, 0.1, -0.8, 1.6, -0.1, -0.8, 1.6])


@pytest.mark.parametrize("free_base", [True, False], ids=["free_base", "negative_control_base_held"])
def test_computed_torque_of_a_floating_robot_moves_its_joints_by_the_closed_loop_law_with_its_base_free(free_base):
    """solo12, joints only in the reference: the tracking error obeys ë + Kd ė + Kp e = 0
    while the base, free and pushed by no torque, moves as the legs make it. The negative
    control computes the torques as if the base were held (its acceleration zero)."""
    from robodyn.sim.control import free_base_torques

    robot = robodyn.load("solo12")
    rng = np.random.default_rng(5)
    q0 = robot.floating_configuration([0.1, -0.2, 0.4], [0.3, -0.2, 0.5], SOLO_TARGET + rng.normal(scale=0.2, size=12))
    v0 = np.concatenate([rng.normal(size=6) * 0.3, rng.normal(size=12)])
    kp, kd = 100.0, 12.0

    def law(t, q, v):
        command = kd * (0.0 - v[6:]) + kp * (SOLO_TARGET - q[7:])
        if free_base:
            return free_base_torques(robot, q, v, command)
        torques = robot.inverse_dynamics(q, v, np.concatenate([np.zeros(6), command]))
        torques[:6] = 0.0
        return torques

    trajectory = robodyn.simulate(robot, q0, v0, 0.5, DT, controller=law)
    exact = _linear_error(SOLO_TARGET - q0[7:], -v0[6:], kp, kd, trajectory.t)
    assert np.abs(trajectory.tau[:, :6]).max() == 0.0
    assert np.ptp(trajectory.q[:, :3], axis=0).max() > 0.1  # the base moved (it fell, and the legs pushed it)
    deviation = np.abs((SOLO_TARGET - trajectory.q[:, 7:]) - exact).max()
    assert (deviation < 1e-6) == free_base, deviation


def test_a_joint_target_of_a_floating_robot_is_its_joints_and_any_other_length_is_refused():
    from robodyn.sim.control import joint_target

    robot = robodyn.load("solo12")
    np.testing.assert_array_equal(joint_target(robot, SOLO_TARGET, "pd"), SOLO_TARGET)
    for wrong in (np.zeros(19), np.zeros(18), np.zeros(11)):
        with pytest.raises(InputError) as raised:
            joint_target(robot, wrong, "pd")
        assert "12 joint values" in str(raised.value) and "'FL_HAA'" in str(raised.value) and "'HR_KFE'" in str(raised.value)
    with pytest.raises(InputError):
        joint_target(robodyn.load("rp_arm"), [0.1, np.nan], "pd")


@pytest.mark.parametrize("compensate", [True, False], ids=["compensated", "negative_control_rigid_law"])
def test_computed_torque_compensating_the_damping_keeps_its_closed_loop_law_on_the_damped_panda(compensate):
    """The panda's joints are damped (``b`` 0.003 N m s/rad) and the plant applies it by
    default: with ``compensate_damping`` the tracking error still obeys ë + Kd ė + Kp e = 0
    (as on the rigid plant); the rigid-body law leaves it by far more."""
    robot = robodyn.load("panda", lock={"panda_finger_joint1": 0.0})
    assert robot.joint_damping.all()
    q0 = np.array([0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785])
    v0 = np.array([0.4, -0.3, 0.5, 0.2, -0.6, 0.3, 0.8])
    reference = quintic_reference(q0 + 0.1, q0 + np.array([0.3, 0.25, -0.3, 0.3, 0.2, -0.3, 0.25]), 0.3)
    kp, kd = 100.0, 12.0
    law = ComputedTorque(robot, reference, kp, kd, compensate_damping=compensate)
    trajectory = robodyn.simulate(robot, q0, v0, 0.5, DT, controller=law, limits="ignore", engine="pinocchio")
    desired = np.array([reference(t)[0] for t in trajectory.t])
    exact = _linear_error(reference(0.0)[0] - q0, -v0, kp, kd, trajectory.t)
    deviation = np.abs(desired - trajectory.q - exact).max() / np.abs(exact).max()
    assert (deviation < 1e-6) == compensate, deviation


def _inertial(mass: float, com: str) -> str:
    return f'<inertial><origin xyz="{com}"/><mass value="{mass}"/><inertia ixx="0.02" ixy="0.001" ixz="0" iyy="0.03" iyz="0.002" izz="0.025"/></inertial>'


#: A free-floating body with two damped arms (an oblique axis, non-default gravity below).
FLOATING_DAMPED = (
    f'<robot name="damped_float"><link name="body">{_inertial(2.0, "0 0 0")}</link>'
    f'<link name="a">{_inertial(0.6, "0.1 0 0")}</link><link name="b">{_inertial(0.4, "0 0.1 0.05")}</link>'
    '<joint name="ja" type="revolute"><parent link="body"/><child link="a"/><origin xyz="0.2 0 0"/><axis xyz="0 1 0"/>'
    '<limit lower="-3" upper="3" effort="100" velocity="10"/><dynamics damping="0.3"/></joint>'
    '<joint name="jb" type="revolute"><parent link="body"/><child link="b"/><origin xyz="0 0.2 0" rpy="0.2 0 0"/>'
    '<axis xyz="0.3 0 1"/><limit lower="-3" upper="3" effort="100" velocity="10"/><dynamics damping="0.2"/></joint></robot>'
)


@pytest.mark.parametrize("compensate", [True, False], ids=["compensated", "negative_control_rigid_law"])
def test_computed_torque_of_a_damped_floating_robot_compensates_its_joints_damping(compensate):
    """Base free, joints damped: with ``compensate_damping`` the joints' error obeys
    ë + Kd ė + Kp e = 0 and the base still gets no torque; the rigid law leaves the law."""
    robot = robodyn.load(FLOATING_DAMPED, floating_base=True, gravity=[0.3, -0.2, -9.7])
    assert robot.floating_base and robot.joint_damping[6:].all() and not robot.joint_damping[:6].any()
    target, kp, kd = np.array([0.4, -0.3]), 100.0, 12.0
    q0 = robot.floating_configuration([0.0, 0.0, 1.0], [0.1, -0.2, 0.3], np.array([-0.2, 0.3]))
    v0 = np.concatenate([np.zeros(6), [1.5, -2.0]])
    law = ComputedTorque(robot, lambda t: (target, np.zeros(2), np.zeros(2)), kp, kd, compensate_damping=compensate)
    trajectory = robodyn.simulate(robot, q0, v0, 0.5, DT, controller=law, limits="ignore", engine="pinocchio")
    exact = _linear_error(target - q0[7:], -v0[6:], kp, kd, trajectory.t)
    deviation = np.abs((target - trajectory.q[:, 7:]) - exact).max() / np.abs(exact).max()
    assert np.abs(trajectory.tau[:, :6]).max() == 0.0
    assert (deviation < 1e-6) == compensate, deviation
