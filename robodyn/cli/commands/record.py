"""`robodyn record`: a trajectory as a self-contained HTML animation, stills and videos."""

from __future__ import annotations

import argparse
import sys
import time
import warnings

from robodyn.cli.common import add_model_arguments, load_robot, vector
from robodyn.exceptions import InputError


def add_parser(commands: argparse._SubParsersAction) -> None:
    """Add the command to the ``robodyn`` parser."""
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
    from robodyn.exceptions import MeshWarning
    from robodyn.trajectory import Trajectory
    from robodyn.viz.recording import recording

    if arguments.max_mesh_mb is not None and not arguments.max_mesh_mb > 0:
        raise InputError("--max-mesh-mb", "a positive size in MB", f"{arguments.max_mesh_mb:g}")
    if arguments.filmstrip is not None and not arguments.png:
        raise InputError("--filmstrip", "given with --png FILE (the filmstrip's file)", "no --png")
    if arguments.filmstrip is not None and arguments.at != 0.0:
        raise InputError("--at", "not given with --filmstrip (its frames spread over the motion)", f"--at {arguments.at:g}")
    robot = load_robot(arguments)
    trajectory = Trajectory.load(arguments.trajectory).for_robot(robot)
    started = time.perf_counter()
    with warnings.catch_warnings():  # reported below, one line each
        warnings.simplefilter("ignore", MeshWarning)
        axes = tuple(name for name in (arguments.axes or "").split(",") if name)
        cap = {} if arguments.max_mesh_mb is None else {"max_mesh_bytes": int(arguments.max_mesh_mb * 1e6)}
        made = recording(robot, trajectory, fps=arguments.fps, target=arguments.target, frame=arguments.frame, axes=axes, **cap)
    for reason in made.placeholders:
        print(f"robodyn: warning: {reason}; drawn as a placeholder box", file=sys.stderr)
    if arguments.png:  # stills before the HTML is written: a failed still leaves no half result
        if arguments.filmstrip is not None:
            made.filmstrip(arguments.png, arguments.filmstrip)
        else:
            made.still(arguments.png, at=arguments.at)
    videos = [path for path in (arguments.mp4, arguments.gif) if path]
    for path in videos:
        made.video(path, fps=arguments.video_fps)
    path = made.save(arguments.out)
    size = f"{len(made.html.encode()) / 1e6:.2f} MB"
    print(
        f"wrote {path or 'standard output'} ({size}, {made.duration:.3g} s at {arguments.fps:g} fps, "
        f"{time.perf_counter() - started:.2f} s)",
        file=sys.stderr if path is None else sys.stdout,
    )
    for extra in ([arguments.png] if arguments.png else []) + videos:
        print(f"wrote {extra}")
    return 0
