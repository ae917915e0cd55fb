"""The momentum observer on data from an outside simulator (MuJoCo) and from robodyn's own.

MuJoCo loads the same URDF (meshes dropped; contacts, limits, damping, armature off) and
its mass matrix and gravity are first compared with robodyn's. A joint PD (with MuJoCo's
own bias forces) holds the arm while ``xfrc_applied`` pushes one link at its centre of mass
(run "push"), or moves it fast with nothing pushing (run "free"). The reference external
torques are ``Jᵀ F`` with MuJoCo's own Jacobian (``mj_jac`` at that centre of mass).
Checked on the RP arm, ur5 and panda: the estimate equals ``Jᵀ F`` within 1 % after
settling, reaches 63 % of the step in ``1/K_O``, and stays below 1 % of ``|τ_ext|`` in free
motion. Negative controls: ``C`` instead of ``Cᵀ`` in the observer, a wrong payload in its
model, the torque integrated as "sampled" although MuJoCo held it.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pytest

import robodyn
from robodyn.sim.observer import MomentumObserver, detect_collision, estimate_external_torques, external_wrench

mujoco = pytest.importorskip("mujoco")

GAIN = 50.0  # K_O in [1/s]
DT = 1e-3
PUSH_AT = 0.2
PANDA_READY = np.array([0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785])
#: robot -> (load options, holding configuration, pushed link, wrench at its centre of mass)
CASES = {
    "rp_arm": ({}, np.array([0.5, 0.15]), "link2", [0.0, 0.0, -15.0, 0.0, 0.0, 0.0]),
    "ur5": ({}, np.array([0.3, -1.2, 1.4, -1.5, -1.4, 0.2]), "forearm_link", [10.0, -8.0, 12.0, 0.0, 0.0, 0.0]),
    "panda": ({"lock": {"panda_finger_joint1": 0.0}}, PANDA_READY, "panda_link5", [10.0, -8.0, 12.0, 0.5, 0.0, 0.0]),
}


def mujoco_model(robot):
    """MuJoCo's model of the robot's URDF: meshes dropped, contacts, limits, damping off."""
    root = ET.fromstring(robot.urdf)
    for element in [*root.iter("link"), *root.iter("joint")]:
        for child in [c for c in element if c.tag in ("visual", "collision", "dynamics", "safety_controller", "calibration")]:
            element.remove(child)
    extension = ET.SubElement(root, "mujoco")
    ET.SubElement(extension, "compiler", {"discardvisual": "true", "fusestatic": "false", "balanceinertia": "false"})
    model = mujoco.MjModel.from_xml_string(ET.tostring(root, encoding="unicode"))
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT | mujoco.mjtDisableBit.mjDSBL_LIMIT
    model.opt.gravity[:] = robot.gravity_vector
    model.dof_damping[:] = model.dof_armature[:] = model.dof_frictionloss[:] = 0.0
    model.opt.timestep = DT
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    return model


def mujoco_run(robot, model, q0, body, wrench, *, push_at, duration, amplitude=0.0, frequency=0.8):
    """PD about q0 + amplitude sin(2π f t) in MuJoCo; the torque is held over each step."""
    data = mujoco.MjData(model)
    data.qpos[:] = q0
    link = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, body)
    inertia = robot.mass_matrix(q0)
    omega = 2 * np.pi * frequency
    rows: dict[str, list] = {"t": [], "q": [], "v": [], "tau": [], "ext": []}
    steps = round(duration / DT)
    for step in range(steps + 1):
        t = data.time
        mujoco.mj_forward(model, data)
        q_d, v_d, a_d = (
            q0 + amplitude * np.sin(omega * t),
            amplitude * omega * np.cos(omega * t),
            -amplitude * omega**2 * np.sin(omega * t),
        )
        tau = inertia @ (a_d + 400.0 * (q_d - data.qpos) + 40.0 * (v_d - data.qvel)) + data.qfrc_bias
        pushing = push_at is not None and t >= push_at - 1e-9
        data.xfrc_applied[link] = wrench if pushing else 0.0
        linear, angular = np.zeros((3, model.nv)), np.zeros((3, model.nv))
        mujoco.mj_jac(model, data, linear, angular, data.xipos[link], link)
        for key, value in (("t", t), ("q", data.qpos.copy()), ("v", data.qvel.copy()), ("tau", tau)):
            rows[key].append(value)
        rows["ext"].append(np.vstack([linear, angular]).T @ np.asarray(wrench) if pushing else np.zeros(model.nv))
        data.qfrc_applied[:] = tau
        if step < steps:
            mujoco.mj_step(model, data)
    run = {key: np.array(value) for key, value in rows.items()}
    run["trajectory"] = robodyn.Trajectory(
        run["t"], run["q"], run["v"], np.zeros_like(run["v"]), run["tau"], list(robot.joint_names), robot.name
    )
    return run


@pytest.fixture(scope="module", params=list(CASES))
def case(request):
    options, q0, body, wrench = CASES[request.param]
    robot = robodyn.load(request.param, **options)
    model = mujoco_model(robot)
    push = mujoco_run(robot, model, q0, body, wrench, push_at=PUSH_AT, duration=0.7)
    free = mujoco_run(robot, model, q0, body, wrench, push_at=None, duration=1.0, amplitude=0.5)
    return robot, model, push, free


def figures(robot, push, free, **options):
    """The three figures: settled error, fraction of the step at 1/K_O, free-motion residual."""
    estimate = estimate_external_torques(robot, push["trajectory"], gain=GAIN, **options)
    reference = push["ext"]
    size = float(np.linalg.norm(reference[-1]))
    settled = push["t"] >= push["t"][-1] - 0.1
    k = int(np.searchsorted(push["t"], PUSH_AT + 1 / GAIN - 1e-9))
    fraction = float(estimate[k] @ reference[k] / (reference[k] @ reference[k]))
    quiet = estimate_external_torques(robot, free["trajectory"], gain=GAIN, **options)
    return (
        float(np.abs(estimate[settled] - reference[settled]).max() / size),
        fraction,
        float(np.abs(quiet).max() / size),
    )


def test_mujoco_has_the_same_mass_matrix_and_gravity(case):
    robot, model, _, _ = case
    data = mujoco.MjData(model)
    for q in robot.random_configuration(np.random.default_rng(4), 5):
        data.qpos[:] = q
        mujoco.mj_forward(model, data)
        mass = np.zeros((model.nv, model.nv))
        mujoco.mj_fullM(model, data, mass)
        assert np.abs(mass - robot.mass_matrix(q)).max() < 1e-9 * np.abs(mass).max()
        assert np.abs(data.qfrc_bias - robot.gravity(q)).max() < 1e-9 * np.abs(data.qfrc_bias).max()


def test_the_observer_recovers_a_mujoco_push_with_a_first_order_lag(case):
    robot, _, push, free = case
    settled, fraction, quiet = figures(robot, push, free)
    assert settled < 0.01
    assert fraction == pytest.approx(1 - np.exp(-1), abs=0.01)
    assert quiet < 0.01
    assert np.abs(free["v"]).max() > 2.0  # free motion fast enough for C v to matter


def test_c_instead_of_its_transpose_fails_in_free_motion(case, monkeypatch):
    robot, _, push, free = case
    coriolis = robot.coriolis_matrix
    monkeypatch.setattr(robot, "coriolis_matrix", lambda q, v: np.swapaxes(coriolis(q, v), -1, -2))
    assert figures(robot, push, free)[2] > 0.1


def test_a_wrong_payload_in_the_model_fails_after_settling(case):
    robot, _, push, free = case
    heavy = robodyn.attach_payload(robot, robot.end_effector, 0.5)
    settled, _, quiet = figures(heavy, push, free)
    assert settled > 0.1 and quiet > 0.1


def test_the_torque_taken_as_sampled_when_it_was_held_misses_the_free_motion(case):
    robot, _, push, free = case
    assert figures(robot, push, free, torque="sampled")[2] > 0.03


def test_the_collision_is_detected_at_the_push_on_the_pushed_link():
    robot = robodyn.load("panda", **CASES["panda"][0])
    _, q0, body, wrench = CASES["panda"]
    push = mujoco_run(robot, mujoco_model(robot), q0, body, wrench, push_at=PUSH_AT, duration=0.4)
    estimate = estimate_external_torques(robot, push["trajectory"], gain=GAIN)
    contact = detect_collision(robot, push["t"], estimate, 0.5)
    assert contact is not None
    assert PUSH_AT < contact.time < PUSH_AT + 1 / GAIN
    assert contact.dof == "panda_joint5"  # panda_link5 hangs from it
    assert detect_collision(robot, push["t"], estimate, 1e3) is None  # negative control


def test_the_online_observer_in_simulate_gives_the_wrench_at_the_frame():
    robot = robodyn.load("ur5")
    q0 = CASES["ur5"][1]
    frame = robot.end_effector
    wrench = np.array([6.0, -4.0, 9.0, 0.3, -0.2, 0.4])
    inertia = robot.mass_matrix(q0)
    hold = lambda t, q, v: inertia @ (400.0 * (q0 - q) - 40.0 * v) + robot.gravity(q)  # noqa: E731
    observer = MomentumObserver(robot, GAIN)
    push = robodyn.ExternalWrench(frame, lambda t: wrench if t >= PUSH_AT - 1e-9 else np.zeros(6))
    trajectory = robodyn.simulate(robot, q0, np.zeros(6), 0.8, DT, controller=observer.wrap(hold), external=[push], hold=True)
    residuals = np.array(observer.residuals)
    assert len(residuals) == len(trajectory) - 1  # one update a step
    offline = estimate_external_torques(robot, trajectory, gain=GAIN)
    assert np.abs(offline[:-1] - residuals).max() < 1e-9 * np.abs(residuals).max()
    estimated = external_wrench(robot, trajectory.q[-2], residuals[-1], frame)
    assert np.abs(estimated - wrench).max() < 0.01 * np.abs(wrench).max()
    with pytest.raises(robodyn.InputError, match="hold=True"):  # Runge-Kutta stages are no samples
        robodyn.simulate(robot, q0, np.zeros(6), 0.01, DT, controller=MomentumObserver(robot, GAIN).wrap(hold))


def test_the_sampled_rule_fits_a_torque_that_varies_within_the_step():
    """robodyn.simulate without hold evaluates the controller at every Runge–Kutta stage."""
    robot = robodyn.load("rp_arm")
    q0 = CASES["rp_arm"][1]
    inertia = robot.mass_matrix(q0)
    omega = 2 * np.pi * 0.8
    swing = lambda t, q, v: inertia @ (400.0 * (q0 + np.array([0.5, 0.1]) * np.sin(omega * t) - q) - 40.0 * v) + robot.gravity(q)  # noqa: E731
    force = np.array([0.0, 0.0, -15.0])
    push = robodyn.ExternalWrench(robot.end_effector, lambda t: force if t >= 0.5 - 1e-9 else np.zeros(3))
    trajectory = robodyn.simulate(robot, q0, np.zeros(2), 1.0, DT, controller=swing, external=[push])
    before = trajectory.t < 0.5 - 1e-9
    reference = np.array([robot.wrench_torques(q, robot.end_effector, force) for q in trajectory.q])
    reference[before] = 0.0
    size = np.abs(reference).max()
    lagged = np.zeros_like(reference)  # the reference through the observer's ideal lag
    decay = np.exp(-GAIN * DT)
    for k in range(len(reference) - 1):
        lagged[k + 1] = decay * lagged[k] + (1 - decay) * reference[k]
    sampled = estimate_external_torques(robot, trajectory, gain=GAIN, torque="sampled")
    assert np.abs(sampled[before]).max() < 0.001 * size
    assert np.abs(sampled - lagged).max() < 0.01 * size
    held = estimate_external_torques(robot, trajectory, gain=GAIN, torque="held")  # negative control
    assert np.abs(held[before]).max() > 0.01 * size  # fails the 1 % check


def test_bad_observer_inputs_are_refused_by_name():
    robot = robodyn.load("rp_arm")
    trajectory = robodyn.Trajectory(
        np.array([0.0, 0.1]), np.zeros((2, 2)), np.zeros((2, 2)), np.zeros((2, 2)), None, ["joint1", "joint2"]
    )
    with pytest.raises(robodyn.InputError, match="tau"):
        estimate_external_torques(robot, trajectory, gain=GAIN)
    trajectory.tau = np.zeros((2, 2))
    for options, name in (
        ({"gain": -1.0}, "gain"),
        ({"gain": [1.0, 2.0, 3.0]}, "gain"),
        ({"gain": GAIN, "torque": "zoh"}, "torque"),
    ):
        with pytest.raises(robodyn.InputError) as refused:
            estimate_external_torques(robot, trajectory, **options)
        assert refused.value.argument == name
    # an arm that stays still with no motor torque is held by the environment: r -> G(q)
    t = np.arange(400) * DT
    still = robodyn.Trajectory(
        t, np.full((400, 2), 0.3), np.zeros((400, 2)), np.zeros((400, 2)), np.zeros((400, 2)), ["joint1", "joint2"]
    )
    estimate = estimate_external_torques(robot, still, gain=GAIN)
    assert np.abs(estimate[-1] - robot.gravity(np.full(2, 0.3))).max() < 1e-6 * np.abs(robot.gravity(np.full(2, 0.3))).max()
    with pytest.raises(robodyn.InputError, match="threshold"):
        detect_collision(robot, t, estimate, -1.0)
