"""`robodyn linearize`: (A, B) of a robot's dynamics about one state, continuous or one step."""

from __future__ import annotations

import argparse

import numpy as np

from robodyn.cli.common import RANGES, add_model_arguments, load_robot, state, vector
from robodyn.common.text import json_text
from robodyn.exceptions import InputError


def add_parser(commands: argparse._SubParsersAction) -> None:
    """Add the command to the ``robodyn`` parser.

    Args:
        commands: The subparsers of the ``robodyn`` parser, from ``add_subparsers``.
    """
    parser = commands.add_parser(
        "linearize",
        help="(A, B) of the dynamics about a state: continuous time, or the exact Jacobians of one simulator step",
        description="Linearise x = (q, v), input u (torques of the actuated joints): continuous time "
        "(dx/dt = A dx + B du) or, with --dt, one step of robodyn's integrator (dx+ = A dx + B du), "
        "by Pinocchio's analytical derivatives. A floating base's q perturbations are in the tangent space.",
    )
    add_model_arguments(parser)
    parser.add_argument("--q", type=vector, help="configuration, comma-separated, in [rad] / [m] (default: neutral)")
    parser.add_argument("--v", type=vector, help="velocity in [rad/s] / [m/s] (default: zeros)")
    parser.add_argument("--tau", type=vector, help="torques in [N m] / [N] (default: the holding torque C(q, v) v + G(q))")
    parser.add_argument("--dt", type=float, help=f"step, {RANGES['dt'].text()}: the Jacobians of one step (default: continuous)")
    parser.add_argument("--integrator", choices=["rk4", "semi-implicit-euler"], help="with --dt (default rk4)")
    parser.add_argument("--actuated", help="actuated joints, comma-separated (default: all): the columns of B")
    parser.add_argument(
        "--no-joint-friction",
        dest="joint_friction",
        action="store_false",
        help="leave out the joints' damping and friction (<dynamics>): the rigid-body dynamics (needed at rest "
        "joints with Coulomb friction, where stiction is not differentiable)",
    )
    parser.add_argument("--json", action="store_true", help="print JSON (keys A, B, state, inputs, units, ...)")
    parser.add_argument(
        "--precision", type=int, choices=range(1, 18), metavar="1..17", help="significant digits of the text (default 6)"
    )
    parser.set_defaults(run=run)


def run(arguments: argparse.Namespace) -> int:
    """Run ``robodyn linearize`` with the parsed ``arguments``; return the exit status.

    Args:
        arguments: The command line parsed by the parser :func:`add_parser` built.
    """
    from robodyn.sim.linearize import actuation_matrix, linearization

    if arguments.integrator is not None and arguments.dt is None:
        raise InputError("--integrator", "given with --dt (continuous time has no integrator)", repr(arguments.integrator))
    if arguments.precision is not None and arguments.json:
        raise InputError("--precision", "left out with --json (JSON carries every digit)", str(arguments.precision))
    robot = load_robot(arguments)
    q = state(robot, arguments.q, "q", robot.nq, robot.neutral_configuration())
    v = state(robot, arguments.v, "v", robot.nv, np.zeros(robot.nv))
    tau = None if arguments.tau is None else state(robot, arguments.tau, "tau", robot.nv, np.zeros(robot.nv))
    actuated = None if arguments.actuated is None else [name.strip() for name in arguments.actuated.split(",")]
    result = linearization(
        robot, q, v, tau, dt=arguments.dt, integrator=arguments.integrator or "rk4",
        actuation=actuation_matrix(robot, actuated), joint_friction=arguments.joint_friction,
    )  # fmt: skip
    print(json_text(result.to_dict()) if arguments.json else result.text(precision=arguments.precision or 6))
    return 0
