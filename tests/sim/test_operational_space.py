"""Operational-space and impedance control, checked against their laws.

- With a perfect model the task error obeys ``ë + Kd ė + Kp e = 0`` (position exactly,
  orientation by its SO(3) logarithm): the simulated error against the matrix exponential
  over the whole transient (panda full pose with a posture, ur5 along a moving path, the
  RP arm in its plane), and on the damped panda with ``compensate_damping`` (negative
  control: the rigid-body law). Negative control: without the ``J̇ v`` term the transient is off.
- The posture acts in the null space only: ``J M⁻¹ Nᵀ = 0`` at random states (negative
  control: the kinematic projector ``I − J⁺ J`` fails it) and the task error is the same
  with and without a posture while the joints move differently.
- The final pose, measured by Pinocchio's own forward kinematics, is within 1e-6 m and
  1e-6 rad.
- Impedance: a steady external wrench deflects the frame by ``K⁻¹ F`` (within 1 %);
  negative control: a controller model with a wrong payload misses it.
- The lecture's "always resistive?": the work an external push does on the arm is
  positive under impedance and under position control, ``Fᵀ K⁻¹ F`` for the impedance.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from scipy.linalg import expm

import robodyn
from robodyn.sim import operational_space
from robodyn.sim.control import Impedance, OperationalSpace
from robodyn.sim.operational_space import damped_task_inertia, target_rotation

PANDA = {"lock": {"panda_finger_joint1": 0.0}}
#: The panda's usual ready pose (elbow bent, away from singularities), in [rad].
PANDA_READY = np.array([0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785])
UR5_START = np.array([0.3, -1.2, 1.4, -1.5, -1.4, 0.2])
DT = 2e-3
KP, KD = 400.0, 30.0  # underdamped: the transient has a shape to match


def _panda():
    return robodyn.load("panda", **PANDA), robodyn.load("panda", **PANDA)


def _pose(robot, q, frame):
    """The frame's pose by Pinocchio alone (its own data, no robodyn code)."""
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, q)
    return data.oMf[robot.model.getFrameId(frame)].copy()


def _linear_error(e0, de0, times, kp=KP, kd=KD):
    """Solution of ë + kd ė + kp e = 0 at the given times."""
    n = len(e0)
    system = np.block([[np.zeros((n, n)), np.eye(n)], [-kp * np.eye(n), -kd * np.eye(n)]])
    step = expm(system * (times[1] - times[0]))  # uniform samples: one transition matrix
    states = [np.concatenate([e0, de0])]
    for _ in times[1:]:
        states.append(step @ states[-1])
    return np.array(states)[:, :n]


def _transient_deviation(controller, trajectory):
    """Largest deviation of the simulated task error from the linear law, relative to |e(0)|."""
    errors = np.array(
        [controller.task_error(t, q, v)[0] for t, q, v in zip(trajectory.t, trajectory.q, trajectory.v, strict=True)]
    )
    e0, de0 = controller.task_error(0.0, trajectory.q[0], trajectory.v[0])
    analytic = _linear_error(e0, de0, trajectory.t)
    return float(np.abs(errors - analytic).max() / np.abs(e0).max()), errors


@pytest.fixture(scope="module")
def panda_runs():
    """Panda to a full pose from its ready pose, with and without a posture (1 s)."""
    plant, model = _panda()
    goal = PANDA_READY + np.array([0.3, 0.25, -0.3, 0.3, 0.2, -0.3, 0.25])
    target = _pose(plant, goal, plant.end_effector)
    posture = PANDA_READY + 0.2
    runs = {}
    for name, kwargs in (("posture", {"posture": posture}), ("free", {})):
        law = OperationalSpace(model, None, target.translation, orientation=target.rotation, kp=KP, kd=KD, **kwargs)
        trajectory = robodyn.simulate(
            plant, PANDA_READY, np.zeros(7), 1.2, DT, controller=law, limits="ignore", joint_friction=False
        )  # the rigid-body law (the panda's joints have damping)
        runs[name] = (law, trajectory)
    return plant, target, runs


def test_the_panda_pose_error_follows_the_linear_law_position_and_orientation(panda_runs):
    _, _, runs = panda_runs
    law, trajectory = runs["posture"]
    deviation, errors = _transient_deviation(law, trajectory)
    assert np.abs(errors[0, 3:]).max() > 0.2  # a real rotation to make, not only a shift
    assert deviation < 1e-5, deviation


@pytest.mark.parametrize("compensate", [True, False], ids=["compensated", "negative_control_rigid_law"])
def test_the_pose_error_follows_the_linear_law_on_the_damped_panda_when_the_damping_is_compensated(compensate):
    """The plant applies the panda's joint damping (its default): with ``compensate_damping``
    the transient is the rigid plant's (within 1e-6 of the law); without it, off by ~2e-3."""
    plant, model = _panda()
    assert plant.joint_damping.all()
    goal = PANDA_READY + np.array([0.3, 0.25, -0.3, 0.3, 0.2, -0.3, 0.25])
    target = _pose(plant, goal, plant.end_effector)
    law = OperationalSpace(
        model, None, target.translation, orientation=target.rotation, kp=KP, kd=KD, posture=PANDA_READY + 0.2,
        compensate_damping=compensate,
    )  # fmt: skip
    trajectory = robodyn.simulate(plant, PANDA_READY, np.zeros(7), 0.6, DT, controller=law, limits="ignore", engine="pinocchio")
    deviation, _ = _transient_deviation(law, trajectory)
    assert (deviation < 1e-6) == compensate and deviation < 1e-2, deviation


def test_the_panda_reaches_the_pose_by_pinocchios_forward_kinematics(panda_runs):
    plant, target, runs = panda_runs
    for _, trajectory in runs.values():
        reached = _pose(plant, trajectory.q[-1], plant.end_effector)
        assert np.linalg.norm(reached.translation - target.translation) < 1e-6
        assert np.linalg.norm(pin.log3(reached.rotation.T @ target.rotation)) < 1e-6
        start = _pose(plant, trajectory.q[0], plant.end_effector)
        assert np.linalg.norm(start.translation - target.translation) > 0.05  # negative control


def test_the_posture_changes_the_joints_but_not_the_task_error(panda_runs):
    _, _, runs = panda_runs
    (with_law, with_posture), (_, free) = runs["posture"], runs["free"]
    errors = [
        np.array([law.task_error(t, q, v)[0] for t, q, v in zip(run.t, run.q, run.v, strict=True)]) for law, run in runs.values()
    ]
    assert np.abs(errors[0] - errors[1]).max() < 1e-8
    assert np.abs(with_posture.q[-1] - free.q[-1]).max() > 0.05  # the posture did move the arm
    # at rest the posture's pull left in the null space, Nᵀ M (q₀ − q), vanishes only with it
    assert _posture_pull(with_law, with_posture.q[-1]) < 0.1 * _posture_pull(with_law, free.q[-1])


def _posture_pull(law, q):
    robot = law.model
    jacobian = robot.frame_jacobian(q, law.frame)
    mass = robot.mass_matrix(q)
    mass_inv_jt = np.linalg.solve(mass, jacobian.T)
    null_space = np.eye(robot.nv) - mass_inv_jt @ np.linalg.solve(jacobian @ mass_inv_jt, jacobian)
    return float(np.linalg.norm(null_space.T @ mass @ (law.posture - q)))


@pytest.mark.parametrize("rows", [3, 6], ids=["position", "pose"])
def test_the_null_space_projector_is_dynamically_consistent(rows):
    robot, _ = _panda()
    rng = np.random.default_rng(27)
    for _ in range(10):
        q = robot.random_configuration(rng)
        jacobian = robot.frame_jacobian(q, robot.end_effector)[:rows]
        mass_inv_jt = np.linalg.solve(robot.mass_matrix(q), jacobian.T)
        inertia = damped_task_inertia(jacobian @ mass_inv_jt, operational_space.TASK_DAMPING)
        dynamic = np.eye(7) - mass_inv_jt @ inertia @ jacobian
        kinematic = np.eye(7) - np.linalg.pinv(jacobian) @ jacobian
        scale = np.abs(mass_inv_jt.T).max()
        assert np.abs(mass_inv_jt.T @ dynamic.T).max() < 1e-6 * scale
        assert np.abs(mass_inv_jt.T @ kinematic.T).max() > 1e-3 * scale  # negative control


def test_the_posture_torque_never_accelerates_the_task():
    """J M⁻¹ (τ_with posture − τ_without) = 0 at random states (the controller's own Nᵀ)."""
    robot, model = _panda()
    rng = np.random.default_rng(3)
    target = _pose(robot, PANDA_READY, robot.end_effector)
    common = {"orientation": target.rotation}
    with_posture = OperationalSpace(model, None, target.translation, posture=PANDA_READY, **common)
    without = OperationalSpace(model, None, target.translation, **common)
    for _ in range(5):
        q, v = robot.random_configuration(rng), rng.normal(size=7)
        difference = with_posture(0.0, q, v) - without(0.0, q, v)
        jacobian = robot.frame_jacobian(q, robot.end_effector)
        assert np.abs(difference).max() > 1e-2
        assert np.abs(jacobian @ np.linalg.solve(robot.mass_matrix(q), difference)).max() < 1e-6 * np.abs(difference).max()


def _circle(centre, radius, speed):
    def reference(t):
        angle = speed * t
        offset = radius * np.array([np.cos(angle), np.sin(angle), 0.0])
        rate = radius * speed * np.array([-np.sin(angle), np.cos(angle), 0.0])
        return centre + offset, rate, -(speed**2) * offset

    return reference


def test_the_ur5_follows_a_moving_target_by_the_linear_law():
    plant, model = robodyn.load("ur5"), robodyn.load("ur5")
    start = _pose(plant, UR5_START, plant.end_effector).translation
    path = _circle(start + np.array([0.05, -0.03, 0.04]), 0.08, 3.0)
    law = OperationalSpace(model, None, path, kp=KP, kd=KD)
    trajectory = robodyn.simulate(plant, UR5_START, np.zeros(6), 0.6, DT, controller=law, limits="ignore")
    deviation, _ = _transient_deviation(law, trajectory)
    assert deviation < 1e-5, deviation


def test_the_ur5_reaches_a_pose_given_as_a_quaternion_by_the_linear_law():
    plant, model = robodyn.load("ur5"), robodyn.load("ur5")
    target = _pose(plant, UR5_START + np.array([0.3, -0.2, 0.25, 0.3, -0.3, 0.4]), plant.end_effector)
    quaternion = pin.Quaternion(target.rotation).coeffs()  # x, y, z, w
    law = OperationalSpace(model, None, target.translation, orientation=quaternion, kp=KP, kd=KD)
    trajectory = robodyn.simulate(plant, UR5_START, np.zeros(6), 1.2, DT, controller=law, limits="ignore")
    deviation, errors = _transient_deviation(law, trajectory)
    assert np.abs(errors[0, 3:]).max() > 0.2
    assert deviation < 1e-5, deviation
    reached = _pose(plant, trajectory.q[-1], plant.end_effector)
    assert np.linalg.norm(reached.translation - target.translation) < 1e-6
    assert np.linalg.norm(pin.log3(reached.rotation.T @ target.rotation)) < 1e-6


def test_the_rp_arm_in_its_plane_follows_the_linear_law_and_without_the_bias_term_does_not(monkeypatch):
    plant, model = robodyn.load("rp_arm"), robodyn.load("rp_arm")
    q0 = np.array([0.4, 0.1])
    target = _pose(plant, np.array([0.9, 0.25]), plant.end_effector).translation
    law = OperationalSpace(model, None, target, kp=KP, kd=KD)
    # The Python law itself (engine="pinocchio"): under "auto" its compiled twin could run.
    trajectory = robodyn.simulate(plant, q0, np.zeros(2), 0.6, DT, controller=law, limits="ignore", engine="pinocchio")
    deviation, errors = _transient_deviation(law, trajectory)
    assert np.abs(errors[0]).max() > 0.05
    assert deviation < 1e-5, deviation
    original = operational_space._frame_state

    def without_bias(*args):
        state = original(*args)
        state.bias = np.zeros(6)
        return state

    monkeypatch.setattr(operational_space, "_frame_state", without_bias)
    wrong = robodyn.simulate(plant, q0, np.zeros(2), 0.6, DT, controller=law, limits="ignore", engine="pinocchio")
    assert _transient_deviation(law, wrong)[0] > 1e-3


def test_the_task_inertia_is_damped_at_a_singularity():
    robot = robodyn.load("ur5")
    stretched = np.array([0.0, -np.pi / 2, 0.0, -np.pi / 2, 0.0, 0.0])  # elbow straight
    jacobian = robot.frame_jacobian(stretched, robot.end_effector)
    inverse = jacobian @ np.linalg.solve(robot.mass_matrix(stretched), jacobian.T)
    largest = np.linalg.eigvalsh(inverse)[-1]
    damped = damped_task_inertia(inverse, 1e-3)
    assert np.linalg.eigvalsh(damped)[-1] <= 1 / (2e-3 * largest) * (1 + 1e-9)
    with np.errstate(divide="ignore", invalid="ignore"):
        plain = damped_task_inertia(inverse, 0.0)
    assert not np.isfinite(plain).all() or np.abs(plain).max() > 1e6 * np.abs(damped).max()  # negative control
    law = OperationalSpace(robot, None, [0.3, 0.2, 0.4], orientation=[0.0, 0.0, 0.0], damping=1e-3)
    assert np.isfinite(law(0.0, stretched, np.full(6, 0.1))).all()


def test_a_target_out_of_reach_is_refused_before_simulating():
    robot = robodyn.load("ur5")
    with pytest.raises(robodyn.InputError, match="reach") as refused:
        OperationalSpace(robot, None, [3.0, 0.0, 0.5])
    assert refused.value.argument == "position"
    with pytest.raises(robodyn.InputError, match="reach"):
        Impedance(robot, None, [0.0, 0.0, 2.5])
    with pytest.raises(robodyn.InputError, match="reach"):
        OperationalSpace(robot, None, _circle(np.array([3.0, 0.0, 0.5]), 0.1, 1.0))
    with pytest.raises(robodyn.InputError, match="fixed rest position"):
        Impedance(robot, None, _circle(np.array([0.3, 0.2, 0.4]), 0.05, 1.0))
    OperationalSpace(robot, None, [0.3, 0.2, 0.4])  # negative control: a reachable point passes


def test_an_orientation_given_three_ways_is_the_same_rotation():
    rpy = np.array([0.3, -0.5, 1.2])
    matrix = target_rotation(rpy)
    quaternion = pin.Quaternion(matrix).coeffs()  # x, y, z, w
    assert np.allclose(target_rotation(quaternion), matrix)
    assert np.allclose(target_rotation(matrix), matrix)
    with pytest.raises(robodyn.InputError):
        target_rotation(2 * matrix)


STIFFNESS = np.array([400.0, 600.0, 500.0, 40.0, 60.0, 50.0])
DAMPING = np.array([60.0, 70.0, 60.0, 3.0, 3.0, 3.0])
WRENCH = np.array([8.0, -6.0, 10.0, 0.4, -0.3, 0.5])


def _impedance_run(model, plant, wrench, duration=2.5):
    rest = _pose(plant, PANDA_READY, plant.end_effector)
    law = Impedance(model, None, rest.translation, orientation=rest.rotation, stiffness=STIFFNESS, damping=DAMPING)
    push = robodyn.ExternalWrench(plant.end_effector, wrench)
    return law, robodyn.simulate(plant, PANDA_READY, np.zeros(7), duration, DT, controller=law, external=[push], limits="ignore")


def test_a_steady_wrench_deflects_the_impedance_by_the_compliance():
    plant, model = _panda()
    law, trajectory = _impedance_run(model, plant, WRENCH)
    deflection, expected = law.deflection(trajectory.q[-1]), WRENCH / STIFFNESS
    assert np.abs(deflection / expected - 1).max() < 0.01
    # negative control: the controller's model carries a payload the arm does not
    heavy = robodyn.attach_payload(model, plant.end_effector, 0.5)
    wrong_law, wrong = _impedance_run(heavy, plant, WRENCH)
    assert np.abs(wrong_law.deflection(wrong.q[-1]) / expected - 1).max() > 0.1


def test_the_rp_arm_impedance_deflects_by_the_compliance_in_its_plane():
    plant, model = robodyn.load("rp_arm"), robodyn.load("rp_arm")
    q0 = np.array([0.5, 0.2])
    rest = _pose(plant, q0, plant.end_effector).translation
    law = Impedance(model, None, rest, stiffness=[300.0, 0.0, 200.0], damping=[40.0, 0.0, 30.0])
    force = np.array([5.0, 0.0, -4.0])
    push = robodyn.ExternalWrench(plant.end_effector, force)
    trajectory = robodyn.simulate(plant, q0, np.zeros(2), 2.0, DT, controller=law, external=[push], limits="ignore")
    deflection = law.deflection(trajectory.q[-1])
    expected = np.array([5.0 / 300.0, 0.0, -4.0 / 200.0])
    assert np.abs(deflection[[0, 2]] / expected[[0, 2]] - 1).max() < 0.01


def external_work(plant, trajectory, frame, force_of_time):
    """``∫ Fᵀ ẋ dt`` of a force at a frame's origin (trapezoidal), in [J]."""
    jacobians = plant.frame_jacobian(trajectory.q, frame)[:, :3]
    power = np.array([force_of_time(t) @ (j @ v) for t, j, v in zip(trajectory.t, jacobians, trajectory.v, strict=True)])
    return float(np.sum(0.5 * np.diff(trajectory.t) * (power[1:] + power[:-1])))


def test_a_push_does_positive_work_on_the_arm_under_impedance_and_under_position_control():
    """The numbers of docs/sequel.md's "always resistive?"."""
    plant, model = _panda()
    force = np.array([8.0, -6.0, 10.0])
    push = lambda t: force if t < 1.5 - 1e-9 else np.zeros(3)  # noqa: E731
    rest = _pose(plant, PANDA_READY, plant.end_effector)
    impedance = Impedance(model, None, rest.translation, orientation=rest.rotation, stiffness=STIFFNESS, damping=DAMPING)
    position = OperationalSpace(model, None, rest.translation, orientation=rest.rotation, kp=KP, kd=2 * np.sqrt(KP))
    works = {}
    for name, law in (("impedance", impedance), ("position", position)):
        wrench = robodyn.ExternalWrench(plant.end_effector, push)
        run = robodyn.simulate(plant, PANDA_READY, np.zeros(7), 1.5, DT, controller=law, external=[wrench], limits="ignore")
        works[name] = external_work(plant, run, plant.end_effector, push)
    stored = float(force @ (force / STIFFNESS[:3]))
    assert works["impedance"] == pytest.approx(stored, rel=0.01)
    assert 0 < works["position"] < works["impedance"]
