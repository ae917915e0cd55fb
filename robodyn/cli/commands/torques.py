"""`robodyn torques`: inverse dynamics over a whole trajectory file (and optionally G, M)."""

from __future__ import annotations

import argparse

from robodyn.cli.common import Progress, add_model_arguments, load_robot
from robodyn.common.text import json_text


def _rows(text: str) -> int:
    try:
        rows = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a whole number: {text!r}") from None
    if not 3 <= rows <= 10_000_000:
        raise argparse.ArgumentTypeError(f"must be between 3 and 10000000, got {rows}")
    return rows


def add_parser(commands: argparse._SubParsersAction) -> None:
    """Add the command to the ``robodyn`` parser.

    Args:
        commands: The subparsers of the ``robodyn`` parser, from ``add_subparsers``.
    """
    parser = commands.add_parser(
        "torques",
        help="inverse dynamics over a trajectory file (CSV, NPZ, Parquet), in chunks; writes tau[<joint>] columns",
        description="Inverse dynamics tau = M(q) a + C(q, v) v + G(q) of every sample of a trajectory file, "
        "read in chunks (files larger than memory are fine). Without v or a columns they are derived from q "
        "(second-order finite differences; see docs/trajectory-format.md).",
    )
    add_model_arguments(parser)
    parser.add_argument("trajectory", help="trajectory file (.csv, .npz or .parquet; columns t, q[<joint>], v[...], a[...])")
    parser.add_argument("--out", help="output file (.csv, .npz or .parquet): the input's columns plus tau[<joint>]")
    parser.add_argument("--gravity-torques", action="store_true", help="also write G(q) as G[<joint>] columns")
    parser.add_argument(
        "--mass-matrix", action="store_true", help="also write M(q): upper triangle M[<row>,<col>] (NPZ: N×nv×nv)"
    )
    parser.add_argument("--chunk-rows", type=_rows, default=65_536, metavar="N", help="rows a chunk (default 65536)")
    parser.add_argument(
        "--scheduler",
        metavar="ADDRESS|local:N",
        help="compute on Dask: a scheduler address (tcp://host:8786) or local:N worker processes on 127.0.0.1",
    )
    parser.add_argument("--json", action="store_true", help="print the summary as JSON")
    parser.set_defaults(run=run)


def run(arguments: argparse.Namespace) -> int:
    """Run ``robodyn torques`` with the parsed ``arguments``; return the exit status.

    Args:
        arguments: The command line parsed by the parser :func:`add_parser` built.
    """
    from robodyn.scale.torques import torques_run

    robot = load_robot(arguments)
    progress = Progress("torques")
    try:
        summary = torques_run(
            robot,
            arguments.trajectory,
            arguments.out,
            scheduler=arguments.scheduler,
            gravity=arguments.gravity_torques,
            mass_matrix=arguments.mass_matrix,
            rows=arguments.chunk_rows,
            progress=lambda done, total: progress("inverse dynamics", done, total),
        )
    finally:
        progress.close()
    print(json_text(summary.to_dict()) if arguments.json else summary.text())
    return 0
