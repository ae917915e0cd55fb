"""The frame controllers of `robodyn simulate` crossed pairwise with the options every run takes (issue 39).

task-space, osc and impedance control, with ``--frame``, an attitude, osc's ``--posture`` and
impedance's ``--stiffness``, crossed with the robot (oblique 3-D, the xacro arm with a mimic),
a floating base, ``--gravity``, a push (at the controlled frame unless it names one),
``--observer-gain``, ``--control-period``, ``--limits``, ``--integrator`` and
``--no-joint-friction``: every accepted pair of values in some run, each run's file read back
without robodyn and equal, to 1e-12, to ``robodyn.simulate`` under the law built by hand with
the same options. Each of these options alone: tests/cli/test_simulate_controller_options.py.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import robodyn
from robodyn.sim.control import TaskSpace
from robodyn.sim.observer import MomentumObserver
from robodyn.sim.operational_space import Impedance, OperationalSpace
from robodyn.sim.simulation import ExternalWrench, external_torques
from tests.cli import simulate_options
from tests.cli.simulate_options import BASE, DEFAULT, DURATION, MODELS, PUSH_FORCE, PUSH_TIME, robot_of, run_cli
from tests.pairwise import pairwise, uncovered_pairs

#: Per robot: (its end effector's target, another frame and its target), near where they start, in [m].
TARGETS = {
    "oblique": ((0.38, 0.28, 0.34), "ram", (0.35, 0.21, 0.37)),
    "xacro": ((-0.01, -0.06, 1.08), "r_wrist", (-0.02, -0.07, 0.98)),
}
RPY, STIFFNESS, TURNING = (0.1, -0.2, 0.3), (300.0, 400.0, 500.0), (30.0, 40.0, 50.0)

FRAME_FACTORS: dict[str, tuple | list] = {
    "controller": ("task-space", "osc", "impedance"),
    "model": ("oblique", "xacro"),
    "base": (None, "floating"),
    "frame": (None, "other"),
    "attitude": (None, RPY),
    "posture": (None, "given"),
    "stiffness": (None, STIFFNESS),
    "push": (None, "at the controlled frame"),
    "observer_gain": (None, 20.0),
    "control_period": (None, 0.002),
    "gravity": (None, (1.5, -2.0, -8.0)),
    "limits": ("warn", "enforce", "ignore"),
    "integrator": (None, "semi-implicit-euler"),
    "joint_friction": (True, False),
}
ONLY = {"attitude": ("osc", "impedance"), "posture": ("osc",), "stiffness": ("impedance",)}


def valid(run: dict) -> bool:
    """An attitude for the pose controllers only, a posture for osc, a stiffness for impedance."""
    if run.get("posture") is not None and run.get("stiffness") is not None:
        return False  # no controller takes both
    if run.get("controller") == "impedance" and run.get("model") == "xacro" and run.get("attitude") is not None:
        return False  # the arm's light wrist under a rotational stiffness needs dt <= 3e-5 s (the command warns and says so)
    return "controller" not in run or all(run.get(name) is None or run["controller"] in ONLY[name] for name in ONLY)


RUNS = pairwise(FRAME_FACTORS, valid)


def test_the_frame_runs_cover_every_pair_the_command_accepts():
    assert uncovered_pairs(RUNS, FRAME_FACTORS, valid) == [] and all(valid(run) for run in RUNS) and len(RUNS) <= 16


def controlled(run: dict) -> tuple[str, tuple[float, ...]]:
    tip, other, target = TARGETS[run["model"]]
    return (other, target) if run["frame"] else (MODELS[run["model"]].frame, tip)


def posture(run: dict, robot: robodyn.Robot) -> np.ndarray:
    joints = np.array(MODELS[run["model"]].q0)
    return np.concatenate([BASE, joints]) if robot.floating_base else joints


def stiffness(run: dict) -> tuple[float, ...]:
    """``--stiffness``: 3 values in [N/m], or with an attitude 6 (then [N m/rad]: 3 values are refused)."""
    return STIFFNESS + (TURNING if run["attitude"] else ())


def command_options(run: dict) -> list[str]:
    """The frame controller's own flags (the common ones come from simulate_options.arguments_of)."""
    frame, target = controlled(run)
    numbers = lambda values: ",".join(repr(float(x)) for x in values)  # noqa: E731
    flags = [f"--target={numbers(target + (run['attitude'] or ()))}"]
    flags += ["--frame", frame] if run["frame"] else []
    flags += [f"--posture={numbers(posture(run, robot_of(common(run))))}"] if run["posture"] else []
    flags += [f"--stiffness={numbers(stiffness(run))}"] if run["stiffness"] else []
    return flags


def common(run: dict) -> dict:
    """The run as tests/cli/simulate_options.py writes a command line and loads a robot."""
    push = f"{PUSH_TIME}:{','.join(map(str, PUSH_FORCE))}" if run["push"] else None
    shared = ("model", "base", "gravity", "limits", "integrator", "joint_friction", "observer_gain", "control_period")
    return DEFAULT | {name: run[name] for name in shared} | {"controller": run["controller"], "push": push, "out": ".csv"}


def law_of(run: dict) -> TaskSpace | OperationalSpace | Impedance:
    """The run's controller built with the Python API, on its own model of the robot."""
    frame, target = controlled(run)
    model = robot_of(common(run))
    rpy = None if run["attitude"] is None else np.array(run["attitude"])
    law: TaskSpace | OperationalSpace | Impedance
    if run["controller"] == "task-space":
        law = TaskSpace(model, frame, np.array(target))
    elif run["controller"] == "osc":
        law = OperationalSpace(
            model, frame, np.array(target), orientation=rpy, posture=posture(run, model) if run["posture"] else None
        )
    else:
        law = Impedance(model, frame, np.array(target), orientation=rpy)
        if run["stiffness"]:
            law = Impedance(model, frame, np.array(target), orientation=rpy, stiffness=np.array(stiffness(run)))
    law.compensate_damping = run["joint_friction"]
    return law


class _Step:
    def __call__(self, t: float) -> np.ndarray:
        return np.array(PUSH_FORCE) if t >= PUSH_TIME else np.zeros(3)


@pytest.mark.slow
@pytest.mark.parametrize("run", RUNS, ids=[str(k) for k in range(len(RUNS))])
def test_the_frame_controllers_crossed_pairwise_write_the_python_apis_run(run, tmp_path, monkeypatch):
    shared = common(run)
    plain = simulate_options.arguments_of
    monkeypatch.setattr(simulate_options, "arguments_of", lambda r, out: [*plain(r, out), *command_options(run)])
    written = run_cli(shared, tmp_path)
    robot = robot_of(shared)
    external = [ExternalWrench(controlled(run)[0], _Step())] if run["push"] else []
    held = "held" if run["control_period"] else "sampled"  # a sampled controller's torque is held through a step
    observer = None if run["observer_gain"] is None else MomentumObserver(robot_of(shared), 20.0, torque=held)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        trajectory = robodyn.simulate(
            robot, robot.default_configuration(), np.zeros(robot.nv), DURATION, 1e-3, controller=law_of(run),
            integrator=run["integrator"], external=external, limits=run["limits"], control_period=run["control_period"],
            observer=observer, joint_friction=run["joint_friction"],
        )  # fmt: skip
    assert written.columns is not None
    expected = {
        f"{kind}[{dof.name}]": getattr(trajectory, kind)[:, k] for kind in ("v", "a", "tau") for k, dof in enumerate(robot.dofs)
    }
    expected |= {f"q[{name}]": trajectory.q[:, k] for k, name in enumerate(robot.configuration_names)}
    if external:
        applied = np.array([external_torques(robot, q, t, external) for t, q in zip(trajectory.t, trajectory.q, strict=True)])
        expected |= {f"tau_env[{dof.name}]": applied[:, k] for k, dof in enumerate(robot.dofs)}
    if observer is not None:
        expected |= {f"tau_ext[{dof.name}]": np.array(observer.residuals)[:, k] for k, dof in enumerate(robot.dofs)}
    assert sorted(written.columns) == sorted(["t", *expected])
    for name, values in expected.items():
        scale = max(1.0, float(np.abs(values).max()))
        np.testing.assert_allclose(written.columns[name], values, rtol=0, atol=1e-12 * scale, err_msg=name)


def test_three_stiffness_values_for_a_pose_target_are_one_stderr_line(capsys):
    from robodyn.cli.app import main

    argv = ["simulate", str(simulate_options.OBLIQUE), "--controller", "impedance", "--duration", "0.01"]
    assert main([*argv, f"--target={','.join(map(str, TARGETS['oblique'][0] + RPY))}", "--stiffness=300,400,500"]) == 2
    error = capsys.readouterr().err
    assert error.count("\n") == 1 and "--stiffness" in error and "6 values" in error
