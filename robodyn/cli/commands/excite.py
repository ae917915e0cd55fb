"""`robodyn excite`: an exciting periodic trajectory for identification, written to a file."""

from __future__ import annotations

import argparse

from robodyn.cli.common import add_model_arguments, load_robot, vector


def add_parser(commands: argparse._SubParsersAction) -> None:
    """Add the command to the ``robodyn`` parser.

    Args:
        commands: The subparsers of the ``robodyn`` parser, from ``add_subparsers``.
    """
    parser = commands.add_parser(
        "excite", help="a periodic Fourier-series trajectory within the limits that conditions the base regressor"
    )
    add_model_arguments(parser)
    parser.add_argument("--duration", type=float, default=10.0, help="period of the trajectory in [s] (default 10)")
    parser.add_argument("--out", required=True, help="trajectory file (.csv or .npz), tau = the model's inverse dynamics")
    parser.add_argument("--harmonics", type=int, default=5, help="harmonics per joint (default 5)")
    parser.add_argument("--rate", type=float, default=100.0, help="sampling rate of the file in [Hz] (default 100)")
    parser.add_argument("--velocity-limit", type=vector, help="per joint or one value (default: the URDF's)")
    parser.add_argument("--acceleration-limit", type=vector, help="per joint or one value (default 5 rad/s², 0.5 m/s²)")
    parser.add_argument("--iterations", type=int, default=60, help="optimiser iterations (default 60)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the random start")
    parser.add_argument("--lock", help="freeze joints: name=value,... (e.g. panda_finger_joint1=0)")
    parser.set_defaults(run=run)


def _limit(values: list[float] | None):
    return None if values is None else (values[0] if len(values) == 1 else values)


def run(arguments: argparse.Namespace) -> int:
    """Run ``robodyn excite`` with the parsed ``arguments``; return the exit status.

    Args:
        arguments: The command line parsed by the parser :func:`add_parser` built.
    """
    from robodyn.ident.run import excite_run

    run = excite_run(
        load_robot(arguments),
        out=arguments.out,
        rate=arguments.rate,
        harmonics=arguments.harmonics,
        duration=arguments.duration,
        velocity_limit=_limit(arguments.velocity_limit),
        acceleration_limit=_limit(arguments.acceleration_limit),
        iterations=arguments.iterations,
        seed=arguments.seed,
    )
    print(run.text())
    return 0
