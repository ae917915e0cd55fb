"""`robodyn simulate`: a simulation run, its files and summary."""

from __future__ import annotations

import argparse
import sys

import numpy as np

from robodyn.cli.common import RANGES, add_model_arguments, load_robot, vector
from robodyn.common.files import outputs_together
from robodyn.common.text import json_text


def add_parser(commands: argparse._SubParsersAction) -> None:
    """Add the command to the ``robodyn`` parser."""
    parser = commands.add_parser("simulate", help="simulate a robot, optionally under a controller; write trajectory and plot")
    add_model_arguments(parser)
    parser.add_argument("--controller", choices=["passive", "pd", "computed-torque", "task-space"], default="passive")
    parser.add_argument(
        "--target", type=vector, help="task-space: frame position X,Z or X,Y,Z in [m]; pd / computed-torque: joint target"
    )
    parser.add_argument(
        "--frame", help="controlled frame for task-space (default: the end effector 'robodyn info' shows; it must move)"
    )
    parser.add_argument("--q0", type=vector, help="initial configuration (default: neutral, clipped into the joint limits)")
    parser.add_argument("--duration", type=float, default=3.0, help=f"simulated time, {RANGES['duration'].text()} (default 3)")
    parser.add_argument("--dt", type=float, default=1e-3, help=f"step, {RANGES['dt'].text()}, at most --duration (default 0.001)")
    parser.add_argument("--integrator", choices=["rk4", "semi-implicit-euler"], default="rk4")
    parser.add_argument(
        "--limits",
        choices=["warn", "enforce", "ignore"],
        default="warn",
        help="joint limits: warn (report every violation, default), enforce (saturate torques at the effort "
        "limits, stop joints at the position limits), ignore",
    )
    parser.add_argument(
        "--compiled",
        action="store_true",
        help="integrate in C (robodyn.compile; fixed base, a C compiler needed); PD and computed torque run in C too",
    )
    parser.add_argument("--out", help="trajectory file (.csv or .npz)")
    parser.add_argument("--plot", help="PNG figure: positions, torques, task error, energy")
    parser.add_argument("--record", help="HTML animation (meshcat, self-contained, plays on open)")
    parser.add_argument("--png", help="with --record: a still of the first frame (needs Chromium)")
    parser.add_argument("--json", action="store_true", help="print the summary as JSON")
    parser.set_defaults(run=run)


def run(arguments: argparse.Namespace) -> int:
    from robodyn.cli.report import simulation_text
    from robodyn.common.text import printable
    from robodyn.sim.experiment import run_simulation
    from robodyn.sim.limits import LimitViolation, warning_text

    robot = load_robot(arguments)
    trajectory, summary = run_simulation(
        robot,
        controller=arguments.controller,
        target=arguments.target,
        frame=arguments.frame,
        q0=arguments.q0,
        duration=arguments.duration,
        dt=arguments.dt,
        integrator=arguments.integrator,
        limits=arguments.limits,
        engine="compiled" if arguments.compiled else "pinocchio",
    )
    frame = summary.get("frame")
    task = np.asarray(summary["target_m"]) if "target_m" in summary else None
    with outputs_together():  # every file of the run, or none of them
        if arguments.out:
            summary["trajectory"] = str(trajectory.save(arguments.out))
        if arguments.plot:
            from robodyn.viz.plots import plot_simulation

            summary["plot"] = str(plot_simulation(robot, trajectory, arguments.plot, frame=frame, target=task))
        if arguments.record:
            from robodyn.viz.viewer import record

            summary["recording"] = str(
                record(robot, trajectory, arguments.record, png=arguments.png, target=task, frame=frame or robot.end_effector)
            )
            if arguments.png:
                summary["poster"] = str(arguments.png)
    violations = [LimitViolation(**_violation_fields(item)) for item in summary["limit_violations"]]
    if violations:
        print(f"robodyn: warning: {warning_text(robot.name, violations)}", file=sys.stderr)
    if summary.get("target_reached") is False:
        print(
            f"robodyn: warning: {printable(robot.name)}: the target was not reached: final error {summary['final_error_m']:.3g} m "
            "(a longer --duration, another --q0 or --target?)",
            file=sys.stderr,
        )
    print(json_text(summary) if arguments.json else simulation_text(summary))
    return 0


def _violation_fields(item: dict) -> dict:
    fields = dict(item)
    fields["first_time"] = fields.pop("first_time_s")
    return fields
