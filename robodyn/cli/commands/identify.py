"""`robodyn identify`: base parameters of a model, or its parameters identified from data."""

from __future__ import annotations

import argparse
import json

from robodyn.cli.common import add_model_arguments, load_robot
from robodyn.exceptions import InputError


def add_parser(commands: argparse._SubParsersAction) -> None:
    """Add the command to the ``robodyn`` parser."""
    parser = commands.add_parser("identify", help="identify base inertial parameters from a trajectory with tau columns")
    add_model_arguments(parser)
    parser.add_argument("data", nargs="?", help="trajectory file (.csv or .npz) with q, v, a and tau columns")
    parser.add_argument("--method", choices=["ls", "wls", "physical"], default="ls", help="estimator (default ls)")
    parser.add_argument("--friction", action="store_true", help="also identify viscous and Coulomb friction per joint")
    parser.add_argument("--out", help="write the result as JSON to this file")
    parser.add_argument("--urdf-out", help="with --method physical: write the identified URDF to this file")
    parser.add_argument("--base-parameters", action="store_true", help="print the base parameters of the model and stop")
    parser.add_argument("--format", choices=["text", "latex", "json"], default="text", help="with --base-parameters")
    parser.add_argument("--lock", help="freeze joints: name=value,... (e.g. panda_finger_joint1=0)")
    parser.set_defaults(run=run)


def run(arguments: argparse.Namespace) -> int:
    from robodyn.common.files import atomic_write_text
    from robodyn.common.text import printable
    from robodyn.ident import base_parameters, identified_urdf, identify
    from robodyn.ident.render import render_base_parameters
    from robodyn.trajectory import Trajectory

    if arguments.urdf_out and arguments.method != "physical":
        raise InputError(
            "--urdf-out", "used with --method physical (only it gives consistent standard parameters)", arguments.method
        )
    if arguments.data is None and not arguments.base_parameters:
        raise InputError("DATA", "a trajectory file (or --base-parameters)", "nothing")
    robot = load_robot(arguments)
    base = base_parameters(robot, friction=arguments.friction)
    if arguments.base_parameters:
        print(render_base_parameters(base, arguments.format), end="")
        return 0
    data = Trajectory.load(arguments.data).for_robot(robot)
    if data.tau is None:
        raise InputError("DATA", "a trajectory file with tau[<joint>] columns (the measured torques)", repr(arguments.data))
    result = identify(robot, data, method=arguments.method, base=base)  # type: ignore[arg-type]  # tau checked above
    urdf = identified_urdf(robot, result.standard, base.columns) if arguments.urdf_out and result.standard is not None else None
    width = max(len(printable(name)) for name in base.names)
    print(
        f"{printable(robot.name)}: {arguments.method} identification of {base.count} base parameters from {result.samples} samples"
    )
    print(f"condition number {result.condition:.4g}; relative torque error {result.relative_error:.3g}\n")
    print(f"{'parameter':{width}s} {'identified':>12s} {'std':>10s} {'URDF':>12s}")
    for name, value, std, nominal in zip(base.names, result.values, result.std, base.values, strict=True):
        print(f"{printable(name):{width}s} {value:>12.6g} {std:>10.3g} {nominal:>12.6g}")
    if arguments.out:
        atomic_write_text(arguments.out, json.dumps(result.to_dict(), indent=2) + "\n")
        print(f"\nwrote {arguments.out}")
    if urdf is not None:
        atomic_write_text(arguments.urdf_out, urdf)
        print(f"wrote {arguments.urdf_out}")
    return 0
