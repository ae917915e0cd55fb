"""Both engines give the same trajectory for every controller; sampling is explicit; auto chooses.

- A Python controller in the compiled engine is called at every integrator stage, as in
  the Pinocchio engine (negative control: the old once-a-step sampling is far off).
- ``control_period=`` samples and holds in either engine, and the summary says so.
- ``engine="auto"`` runs the compiled engine only where the whole loop runs in C, and
  gives the Pinocchio engine's trajectory; the summary's real-time factor is the loop's.
"""

from __future__ import annotations

import shutil

import numpy as np
import pytest

import robodyn
from robodyn.exceptions import InputError
from robodyn.sim.control import PDGravity, TaskSpace
from robodyn.sim.experiment import CONTROLLERS, controller_model, run_simulation
from robodyn.sim.simulation import ExternalWrench, choose_engine, simulate, simulate_run

pytestmark = pytest.mark.skipif(shutil.which("cc") is None and shutil.which("gcc") is None, reason="no C compiler")
DT = 1e-3


def _target(robot, controller: str) -> list[float]:
    q0 = robot.default_configuration()
    if controller in ("pd", "computed-torque"):
        return (q0 + 0.3).tolist()
    if controller == "lqr":
        return (q0 + 0.05).tolist()
    return (robot.frame_position(q0, robot.end_effector) + np.array([0.05, -0.04, -0.06])).tolist()


def _runs(name: str, controller: str, **options):
    robot = robodyn.load(name)
    target = None if controller == "passive" else _target(robot, controller)
    settings = {"controller": controller, "target": target, "duration": 0.15, "limits": "ignore", **options}
    return [run_simulation(robot, engine=engine, **settings) for engine in ("pinocchio", "compiled")]


@pytest.mark.parametrize("name", ["rp_arm", "ur5"])
@pytest.mark.parametrize(
    "controller", [name for name in CONTROLLERS if name != "stand"]
)  # stand: a floating robot on a ground, Pinocchio only
def test_every_controller_gives_the_same_trajectory_in_both_engines(name, controller):
    (python, python_summary), (compiled, compiled_summary) = _runs(name, controller)
    assert (python_summary.engine, compiled_summary.engine) == ("pinocchio", "compiled")
    scale = max(1.0, float(np.abs(python.q).max()))
    np.testing.assert_allclose(compiled.q, python.q, rtol=0, atol=1e-9 * scale)
    np.testing.assert_allclose(compiled.v, python.v, rtol=0, atol=1e-9 * max(1.0, float(np.abs(python.v).max())))
    np.testing.assert_allclose(compiled.tau, python.tau, rtol=0, atol=1e-9 * max(1.0, float(np.abs(python.tau).max())))
    assert compiled_summary.control_period is None  # evaluated at every stage, not sampled
    if controller != "passive":
        assert "every integrator stage" in compiled_summary.text()


def test_the_old_once_a_step_sampling_is_not_what_the_engines_agree_on():
    """Negative control: the compiled engine sampling a Python controller once a step (as it
    silently did) is off the continuous run by far more than the 1e-9 the engines keep."""
    robot = robodyn.load("ur5")
    q0 = robot.default_configuration()
    law = TaskSpace(controller_model(robot), robot.end_effector, np.asarray(_target(robot, "task-space")))
    continuous = simulate(robot, q0, np.zeros(6), 0.15, DT, controller=law, engine="pinocchio", limits="ignore")
    sampled = simulate(robot, q0, np.zeros(6), 0.15, DT, controller=law, engine="compiled", control_period=DT, limits="ignore")
    assert np.abs(sampled.tau - continuous.tau).max() > 1e-4


def test_a_control_period_samples_and_holds_in_both_engines_and_the_summary_says_so():
    (python, python_summary), (compiled, compiled_summary) = _runs("rp_arm", "task-space", control_period=5 * DT)
    np.testing.assert_allclose(compiled.q, python.q, rtol=0, atol=1e-9)
    for summary in (python_summary, compiled_summary):
        assert summary.control_period == pytest.approx(5 * DT)
        assert "sampled every 0.005 s and held" in summary.text()
        assert summary.to_dict()["control_period_s"] == pytest.approx(5 * DT)
    blocks = python.tau[:-1].reshape(-1, 5, python.tau.shape[1])  # held for 5 steps at a time
    assert np.array_equal(blocks, np.repeat(blocks[:, :1], 5, axis=1))
    assert not np.array_equal(blocks[0, 0], blocks[1, 0])
    (continuous, _), _ = _runs("rp_arm", "task-space")
    assert np.abs(continuous.q - python.q).max() > 1e-6  # holding changes the run


def test_a_control_period_is_refused_unless_whole_steps_and_a_controller():
    robot = robodyn.load("rp_arm")
    q0 = robot.default_configuration()
    law = PDGravity(controller_model(robot), q0 + 0.1)
    for engine in ("pinocchio", "compiled"):
        with pytest.raises(InputError, match="control_period"):
            simulate(robot, q0, np.zeros(2), 0.01, DT, controller=law, control_period=1.5 * DT, engine=engine)
        with pytest.raises(InputError, match="control_period"):
            simulate(robot, q0, np.zeros(2), 0.01, DT, control_period=DT, engine=engine)


def test_auto_runs_the_compiled_engine_only_where_the_whole_loop_runs_in_c(monkeypatch, tmp_path):
    robot = robodyn.load("rp_arm")
    robodyn.compile(robot)  # auto uses compiled robots, never starts a cold compile
    q0 = robot.default_configuration()
    pd = PDGravity(controller_model(robot), q0 + 0.2)
    task = TaskSpace(controller_model(robot), robot.end_effector, np.array([0.7, 0.0, 0.7]))
    assert choose_engine(robot, None)[0] == "compiled"
    assert choose_engine(robot, pd)[0] == "compiled"
    assert choose_engine(robot, pd, every=5)[0] == "pinocchio"  # sampled every 5 steps: Python
    assert choose_engine(robot, task)[0] == "compiled"  # task space has a compiled twin

    def custom(t, q, v):
        return -v

    assert choose_engine(robot, custom) == (
        "pinocchio",
        "a Python controller (called from Python at every stage in either engine)",
    )
    assert "external" in choose_engine(robot, None, external=[ExternalWrench(robot.end_effector, [1.0, 0, 0])])[1]
    assert "enforced" in choose_engine(robot, None, limits="enforce")[1]
    solo12 = robodyn.load("solo12")  # a floating base runs in C passive or under PD / computed torque only
    assert "floating" in choose_engine(solo12, TaskSpace(solo12, "FL_FOOT", np.zeros(3)))[1]
    monkeypatch.setenv("CC", "no-such-compiler-here")
    assert choose_engine(robot, pd)[0] == "pinocchio" and "compiler" in choose_engine(robot, pd)[1]
    monkeypatch.delenv("CC")
    monkeypatch.setenv("ROBODYN_CACHE", str(tmp_path))  # an empty cache: nothing compiled yet
    assert choose_engine(robot, pd)[0] == "pinocchio" and "not compiled yet" in choose_engine(robot, pd)[1]
    monkeypatch.undo()
    auto, run = simulate_run(robot, q0, np.zeros(2), 0.3, DT, controller=pd, limits="ignore")
    python = simulate(robot, q0, np.zeros(2), 0.3, DT, controller=pd, limits="ignore", engine="pinocchio")
    assert run.engine == "compiled" and run.controller_in_c
    np.testing.assert_allclose(auto.q, python.q, rtol=0, atol=1e-9)


def test_the_real_time_factor_is_the_loops_and_start_up_is_reported_apart():
    _, summary = run_simulation(robodyn.load("rp_arm"), controller="pd", target=[0.5, 0.05], duration=0.2, limits="ignore")
    assert summary.loop_time is not None and summary.loop_time > 0
    assert summary.real_time_factor == pytest.approx(0.2 / summary.loop_time)
    assert summary.compile_time > 0  # the engine's choice and the cached kernels' load, apart from the loop
    data = summary.to_dict()
    assert {"loop_time_s", "compile_time_s", "startup_time_s", "engine_reason"} <= set(data)
    assert "(loop only)" in summary.text() and "engine: compiled" in summary.text()
    assert summary.with_startup(1.25).to_dict()["startup_time_s"] == 1.25
    assert "start-up 1.25 s" in summary.with_startup(1.25).text()


@pytest.mark.parametrize(
    ("engine", "error", "sentence"),
    [
        ("pinocchio", robodyn.exceptions.ControllerFailedError, "the controller failed"),
        ("compiled", robodyn.exceptions.SimulationError, "diverged at t = .* is no longer finite"),
    ],
)
def test_a_controller_overflowing_on_a_blown_up_state_stops_the_run_in_one_sentence(engine, error, sentence):
    """ur5 driven past a singular posture at dt = 1 ms: the task-space law's J̇ q̇ overflows.
    In Python that is a NonFiniteResultError inside the controller (ControllerFailedError);
    its compiled twin runs in C, where the loop stops at the first non-finite state."""
    robot = robodyn.load("ur5")
    q0 = robot.default_configuration()
    target = (robot.frame_position(q0, robot.end_effector) + np.array([0.1, -0.1, -0.1])).tolist()
    with pytest.raises(error, match=sentence):
        run_simulation(robot, controller="task-space", target=target, duration=0.4, limits="ignore", engine=engine)


@pytest.mark.parametrize("controller", ["computed-torque", "osc", "impedance"])
@pytest.mark.parametrize("joint_friction", [True, False], ids=["damped", "rigid"])
def test_a_damped_robot_gives_the_same_trajectory_in_both_engines_its_damping_compensated_when_applied(
    controller, joint_friction
):
    """run_simulation sets ``compensate_damping`` from ``joint_friction``: both engines agree
    (the C twins add the same ``b ∘ v``), and computed torque, started on its reference at
    rest, tracks it to rounding on the damped plant as on the rigid one."""
    robot = robodyn.load("double_pendulum_continuous", gravity=[0.6, 0.0, -9.7])
    assert robot.joint_damping.all()
    joints = np.array([0.6, -0.4])
    target = joints if controller == "computed-torque" else robot.frame_position(joints, robot.end_effector)
    settings = {"controller": controller, "target": target.tolist(), "duration": 0.4, "limits": "ignore"}
    (python, _), (compiled, summary) = [
        run_simulation(robot, engine=engine, joint_friction=joint_friction, **settings) for engine in ("pinocchio", "compiled")
    ]
    assert summary.engine == "compiled"
    np.testing.assert_allclose(compiled.q, python.q, rtol=0, atol=1e-9 * max(1.0, float(np.abs(python.q).max())))
    np.testing.assert_allclose(compiled.tau, python.tau, rtol=0, atol=1e-9 * max(1.0, float(np.abs(python.tau).max())))
    if controller == "computed-torque":
        from robodyn.sim.control import quintic_reference

        reference = quintic_reference(np.zeros(2), joints, 0.2)
        assert np.abs(np.array([reference(t)[0] for t in python.t]) - python.q).max() < 1e-7  # 0.35 rad with the rigid law
