"""The options of `robodyn simulate`'s other controllers, each alone, read back (issue 39).

tests/cli/test_simulate_options.py crosses the options every run takes (with the passive, PD
and computed-torque controllers); the options of one controller only are run here, each on
the oblique robot (3-D, oblique axes, joint damping and Coulomb friction): the file read back
without robodyn equals, to 1e-12, ``robodyn.simulate`` under the controller built by hand from
the same options, and the run without the option differs (its effect visible). The frame
controllers: ``--target`` with ``--frame``, osc's ``--posture`` and attitude, impedance's
``--stiffness`` and ``--damping``; pd's ``--actuated``; computed torque's ``--reference``.
"""

from __future__ import annotations

import contextlib
import io
import json
import warnings

import numpy as np
import pytest

import robodyn
from robodyn.cli.app import main
from robodyn.sim.control import ComputedTorque, TaskSpace
from robodyn.sim.gains import pd_gains
from robodyn.sim.operational_space import Impedance, OperationalSpace
from robodyn.sim.requests import TrajectoryReference
from robodyn.sim.underactuated import UnderactuatedPD
from tests.cli.simulate_options import DEFAULT, DURATION, OBLIQUE, robot_of
from tests.differential.pairs import written_columns

ROBOT = DEFAULT  # the oblique robot, fixed, the file's gravity
TIP = (0.38, 0.28, 0.34)  # near the end effector's start (0.394, 0.270, 0.331) [m]
RAM = (0.33, 0.31, 0.36)  # near the ram's start [m]
RPY = (0.1, -0.2, 0.3)
POSTURE = (0.2, -0.3, 0.05, 0.4)
STIFFNESS, DAMPING = (300.0, 400.0, 500.0), (30.0, 40.0, 50.0)


def numbers(values) -> str:
    return ",".join(repr(float(x)) for x in values)


def model() -> robodyn.Robot:
    return robot_of(ROBOT)


def task_space(frame: str = "end_effector", target=TIP):
    return TaskSpace(model(), frame, np.array(target))


def osc(rpy=None, posture=None):
    return OperationalSpace(
        model(), "end_effector", np.array(TIP), orientation=None if rpy is None else np.array(rpy),
        posture=None if posture is None else np.array(posture),
    )  # fmt: skip


def impedance(stiffness=None, damping=None):
    gains = {name: np.array(v) for name, v in (("stiffness", stiffness), ("damping", damping)) if v is not None}
    return Impedance(model(), "end_effector", np.array(TIP), **gains)


def underactuated_pd():
    robot = model()
    driven = np.array([True, True, True, False])
    start = robot.default_configuration()
    return UnderactuatedPD(robot, start.copy(), *pd_gains(robot, np.array([start, start]), driven=driven), driven=driven)


#: (case id, the command's options, the run without the option (its negative control), the law built by hand).
CASES = [
    ("task-space", ["--controller", "task-space", f"--target={numbers(TIP)}"], None, task_space),
    ("task-space --frame", ["--controller", "task-space", f"--target={numbers(RAM)}", "--frame", "ram"],
     ["--controller", "task-space", f"--target={numbers(RAM)}"], lambda: task_space("ram", RAM)),
    ("osc attitude", ["--controller", "osc", f"--target={numbers(TIP + RPY)}"],
     ["--controller", "osc", f"--target={numbers(TIP)}"], lambda: osc(RPY)),
    ("osc --posture", ["--controller", "osc", f"--target={numbers(TIP)}", f"--posture={numbers(POSTURE)}"],
     ["--controller", "osc", f"--target={numbers(TIP)}"], lambda: osc(posture=POSTURE)),
    ("impedance --stiffness", ["--controller", "impedance", f"--target={numbers(TIP)}", f"--stiffness={numbers(STIFFNESS)}"],
     ["--controller", "impedance", f"--target={numbers(TIP)}"], lambda: impedance(STIFFNESS)),
    ("impedance --damping", ["--controller", "impedance", f"--target={numbers(TIP)}", f"--damping={numbers(DAMPING)}"],
     ["--controller", "impedance", f"--target={numbers(TIP)}"], lambda: impedance(damping=DAMPING)),
    ("pd --actuated", ["--controller", "pd", "--actuated", "j_yaw,j_twist,j_extend"], ["--controller", "pd"], underactuated_pd),
]  # fmt: skip


def command(options: list[str], out) -> dict:
    """Run ``robodyn simulate`` on the oblique robot; its summary (JSON)."""
    argv = ["simulate", str(OBLIQUE), "--duration", str(DURATION), *options, "--out", str(out), "--json"]
    stdout, stderr = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr):
        assert main(argv) == 0, stderr.getvalue()
    return json.loads(stdout.getvalue())


def library(law, start=None) -> robodyn.Trajectory:
    """``robodyn.simulate`` of the oblique robot under ``law`` (the joints' damping compensated, as the command's laws do)."""
    robot = model()
    if hasattr(law, "compensate_damping"):
        law.compensate_damping = True
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        q0 = robot.default_configuration() if start is None else start
        return robodyn.simulate(robot, q0, np.zeros(robot.nv), DURATION, 1e-3, controller=law)


def same_as(columns: dict, trajectory: robodyn.Trajectory) -> None:
    robot = model()
    for kind in ("q", "v", "a", "tau"):
        for k, dof in enumerate(robot.dofs):
            values = getattr(trajectory, kind)[:, k]
            scale = max(1.0, float(np.abs(values).max()))
            np.testing.assert_allclose(columns[f"{kind}[{dof.name}]"], values, rtol=0, atol=1e-12 * scale, err_msg=kind)


@pytest.mark.slow
@pytest.mark.parametrize(("options", "without", "law"), [case[1:] for case in CASES], ids=[case[0] for case in CASES])
def test_each_controller_option_alone_writes_the_librarys_run_and_changes_it(options, without, law, tmp_path):
    summary = command(options, tmp_path / "with.csv")
    columns = written_columns(tmp_path / "with.csv")
    same_as(columns, library(law()))
    assert summary["controller"] == options[1]
    if options[1] != "pd":  # the task's frame, target and where the written motion left the frame
        frame = "ram" if "--frame" in options else "end_effector"
        q = np.array([columns[f"q[{name}]"][-1] for name in model().joint_names])
        assert summary["frame"] == frame and summary["target_m"] == list(RAM if frame == "ram" else TIP)
        np.testing.assert_allclose(summary["final_position_m"], model().frame_position(q, frame), rtol=0, atol=1e-12)
    if "--actuated" in options:  # the joint left out gets no torque
        assert np.abs(columns["tau[j_tool]"]).max() == 0 and np.abs(columns["tau[j_extend]"]).max() > 0
    if without is not None:
        command(without, tmp_path / "without.csv")
        other = written_columns(tmp_path / "without.csv")
        assert max(np.abs(columns[name] - other[name]).max() for name in columns if name.startswith("q[")) > 1e-9


@pytest.mark.slow
def test_reference_makes_computed_torque_track_the_files_motion_from_its_first_sample(tmp_path):
    robot = model()
    t = np.linspace(0.0, DURATION, 6)
    amplitude, middle = np.array([0.02, -0.01, 0.005, 0.03]), np.array([0.1, -0.1, 0.02, 0.2])
    q = middle + np.outer(np.sin(40 * t), amplitude)
    v = np.outer(40 * np.cos(40 * t), amplitude)
    a = np.outer(-1600 * np.sin(40 * t), amplitude)
    path = robodyn.Trajectory(t, q, v, a, None, list(robot.joint_names), robot.name).save(tmp_path / "reference.csv")
    command(["--controller", "computed-torque", "--reference", str(path)], tmp_path / "tracked.csv")
    columns = written_columns(tmp_path / "tracked.csv")
    assert [columns[f"q[{name}]"][0] for name in robot.joint_names] == list(q[0])  # starts at the file's first sample
    reference = robodyn.Trajectory.load(path)
    same_as(columns, library(ComputedTorque(model(), TrajectoryReference(reference)), start=q[0]))
