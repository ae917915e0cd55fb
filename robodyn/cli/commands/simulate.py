"""`robodyn simulate`: a simulation run, its files and summary."""

from __future__ import annotations

import argparse
import json

import numpy as np

from robodyn.cli.common import add_model_arguments, load_robot, vector


def add_parser(commands: argparse._SubParsersAction) -> None:
    """Add the command to the ``robodyn`` parser."""
    parser = commands.add_parser("simulate", help="simulate a robot, optionally under a controller; write trajectory and plot")
    add_model_arguments(parser)
    parser.add_argument("--controller", choices=["passive", "pd", "computed-torque", "task-space"], default="passive")
    parser.add_argument(
        "--target", type=vector, help="task-space: frame position X,Z or X,Y,Z in [m]; pd / computed-torque: joint target"
    )
    parser.add_argument("--frame", help="controlled frame for task-space (default end_effector or the last link)")
    parser.add_argument("--q0", type=vector, help="initial configuration (default neutral)")
    parser.add_argument("--duration", type=float, default=3.0, help="simulated time in [s] (default 3)")
    parser.add_argument("--dt", type=float, default=1e-3, help="step in [s] (default 0.001)")
    parser.add_argument("--integrator", choices=["rk4", "semi-implicit-euler"], default="rk4")
    parser.add_argument("--out", help="trajectory file (.csv or .npz)")
    parser.add_argument("--plot", help="PNG figure: positions, torques, task error, energy")
    parser.add_argument("--record", help="HTML animation (meshcat, self-contained, plays on open)")
    parser.add_argument("--png", help="with --record: a still of the first frame (needs Chromium)")
    parser.add_argument("--json", action="store_true", help="print the summary as JSON")
    parser.set_defaults(run=run)


def run(arguments: argparse.Namespace) -> int:
    from robodyn.sim.experiment import run_simulation

    robot = load_robot(arguments)
    frame = arguments.frame or robot.end_effector
    trajectory, summary = run_simulation(
        robot,
        controller=arguments.controller,
        target=arguments.target,
        frame=frame,
        q0=arguments.q0,
        duration=arguments.duration,
        dt=arguments.dt,
        integrator=arguments.integrator,
    )
    if arguments.out:
        summary["trajectory"] = str(trajectory.save(arguments.out))
    if arguments.plot:
        from robodyn.viz.plots import plot_simulation

        task = np.asarray(summary["target_m"]) if "target_m" in summary else None
        summary["plot"] = str(
            plot_simulation(robot, trajectory, arguments.plot, frame=frame if task is not None else None, target=task)
        )
    if arguments.record:
        from robodyn.viz.viewer import record

        summary["recording"] = str(record(robot, trajectory, arguments.record, png=arguments.png))
        if arguments.png:
            summary["poster"] = str(arguments.png)
    print(json.dumps(summary, indent=2) if arguments.json else "\n".join(f"{key}: {value}" for key, value in summary.items()))
    return 0
