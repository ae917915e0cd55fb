"""`robodyn whatif`: the materials / payloads / forces sweep."""

from __future__ import annotations

import argparse
from typing import Any

import robodyn
from robodyn.cli.common import RANGES, vector
from robodyn.common.text import json_text, printable
from robodyn.exceptions import InputError


def add_parser(commands: argparse._SubParsersAction) -> None:
    """Add the command to the ``robodyn`` parser."""
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
    from robodyn.cli.report import dof_units
    from robodyn.sim.whatif import sweep, table_dict, table_text
    from robodyn.viz.plots import plot_whatif

    materials = tuple(arguments.materials.split(",")) if arguments.materials else None
    forces = ((0.0, 0.0, 0.0),) + ((tuple(arguments.force),) if arguments.force else ())
    if arguments.force and len(arguments.force) != 3:
        raise InputError("--force", "3 values FX,FY,FZ in [N]", f"{len(arguments.force)} values")
    options: dict[str, Any] = {"materials": materials, "payloads": tuple(arguments.payloads), "forces": forces}
    options |= {"duration": arguments.duration, "frame": arguments.frame}
    if arguments.scheduler:
        from robodyn.scale.cluster import connect
        from robodyn.scale.sweeps import sweep as distributed_sweep

        with connect(arguments.scheduler) as client:
            rows = distributed_sweep(arguments.model, client=client, **options)
    else:
        rows = sweep(arguments.model, **options)
    robot = robodyn.load(arguments.model)
    units = dof_units(robot)["tau"]
    if arguments.plot:
        plot_whatif(rows, robot.joint_names, units, arguments.plot, effort_limits=[float(e) for e in rows[0].effort])
    if arguments.json:
        print(json_text(table_dict(rows, robot.joint_names, units)))
    else:
        print(f"{printable(robot.name)}: one rest-to-rest motion of {arguments.duration:g} s; torques of each joint\n")
        print(table_text(rows, robot.joint_names, units))
        if arguments.plot:
            print(f"\nplot: {arguments.plot}")
    return 0
