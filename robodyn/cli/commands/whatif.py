"""`robodyn whatif`: the materials / payloads / forces sweep."""

from __future__ import annotations

import argparse

from robodyn.cli.common import RANGES, vector
from robodyn.common.text import counted, json_text
from robodyn.exceptions import InputError


def add_parser(commands: argparse._SubParsersAction) -> None:
    """Add the command to the ``robodyn`` parser.

    Args:
        commands: The subparsers of the ``robodyn`` parser, from ``add_subparsers``.
    """
    parser = commands.add_parser("whatif", help="peak and RMS torques of one motion across materials, payloads, forces")
    parser.add_argument("model", nargs="?", default="rp_arm", help="robot (default rp_arm; materials apply to rp_arm only)")
    parser.add_argument("--materials", help="comma-separated: abs (plastic), aluminium, steel or densities in kg/m³")
    parser.add_argument(
        "--payloads", type=vector, default=[0.0, 0.5, 2.0], help="payload masses in [kg] (each ≥ 0) at the end effector"
    )
    parser.add_argument("--force", type=vector, help="also an external force FX,FY,FZ in [N] on the end effector")
    parser.add_argument(
        "--frame", help="the frame carrying payload and force (default: the end effector 'robodyn info' shows; it must move)"
    )
    parser.add_argument("--duration", type=float, default=1.5, help=f"motion time, {RANGES['duration'].text()} (default 1.5)")
    parser.add_argument("--plot", help="PNG bar chart of the table")
    parser.add_argument(
        "--scheduler", metavar="ADDRESS|local:N", help="compute the variants on Dask (a scheduler address, or N local workers)"
    )
    parser.add_argument("--json", action="store_true", help="print JSON")
    parser.set_defaults(run=run)


def run(arguments: argparse.Namespace) -> int:
    """Run ``robodyn whatif`` with the parsed ``arguments``; return the exit status.

    Args:
        arguments: The command line parsed by the parser :func:`add_parser` built.
    """
    from robodyn.viz.experiment import run_whatif

    if arguments.force and len(arguments.force) != 3:
        raise InputError("--force", "3 values FX,FY,FZ in [N]", counted(len(arguments.force), "value"))
    table = run_whatif(
        arguments.model,
        scheduler=arguments.scheduler,
        plot=arguments.plot,
        materials=tuple(arguments.materials.split(",")) if arguments.materials else None,
        payloads=tuple(arguments.payloads),
        forces=((0.0, 0.0, 0.0),) + ((tuple(arguments.force),) if arguments.force else ()),
        duration=arguments.duration,
        frame=arguments.frame,
    )
    print(json_text(table.to_dict()) if arguments.json else table.text())
    return 0
