"""`robodyn record`: a trajectory as a self-contained HTML animation, stills and videos."""

from __future__ import annotations

import argparse
import sys
import warnings

from robodyn.cli.common import add_model_arguments, load_robot, vector, warn
from robodyn.exceptions import InputError


def add_parser(commands: argparse._SubParsersAction) -> None:
    """Add the command to the ``robodyn`` parser.

    Args:
        commands: The subparsers of the ``robodyn`` parser, from ``add_subparsers``.
    """
    parser = commands.add_parser(
        "record", help="write a trajectory as a self-contained HTML animation (and stills, a filmstrip, a video)"
    )
    add_model_arguments(parser)
    parser.add_argument("--trajectory", required=True, help="trajectory file (.csv or .npz) from robodyn simulate")
    parser.add_argument("--out", required=True, help="HTML file to write")
    parser.add_argument("--fps", type=float, default=30.0, help="frames per second of the animation (default 30)")
    parser.add_argument("--target", type=vector, metavar="X,Z|X,Y,Z", help="task target drawn as a red sphere, in [m]")
    parser.add_argument("--frame", help="frame whose path is drawn (default: the robot's end effector)")
    parser.add_argument("--axes", help="comma-separated links that carry an x/y/z triad")
    parser.add_argument("--png", help="a still PNG (needs Chromium); with --filmstrip, the filmstrip")
    parser.add_argument("--at", type=float, default=0.0, help="time of the --png still in [s] from the start (default 0)")
    parser.add_argument("--filmstrip", type=int, metavar="N", help="with --png: N frames evenly over the motion, side by side")
    parser.add_argument("--mp4", help="an MP4 video of the motion (needs Chromium and the viewer extra)")
    parser.add_argument("--gif", help="an animated GIF of the motion (needs Chromium and the viewer extra)")
    parser.add_argument(
        "--max-mesh-mb",
        type=float,
        help="largest mesh file drawn, in MB (default 64 or ROBODYN_MAX_MESH_MB); larger: a placeholder",
    )
    parser.add_argument("--video-fps", type=float, default=15.0, help="frames per second of --mp4/--gif (default 15)")
    parser.set_defaults(run=run)


def run(arguments: argparse.Namespace) -> int:
    """Run ``robodyn record`` with the parsed ``arguments``; return the exit status.

    Args:
        arguments: The command line parsed by the parser :func:`add_parser` built.
    """
    from robodyn.exceptions import MeshWarning
    from robodyn.trajectory import Trajectory
    from robodyn.viz.experiment import record_files

    if arguments.max_mesh_mb is not None and not arguments.max_mesh_mb > 0:
        raise InputError("--max-mesh-mb", "a positive size in MB", f"{arguments.max_mesh_mb:g}")
    if arguments.filmstrip is not None and not arguments.png:
        raise InputError("--filmstrip", "given with --png FILE (the filmstrip's file)", "no --png")
    if arguments.filmstrip is not None and arguments.at != 0.0:
        raise InputError("--at", "not given with --filmstrip (its frames spread over the motion)", f"--at {arguments.at:g}")
    robot = load_robot(arguments)
    with warnings.catch_warnings():  # reported below, one line each
        warnings.simplefilter("ignore", MeshWarning)
        run = record_files(
            robot,
            Trajectory.load(arguments.trajectory).for_robot(robot),
            arguments.out,
            fps=arguments.fps,
            target=arguments.target,
            frame=arguments.frame,
            axes=tuple(name for name in (arguments.axes or "").split(",") if name),
            png=arguments.png,
            at=arguments.at,
            filmstrip=arguments.filmstrip,
            videos=tuple(path for path in (arguments.mp4, arguments.gif) if path),
            video_fps=arguments.video_fps,
            max_mesh_bytes=None if arguments.max_mesh_mb is None else int(arguments.max_mesh_mb * 1e6),
        )
    warn([f"{reason}; drawn as a placeholder box" for reason in run.placeholders])
    print(run.headline(), file=sys.stderr if run.path is None else sys.stdout)
    for extra in run.extras:
        print(f"wrote {extra}")
    return 0
