"""Compiled controllers against the Python engine: the same trajectory over the whole run."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import robodyn
from robodyn.compiled import compile
from robodyn.compiled.simulation import compiled_controller, has_twin, simulate_compiled
from robodyn.exceptions import CompileError
from robodyn.sim.control import ComputedTorque, Impedance, OperationalSpace, PDGravity, TaskSpace, quintic_reference
from tests.compiled_helpers import shared_cache

#: The issue's bar: the two engines' trajectories agree to 1e-9 at every sample.
TOLERANCE = 1e-9
PANDA_ARM = {"lock": {"panda_finger_joint1": 0.0}}


@pytest.fixture(scope="module", autouse=True)
def cache():
    """The session's compile cache (never the user's)."""
    with shared_cache() as folder:
        yield folder


def controllers(robot, rng: np.random.Generator) -> dict[str, object]:
    """Each controller, aimed at a reachable pose, on the robot's own model."""
    frame = robot.end_effector
    goal = robot.random_configuration(rng)
    target = robot.frame_position(goal, frame)
    rotation = compile(robot).frame_rotation(goal, frame) if robot.nv >= 6 else None
    posture = robot.random_configuration(rng) if robot.nv >= 6 else None
    return {
        "pd": PDGravity(robot, goal, kp=80.0, kd=15.0),
        "computed-torque": ComputedTorque(robot, quintic_reference(np.zeros(robot.nv), goal, 0.3)),
        "task-space": TaskSpace(robot, frame, target, kp=60.0, kd=14.0),
        "operational-space": OperationalSpace(robot, frame, target, orientation=rotation, posture=posture, kp=60.0, kd=14.0),
        "impedance": Impedance(robot, frame, target, orientation=rotation),
    }


def deviation(python, compiled) -> float:
    """The largest difference of positions and velocities (absolute) and torques (relative) over the run."""
    torque_scale = max(1.0, float(np.abs(python.tau).max()))
    return max(
        float(np.abs(python.q - compiled.q).max()),
        float(np.abs(python.v - compiled.v).max()),
        float(np.abs(python.tau - compiled.tau).max()) / torque_scale,
    )


def runs(robot, controller, q0, duration, dt=1e-3, integrator="rk4", twin=None):
    python = robodyn.simulate(
        robot, q0, np.zeros(robot.nv), duration, dt, controller=controller, integrator=integrator, limits="ignore",
        engine="pinocchio", joint_friction=False,  # the Python engine against the rigid-body loop in C
    )  # fmt: skip
    law = twin if twin is not None else compiled_controller(controller)
    compiled = simulate_compiled(
        compile(robot), q0, np.zeros(robot.nv), duration, dt, controller=law, integrator=integrator, joint_friction=False
    )
    return python, compiled


@pytest.mark.parametrize("kind", ["pd", "computed-torque", "task-space", "operational-space", "impedance"])
@pytest.mark.parametrize(
    ("source", "options", "duration"),
    [pytest.param("rp_arm", {}, 1.0, id="rp_arm"), pytest.param("panda", PANDA_ARM, 0.3, id="panda_arm", marks=pytest.mark.slow)],
)
def test_each_compiled_controller_follows_the_python_engine_over_the_whole_run(kind, source, options, duration, rng):
    robot = robodyn.load(source, **options)
    law = controllers(robot, rng)[kind]
    q0 = robot.random_configuration(rng)
    python, compiled = runs(robot, law, q0, duration)
    assert deviation(python, compiled) <= TOLERANCE
    assert np.abs(python.q[-1] - python.q[0]).max() > 1e-3  # the controller moved the arm


@pytest.mark.slow
def test_a_mismatched_model_non_default_gravity_and_semi_implicit_euler_still_agree(rng):
    """The controller's model carries a payload the plant does not; gravity is tilted."""
    plant = robodyn.load("panda", **PANDA_ARM, gravity=[0.4, -0.3, -9.7])
    model = robodyn.attach_payload(plant, "panda_link7", 1.5, com=[0.01, 0.02, 0.05])
    for kind in ("operational-space", "impedance"):
        law = controllers(model, rng)[kind]
        python, compiled = runs(plant, law, plant.random_configuration(rng), 0.2, integrator="semi-implicit-euler")
        assert deviation(python, compiled) <= TOLERANCE


def test_negative_control_a_twin_with_another_gain_departs_from_the_python_run(rng):
    robot = robodyn.load("rp_arm")
    law = controllers(robot, rng)["task-space"]
    twin = compiled_controller(law)
    python, compiled = runs(robot, law, robot.random_configuration(rng), 0.5, twin=dataclasses.replace(twin, kp=twin.kp * 1.0001))
    assert deviation(python, compiled) > TOLERANCE


def test_a_controller_without_a_twin_is_refused_in_one_sentence():
    robot = robodyn.load("rp_arm")
    with pytest.raises(CompileError, match="no compiled twin"):
        compiled_controller(lambda t, q, v: np.zeros(robot.nv))
    path = OperationalSpace(
        robot, None, lambda t: (robot.frame_position(np.zeros(robot.nv), robot.end_effector), np.zeros(3), np.zeros(3))
    )
    with pytest.raises(CompileError, match="fixed target"):
        compiled_controller(path)
    assert not has_twin(path) and has_twin(TaskSpace(robot, None, [0.7, 0.0, 0.7]))


def _lqr(robot, rng, **options):
    """An LQR about a random held configuration (every joint actuated unless told)."""
    from robodyn.sim.control import LQR

    q_eq = robot.random_configuration(rng)
    return LQR(robot, q_eq, np.zeros(robot.nv), 10.0, 0.1, **options), q_eq


@pytest.mark.parametrize(
    ("source", "options"),
    [
        pytest.param("rp_arm", {"gravity": [0.8, -0.5, -9.6]}, id="rp_arm"),
        pytest.param("panda", {}, id="panda_with_a_mimic_finger", marks=pytest.mark.slow),
    ],
)
def test_the_compiled_lqr_follows_the_python_engine_over_the_whole_run(source, options, rng):
    robot = robodyn.load(source, **options)
    law, q_eq = _lqr(robot, rng)
    python, compiled = runs(robot, law, q_eq + 0.05 * rng.normal(size=robot.nv), 1.0)
    assert deviation(python, compiled) <= TOLERANCE
    assert np.abs(python.q[-1] - python.q[0]).max() > 1e-3  # the regulator moved the arm back


def test_the_compiled_lqr_leaves_unactuated_joints_free_and_holds_like_the_python_engine(rng):
    """An acrobot-like design (the second joint alone actuated, a discrete gain sampled and
    held once a step): the same trajectory, zero torque on the first joint; negative
    control: the twin with another gain departs."""
    from robodyn.sim.control import LQR

    robot = robodyn.load("double_pendulum_continuous", gravity=[1.2, 0.0, -9.7])
    up = np.array([np.pi, 0.0])
    law = LQR(robot, up, np.zeros(2), np.diag([10.0, 10.0, 1.0, 1.0]), 0.5, dt=2e-3, actuated=[robot.joint_names[1]])
    q0, v0 = up + np.array([0.02, -0.01]), np.zeros(2)
    python = robodyn.simulate(
        robot, q0, v0, 1.5, 2e-3, controller=law, limits="ignore", engine="pinocchio", joint_friction=False, hold=True
    )
    twin = compiled_controller(law)
    compiled = simulate_compiled(compile(robot), q0, v0, 1.5, 2e-3, controller=twin, hold=True, joint_friction=False)
    assert deviation(python, compiled) <= TOLERANCE
    assert np.abs(compiled.tau[:, 0]).max() == 0.0 and np.abs(compiled.tau[:, 1]).max() > 1e-3
    assert np.abs(python.q - up).max() < 0.05  # held near the upright (it falls without control)
    other = dataclasses.replace(twin, gain=twin.gain * 1.0001)
    departed = simulate_compiled(compile(robot), q0, v0, 1.5, 2e-3, controller=other, hold=True, joint_friction=False)
    assert deviation(python, departed) > TOLERANCE


#: A damped robot small enough to compile in the fast tier (damping 0.05 N m s/rad a joint).
DAMPED = "double_pendulum_continuous"


def _damped_laws(robot) -> dict[str, object]:
    """The model-based laws, compensating the model's joint damping (``b ∘ v``)."""
    q_goal = np.array([0.6, -0.4])
    target = robot.frame_position(q_goal, robot.end_effector)
    return {
        "computed-torque": ComputedTorque(robot, quintic_reference(np.zeros(2), q_goal, 0.3), compensate_damping=True),
        "task-space": TaskSpace(robot, None, target, kp=60.0, kd=14.0, compensate_damping=True),
        "operational-space": OperationalSpace(robot, None, target, kp=60.0, kd=14.0, compensate_damping=True),
        "impedance": Impedance(robot, None, target, compensate_damping=True),
    }


@pytest.mark.parametrize("kind", ["computed-torque", "task-space", "operational-space", "impedance"])
def test_each_twin_compensates_the_joint_damping_as_the_python_law_does(kind):
    """On a damped plant (its damping applied in both engines), from a moving start: the
    twin's torque at the first state within 1e-12 of the Python law's, the runs within 1e-9;
    negative control: the twin without the damping vector departs by about b v."""
    robot = robodyn.load(DAMPED, gravity=[0.6, 0.0, -9.7])
    assert robot.joint_damping.all()
    law = _damped_laws(robot)[kind]
    q0, v0 = np.array([0.2, 0.3]), np.array([1.5, -2.0])
    python = robodyn.simulate(robot, q0, v0, 0.5, 1e-3, controller=law, limits="ignore", engine="pinocchio")
    twin = compiled_controller(law)
    assert np.array_equal(twin.viscous, robot.joint_damping)
    compiled = simulate_compiled(compile(robot), q0, v0, 0.5, 1e-3, controller=twin)
    np.testing.assert_allclose(python.tau[0], law(0.0, q0, v0), rtol=0, atol=1e-12)
    assert np.abs(compiled.tau[0] - python.tau[0]).max() <= 1e-12 * max(1.0, np.abs(python.tau[0]).max())
    assert deviation(python, compiled) <= TOLERANCE
    rigid = simulate_compiled(compile(robot), q0, v0, 0.5, 1e-3, controller=dataclasses.replace(twin, viscous=None))
    assert np.abs(rigid.tau[0] - python.tau[0]).max() == pytest.approx(np.abs(robot.joint_damping * v0).max(), rel=1e-9)


def test_the_floating_computed_torque_twin_compensates_the_joints_damping_as_the_python_law():
    """A free body with two damped arms: the twin carries the joints' damping (not the base's
    six zeros) and gives the Python law's run; negative control: without it, it departs."""
    from tests.sim.test_control import FLOATING_DAMPED

    robot = robodyn.load(FLOATING_DAMPED, floating_base=True, gravity=[0.3, -0.2, -9.7])
    q0 = robot.floating_configuration([0.0, 0.0, 1.0], [0.1, -0.2, 0.3], np.array([-0.2, 0.3]))
    v0 = np.concatenate([0.2 * np.ones(6), [1.5, -2.0]])
    law = ComputedTorque(robot, quintic_reference(q0[7:], np.array([0.4, -0.3]), 0.3), compensate_damping=True)
    python = robodyn.simulate(robot, q0, v0, 0.4, 1e-3, controller=law, limits="ignore", engine="pinocchio")
    twin = compiled_controller(law)
    assert np.array_equal(twin.viscous, robot.joint_damping[6:])
    compiled = simulate_compiled(compile(robot), q0, v0, 0.4, 1e-3, controller=twin)
    assert np.abs(compiled.tau[0] - python.tau[0]).max() <= 1e-12 * np.abs(python.tau[0]).max()
    assert deviation(python, compiled) <= TOLERANCE
    rigid = simulate_compiled(compile(robot), q0, v0, 0.4, 1e-3, controller=dataclasses.replace(twin, viscous=None))
    assert np.abs(rigid.tau[0] - python.tau[0]).max() == pytest.approx(np.abs(robot.joint_damping * v0).max(), rel=1e-9)
