"""`robodyn record`: a trajectory as a self-contained HTML animation."""

from __future__ import annotations

import argparse
import time

from robodyn.cli.common import add_model_arguments, load_robot


def add_parser(commands: argparse._SubParsersAction) -> None:
    """Add the command to the ``robodyn`` parser."""
    parser = commands.add_parser("record", help="write a trajectory as a self-contained HTML animation")
    add_model_arguments(parser)
    parser.add_argument("--trajectory", required=True, help="trajectory file (.csv or .npz) from robodyn simulate")
    parser.add_argument("--out", required=True, help="HTML file to write")
    parser.add_argument("--fps", type=float, default=30.0, help="frames per second (default 30)")
    parser.add_argument("--png", help="also a still of the first frame (needs Chromium)")
    parser.set_defaults(run=run)


def run(arguments: argparse.Namespace) -> int:
    from robodyn.sim.simulation import Trajectory
    from robodyn.viz.viewer import record

    robot = load_robot(arguments)
    trajectory = Trajectory.load(arguments.trajectory)
    started = time.perf_counter()
    path = record(robot, trajectory, arguments.out, fps=arguments.fps, png=arguments.png)
    print(
        f"wrote {path} ({path.stat().st_size / 1e6:.2f} MB, {len(trajectory)} samples at {arguments.fps:g} fps, {time.perf_counter() - started:.2f} s)"
    )
    if arguments.png:
        print(f"wrote {arguments.png}")
    return 0
