"""The options of `robodyn simulate`, their values, and a run of any choice of them made two
ways: by the command (its file read back without robodyn, its summary parsed) and by the
Python API given the same options (``robodyn.load``, the controller built here,
``robodyn.simulate``). Shared by tests/cli/test_simulate_options.py (each option alone) and
tests/cli/test_simulate_options_pairwise.py (the options crossed pairwise).

The robots: the oblique test robot (3-D, oblique non-unit axes, a prismatic joint, a fixed
joint between moving ones, joint damping and Coulomb friction) and the xacro test arm (a
mimic joint, non-default ``--xacro-arg`` values, ``--package``), each fixed or floating.
"""

from __future__ import annotations

import contextlib
import io
import json
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

import robodyn
from robodyn.cli.app import main
from robodyn.sim.contact_checks import start_above
from robodyn.sim.control import ComputedTorque, PDGravity, quintic_reference
from robodyn.sim.gains import pd_defaults, pd_gains
from robodyn.sim.ground import Ground
from robodyn.sim.observer import MomentumObserver
from robodyn.sim.simulation import ExternalWrench, external_torques
from tests.cli.option_runs import GRAVITY, OBLIQUE, PACKAGE, XACRO, XACRO_ARGS
from tests.differential.pairs import expected_header, written_columns

DURATION = 0.01
PUSH_TIME, PUSH_FORCE = 0.005, (1.5, -2.0, 3.0)
PD_GAINS, CT_GAINS = (5.0, 0.05), (100.0, 20.0)  # --kp, --kd of pd [N m/rad], [N m s/rad]; computed torque [1/s²], [1/s]
DEFAULT_CT_GAINS = (400.0, 40.0)  # the documented defaults of computed torque (--kp's help)


@dataclass(frozen=True)
class Model:
    """A test robot: how the command names it, and the values its options take (read from its file)."""

    argv: tuple[str, ...]
    q0: tuple[float, ...]  # the joints' start (a floating base adds BASE before them)
    step: tuple[float, ...]  # the joint target: the start's joints plus this (a gentle motion in 5 ms)
    frame: str  # its end effector: the default frame of a push, the contact point on the ground
    touching: float | None  # a ground 0.5 mm above the end effector at q0, the lowest link there (fixed base)
    effort: dict  # joint -> effort limit of the file, in [N m] or [N]
    prismatic: tuple[str, ...]


MODELS = {
    "oblique": Model(
        (str(OBLIQUE),), (1.44, -1.11, 0.08, 2.97), (0.002, -0.002, 0.001, 0.003), "end_effector", -0.11839857,
        {"j_yaw": 80.0, "j_twist": 60.0, "j_extend": 100.0}, ("j_extend",),
    ),
    "xacro": Model(
        (str(XACRO), *(f"--xacro-arg={k}:={v}" for k, v in XACRO_ARGS.items()), f"--package=robodyn_test_arm={PACKAGE}"),
        (0.2, 0.05, -0.3), (0.002, 0.001, -0.003), "r_finger", None, {"r_shoulder": 50.0, "r_slide": 100.0}, ("r_slide",),
    ),
}  # fmt: skip
LOW_GROUND = -0.3  # below every link of either robot at any start here: a floating one falls toward it
BASE = (0.01, -0.02, 0.03, *(np.array([0.1, 0.05, -0.02, 1.0]) / np.linalg.norm([0.1, 0.05, -0.02, 1.0])))

#: Each option of ``robodyn simulate`` with its values; the first is the default (the option left out).
FACTORS: dict[str, tuple | list] = {  # in the order the pairwise generator fills a run: the options others depend on first
    "model": ("oblique", "xacro"),
    "base": (None, "floating", "fixed"),
    "ground": (None, "given"),
    "friction": (None, 0.0),
    "integrator": (None, "rk4", "semi-implicit-euler"),
    "out": (None, ".csv", ".npz"),
    "controller": ("passive", "pd", "computed-torque"),
    "target": (None, "given"),
    "gains": (None, "given"),
    "control_period": (None, 0.002),
    "q0": (None, "given"),
    "dt": (None, 0.0005),
    "gravity": (None, GRAVITY),
    "inertia": (None, "strict", "no-check"),
    "max_dof": (None, 12),
    "limits": ("warn", "enforce", "ignore"),
    "engine": (None, "pinocchio"),
    "joint_friction": (True, False),
    "observer_gain": (None, 20.0),
    "push": (None, f"{PUSH_TIME}:{','.join(map(str, PUSH_FORCE))}"),
    "json": (False, True),
}
DEFAULT = {name: values[0] for name, values in FACTORS.items()}

#: The combinations the command refuses: (options, values), the words its one stderr line names.
REFUSED: tuple[tuple[dict, tuple[str, ...]], ...] = (
    ({"controller": "passive", "target": "given"}, ("--target", "passive")),
    ({"controller": "computed-torque", "target": None}, ("--target", "computed-torque")),
    ({"controller": "passive", "gains": "given"}, ("--kp", "pd or computed-torque")),
    ({"controller": "passive", "control_period": 0.002}, ("--control-period", "controller")),
    ({"ground": "given", "integrator": "rk4"}, ("--integrator", "ground")),
    ({"ground": "given", "out": ".npz"}, ("--out", ".csv", "ground")),
    ({"ground": "given", "control_period": 0.002}, ("--control-period", "ground")),
    ({"ground": "given", "observer_gain": 20.0}, ("--observer-gain", "ground")),
    ({"ground": None, "friction": 0.0}, ("--friction", "--ground")),
)


#: Pairs no run can hold though the command refuses neither alone: ``--friction`` needs ``--ground``, which refuses them.
UNCOMPLETABLE = tuple(
    {"friction": 0.0} | {name: value for name, value in pair.items() if name != "ground"}
    for pair, _ in REFUSED
    if pair.get("ground") == "given"
)


def valid(run: dict) -> bool:
    """Whether the command accepts a (partial) choice of options: none of :data:`REFUSED` in it
    (nor of :data:`UNCOMPLETABLE`)."""
    pairs = (*(pair for pair, _ in REFUSED), *UNCOMPLETABLE)
    return not any(all(name in run and run[name] == value for name, value in pair.items()) for pair in pairs)


def floating(run: dict) -> bool:
    return run["base"] == "floating"


def start_of(run: dict) -> tuple[float, ...] | None:
    """The ``--q0`` of a run (``None``: not given)."""
    joints = MODELS[run["model"]].q0
    return None if run["q0"] is None else ((*BASE, *joints) if floating(run) else joints)


def target_of(run: dict) -> tuple[float, ...]:
    """The ``--target`` of a run: its start's joints moved by the model's ``step``."""
    model = MODELS[run["model"]]
    start = model.q0 if run["q0"] else (0.0,) * len(model.q0)
    return tuple(a + b for a, b in zip(start, model.step, strict=True))


def ground_of(run: dict) -> float:
    """The ``--ground`` height: touching the oblique robot's end effector when it starts fixed at
    its ``--q0``, else below the robot."""
    touching = MODELS[run["model"]].touching
    return touching if touching is not None and run["base"] != "floating" and run["q0"] else LOW_GROUND


def arguments_of(run: dict, out: Path | None) -> list[str]:
    """The command line of a run."""
    model = MODELS[run["model"]]
    gains = PD_GAINS if run["controller"] == "pd" else CT_GAINS
    numbers = lambda values: ",".join(repr(float(x)) for x in values)  # noqa: E731
    flags = {
        "base": [f"--{run['base']}-base"],
        "gravity": [f"--gravity={numbers(GRAVITY)}"],
        "inertia": ["--strict" if run["inertia"] == "strict" else "--no-check-inertia"],
        "max_dof": ["--max-dof", str(run["max_dof"])],
        "target": [f"--target={numbers(target_of(run))}"],
        "gains": ["--kp", str(gains[0]), "--kd", str(gains[1])],
        "q0": [f"--q0={numbers(start_of(run) or ())}"],
        "dt": ["--dt", str(run["dt"])],
        "integrator": ["--integrator", str(run["integrator"])],
        "limits": ["--limits", run["limits"]],
        "engine": ["--engine", str(run["engine"])],
        "control_period": ["--control-period", str(run["control_period"])],
        "joint_friction": ["--no-joint-friction"],
        "observer_gain": ["--observer-gain", str(run["observer_gain"])],
        "push": ["--force-at", str(run["push"])],
        "ground": [f"--ground={ground_of(run)!r}", "--contact", model.frame],
        "friction": ["--friction", str(run["friction"])],
        "json": ["--json"],
    }
    argv = ["simulate", *model.argv, "--duration", str(DURATION), "--controller", run["controller"]]
    for name, flag in flags.items():
        if run[name] != DEFAULT[name] or (name == "friction" and run[name] is not None):
            argv += flag
    return argv + (["--out", str(out)] if out else [])


def robot_of(run: dict) -> robodyn.Robot:
    """The robot as the Python API loads it with the run's options."""
    keywords: dict = {"floating_base": {"floating": True, "fixed": False}.get(run["base"])}
    keywords |= {"gravity": GRAVITY} if run["gravity"] else {}
    keywords |= {"strict": True} if run["inertia"] == "strict" else {}
    keywords |= {"check_inertia": False} if run["inertia"] == "no-check" else {}
    keywords |= {"max_dof": run["max_dof"]} if run["max_dof"] else {}
    if run["model"] == "xacro":
        return robodyn.load(XACRO, xacro_args=XACRO_ARGS, packages={"robodyn_test_arm": str(PACKAGE)}, **keywords)
    return robodyn.load(OBLIQUE, **keywords)


class _Step:
    """A force from a time on (the push of ``--force-at T:F``), written here."""

    def __call__(self, t: float) -> np.ndarray:
        return np.array(PUSH_FORCE) if t >= PUSH_TIME else np.zeros(3)


def _controller(run: dict, robot: robodyn.Robot, start: np.ndarray, ground: Ground | None, contacts: list[str]):
    """The run's controller built with the Python API, on its own model of the robot."""
    if run["controller"] == "passive":
        return None
    n = robot.nq - 7 if robot.floating_base else robot.nq
    joints = np.array(target_of(run)) if run["target"] else start[robot.nq - n :].copy()
    if run["controller"] == "computed-torque":
        kp, kd = CT_GAINS if run["gains"] else DEFAULT_CT_GAINS
        law = ComputedTorque(robot_of(run), quintic_reference(start[robot.nq - n :], joints, DURATION / 2), kp, kd)
        law.compensate_damping = run["joint_friction"]
        return law
    if run["gains"]:
        return PDGravity(robot_of(run), joints, *PD_GAINS)
    _, asked = pd_defaults(robot, "pd", list(joints), start, {"kp": None, "kd": None}, ground, contacts)
    goal = start.copy()
    goal[robot.nq - n :] = joints
    return PDGravity(robot_of(run), joints, *pd_gains(robot, np.array([start, goal]), **asked))


def library_run(run: dict) -> tuple[robodyn.Robot, robodyn.Trajectory, dict[str, np.ndarray]]:
    """The run through the Python API: the robot, its trajectory and the extra columns the
    command writes beside it (``tau_ext``: the observer's estimate; ``tau_env``: the push's torques)."""
    robot, model = robot_of(run), MODELS[run["model"]]
    given = start_of(run)
    start = robot.default_configuration() if given is None else np.array(given)
    ground = (
        None if run["ground"] is None else Ground(ground_of(run), friction=1.0 if run["friction"] is None else run["friction"])
    )
    contacts = [model.frame]
    if ground is not None and robot.floating_base and given is None:  # the command lifts a floating robot out of the ground
        lifted, lift = start_above(robot, start, ground, contacts, clearance=0.05)
        start = lifted if lift > 0.05 else start
    held = "held" if run["control_period"] else "sampled"  # a sampled controller's torque is held through a step
    observer = None if run["observer_gain"] is None else MomentumObserver(robot_of(run), run["observer_gain"], torque=held)
    external = [ExternalWrench(model.frame, _Step())] if run["push"] else []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        trajectory = robodyn.simulate(
            robot, start, np.zeros(robot.nv), DURATION, run["dt"] or 1e-3, controller=_controller(run, robot, start, ground, contacts),
            integrator=run["integrator"], external=external, limits=run["limits"], engine=run["engine"] or "auto",
            control_period=run["control_period"], observer=observer, joint_friction=run["joint_friction"],
            ground=ground, contacts=contacts if ground else "collision",
        )  # fmt: skip
    extras = {} if observer is None else {"tau_ext": np.array(observer.residuals)}
    if external:
        extras["tau_env"] = np.array(
            [external_torques(robot, q, t, external) for t, q in zip(trajectory.t, trajectory.q, strict=True)]
        )
    return robot, trajectory, extras


@dataclass(frozen=True)
class Written:
    """What the command wrote: its file's columns (read without robodyn), its summary."""

    columns: dict[str, np.ndarray] | None
    header: list[str] | None
    printed: str
    stderr: str


def run_cli(run: dict, folder: Path) -> Written:
    """Run the command in this process and read back what it wrote and printed."""
    out = folder / f"run{run['out']}" if run["out"] else None
    stdout, stderr = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr):
        code = main(arguments_of(run, out))
    assert code == 0, stderr.getvalue()
    header = None
    if out is not None and out.suffix == ".csv":
        header = next(line for line in out.read_text().splitlines() if not line.startswith("#")).split(",")
    columns = written_columns(out) if out else None
    return Written(columns, header or (None if columns is None else list(columns)), stdout.getvalue(), stderr.getvalue())


def header_of(robot: robodyn.Robot, run: dict) -> list[str]:
    """The columns the run's file must have, from the robot's names: t, q, v, a, tau, then the
    observer's, the push's and the ground's."""
    dofs = [dof.name for dof in robot.dofs]
    header = expected_header(robot)
    header += [f"tau_ext[{d}]" for d in dofs] if run["observer_gain"] else []
    header += [f"tau_env[{d}]" for d in dofs] if run["push"] else []
    frame = MODELS[run["model"]].frame
    return header + ([f"f[{frame}].{axis}" for axis in "xyz"] + [f"contact[{frame}]"] if run["ground"] else [])


def check_run(run: dict, folder: Path) -> tuple[Written, robodyn.Trajectory]:
    """Run the command and check what it wrote against the Python API given the same options:
    the file's columns (names, order, values to 1e-12) and the summary's lines or JSON."""
    written = run_cli(run, folder)
    robot, trajectory, extras = library_run(run)
    if written.columns is not None:
        header = header_of(robot, run)
        assert (sorted(written.columns) if run["out"] == ".npz" else written.header) == (
            sorted(header) if run["out"] == ".npz" else header
        )
        expected = {"t": trajectory.t}
        for kind, names in (("q", robot.configuration_names), *((k, [d.name for d in robot.dofs]) for k in ("v", "a", "tau"))):
            expected |= {f"{kind}[{name}]": getattr(trajectory, kind)[:, k] for k, name in enumerate(names)}
        for kind, values in extras.items():
            expected |= {f"{kind}[{dof.name}]": values[:, k] for k, dof in enumerate(robot.dofs)}
        for name, values in expected.items():
            scale = max(1.0, float(np.abs(values).max()))
            np.testing.assert_allclose(written.columns[name], values, rtol=0, atol=1e-12 * scale, err_msg=name)
        assert all(np.isfinite(values).all() for values in written.columns.values())
    check_summary(run, robot, trajectory, written)
    return written, trajectory


def check_summary(run: dict, robot: robodyn.Robot, trajectory: robodyn.Trajectory, written: Written) -> None:
    """The summary's settings, steps, units and limits against the run asked for and the library's trajectory."""
    integrator = run["integrator"] or ("semi-implicit-euler" if run["ground"] else "rk4")
    steps = round(DURATION / (run["dt"] or 1e-3))
    out = None if written.columns is None else f"run{run['out']}"
    if not run["json"]:
        assert f"controller: {run['controller']} (integrator {integrator}, limits {run['limits']})" in written.printed
        assert f"simulated: {DURATION:g} s in {steps} steps of {run['dt'] or 1e-3:g} s" in written.printed
        assert ("trajectory: " in written.printed) == (out is not None)
        assert out is None or f"trajectory: {written.printed.split('trajectory: ')[1].split()[0]}".endswith(out)
        return
    summary = json.loads(written.printed)
    assert (summary["controller"], summary["integrator"], summary["limits"]) == (run["controller"], integrator, run["limits"])
    assert summary["engine"] == (run["engine"] or summary["engine"]) and summary["steps"] == steps == len(trajectory) - 1
    assert summary["dt_s"] == (run["dt"] or 1e-3) and summary["duration_s"] == DURATION
    np.testing.assert_allclose(summary["final_q"], trajectory.q[-1], rtol=0, atol=1e-12)
    model = MODELS[run["model"]]
    units = {
        dof.name: "N" if dof.name in model.prismatic or dof.name in ("base.x", "base.y", "base.z") else "N m"
        for dof in robot.dofs
    }
    assert dict(zip(summary["dof_names"], summary["torque_units"], strict=True)) == units
    assert ("trajectory" in summary) == (out is not None) and (out is None or summary["trajectory"].endswith(out))
    assert ("observer_gain_per_s" in summary) == (run["observer_gain"] is not None)
    efforts = {v["joint"] for v in summary["limit_violations"] if v["quantity"] == "effort"}
    peak = dict(zip(summary["dof_names"], summary["peak_abs_torque"], strict=True))
    dofs = [dof.name for dof in robot.dofs]
    beyond = {joint for joint, limit in model.effort.items() if np.abs(trajectory.tau[:, dofs.index(joint)]).max() > limit}
    np.testing.assert_allclose(list(peak.values()), np.abs(trajectory.tau).max(axis=0), rtol=0, atol=1e-9)
    if run["limits"] == "enforce":
        assert not beyond  # saturated at the file's effort limits
    assert efforts == (set() if run["limits"] == "ignore" else beyond)
