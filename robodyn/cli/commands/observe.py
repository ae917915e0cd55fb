"""`robodyn observe`: the external torques a recorded motion reveals (momentum observer)."""

from __future__ import annotations

import argparse

from robodyn.cli.common import add_model_arguments, load_robot
from robodyn.common.text import json_text


def add_parser(commands: argparse._SubParsersAction) -> None:
    """Add the command to the ``robodyn`` parser.

    Args:
        commands: The subparsers of the ``robodyn`` parser, from ``add_subparsers``.
    """
    parser = commands.add_parser(
        "observe", help="estimate external torques from a trajectory file (momentum observer); detect a collision"
    )
    add_model_arguments(parser)
    parser.add_argument("file", help="trajectory file with torques (.csv, .npz, .parquet), e.g. from 'robodyn simulate --out'")
    parser.add_argument("--gain", type=float, required=True, help="observer gain K_O in [1/s] (63 %% of a step in 1/K_O)")
    parser.add_argument("--frame", help="also the wrench at this frame's origin: force[x|y|z] [N], torque[x|y|z] [N m]")
    parser.add_argument("--threshold", type=float, help="collision threshold in [N m] / [N] on each |tau_ext|")
    parser.add_argument(
        "--torque",
        choices=["held", "sampled"],
        default="held",
        help="how the recorded torque acted between samples: held (digital controller, default) or sampled (continuous)",
    )
    parser.add_argument("--out", help="CSV of the estimate: t, tau_ext[<joint>] (and with --frame the wrench)")
    parser.add_argument("--plot", help="PNG: estimated against applied external torques (the file's tau_env columns)")
    parser.add_argument("--lock", help="freeze joints: name=value,... (as the trajectory was recorded)")
    parser.add_argument("--json", action="store_true", help="print the summary as JSON")
    parser.set_defaults(run=run)


def run(arguments: argparse.Namespace) -> int:
    """Run ``robodyn observe`` with the parsed ``arguments``; return the exit status.

    Args:
        arguments: The command line parsed by the parser :func:`add_parser` built.
    """
    from robodyn.viz.experiment import run_observation

    observed = run_observation(
        load_robot(arguments),
        arguments.file,
        gain=arguments.gain,
        frame=arguments.frame,
        threshold=arguments.threshold,
        torque=arguments.torque,
        out=arguments.out,
        plot=arguments.plot,
    )
    print(json_text(observed.to_dict()) if arguments.json else observed.text())
    return 0
