"""`robodyn equations`: tau, M, C, G at one state, or the symbolic equations."""

from __future__ import annotations

import argparse
import sys

import numpy as np

from robodyn.cli.common import (
    Progress,
    add_constraints_argument,
    add_model_arguments,
    constraints_file,
    load_robot,
    lock_values,
    package_arguments,
    state,
    vector,
    xacro_arguments,
)
from robodyn.common.text import json_text
from robodyn.exceptions import InputError

#: Each option's value when it is not given (``--fixed-base`` is never refused: every output models a fixed base or reads it).
_NOT_GIVEN: dict[str, object] = {
    "q": None, "v": None, "a": None, "json": False, "precision": 6, "symbolic": False, "format": "text", "out": None,
    "form": "auto", "keep_params": False, "lock": None, "kinematics": None, "christoffel": False, "base_parameters": False,
    "lecture": False, "derivation": False, "gravity": None, "floating_base": None, "strict": False, "check_inertia": True,
    "max_dof": None, "constraints": None,
}  # fmt: skip
_LOADING = frozenset({"gravity", "floating_base", "lock", "strict", "check_inertia", "max_dof"})
_EQUATIONS = frozenset(
    {"symbolic", "format", "out", "form", "keep_params", "gravity", "lock", "floating_base", "precision", "constraints"}
)
#: The options each output reads, by its label in a refusal (besides the model, --xacro-arg,
#: --package and --xacro-env): any other one given is refused, never silently ignored.
_READS: dict[str, frozenset[str]] = {
    "the numbers at one state": frozenset({"q", "v", "a", "json", "precision", "out"}) | _LOADING,
    "the numbers at one state as JSON": frozenset({"q", "v", "a", "json", "out"}) | _LOADING,
    "--symbolic": _EQUATIONS,
    "--christoffel": _EQUATIONS | {"christoffel"},
    "--kinematics": frozenset({"symbolic", "kinematics", "format", "out", "lock", "precision", "constraints"}),
    "--derivation": frozenset(
        {"symbolic", "derivation", "format", "out", "keep_params", "gravity", "lock", "precision", "constraints"}
    ),
    "--lecture": frozenset({"symbolic", "lecture", "format", "out"}),
    "--base-parameters": frozenset({"base_parameters", "format", "out"}) | _LOADING,
    "--format casadi or jax": frozenset({"symbolic", "format", "out", "keep_params"}) | _LOADING,
}


def add_parser(commands: argparse._SubParsersAction) -> None:
    """Add the command to the ``robodyn`` parser.

    Args:
        commands: The subparsers of the ``robodyn`` parser, from ``add_subparsers``.
    """
    parser = commands.add_parser("equations", help="tau, M, C and G of a robot at one state")
    add_model_arguments(parser)
    add_constraints_argument(parser)
    parser.add_argument("--q", type=vector, help="configuration, comma-separated, in [rad] / [m] (default: neutral)")
    parser.add_argument("--v", type=vector, help="velocity in [rad/s] / [m/s] (default: zeros)")
    parser.add_argument("--a", type=vector, help="acceleration in [rad/s²] / [m/s²] (default: zeros)")
    parser.add_argument("--json", action="store_true", help="print JSON (keys tau, M, C, G, joint_names, ...)")
    parser.add_argument("--precision", type=int, default=6, help="significant digits of numbers in text and LaTeX, 1..17")
    parser.add_argument("--symbolic", action="store_true", help="closed-form equations from the reference's symbolic Lagrangian")
    parser.add_argument(
        "--format",
        choices=["text", "latex", "pdf", "json", "python", "c", "casadi", "jax"],
        default="text",
        help="with --symbolic (pdf needs pdflatex and --out); casadi, jax: a standalone module whose functions() "
        "returns the robot's dynamics and frames (robodyn.export)",
    )
    parser.add_argument("--out", help="with --symbolic: write to this file instead of stdout")
    parser.add_argument(
        "--form",
        choices=["auto", "closed", "compact"],
        default="auto",
        help="closed (simplified) or compact (intermediate variables)",
    )
    parser.add_argument(
        "--keep-params",
        action="store_true",
        help="keep every link's mass, centre of mass, inertia, joint offsets and g as symbols",
    )
    parser.add_argument("--lock", help="freeze joints: name=value,... (e.g. panda_finger_joint1=0)")
    parser.add_argument(
        "--kinematics",
        metavar="FRAME",
        help="with --symbolic: forward kinematics and Jacobian of a link (formats text, latex, json, python, c)",
    )
    parser.add_argument(
        "--christoffel", action="store_true", help="with --symbolic: the Christoffel symbols of M (closed form; text or json)"
    )
    parser.add_argument(
        "--base-parameters",
        action="store_true",
        help="the identifiable combinations of the inertial parameters (robodyn.base_parameters; text, latex or json)",
    )
    parser.add_argument(
        "--lecture", action="store_true", help="rp_arm: the lecture's printed result, its correction and the URDF's, side by side"
    )
    parser.add_argument("--derivation", action="store_true", help="the Lagrangian worked step by step (up to 4 moving joints)")
    parser.set_defaults(run=run)


def _symbolic(arguments: argparse.Namespace) -> int:
    from robodyn.common.text import printable
    from robodyn.equations.document import What, equations_document

    if arguments.format == "pdf" and not arguments.out:
        raise InputError("--out", "given with --format pdf (a PDF is not printed)", "no --out")
    documents: tuple[What, ...] = ("lecture", "derivation", "kinematics", "christoffel")
    what: What = next((w for w in documents if getattr(arguments, w)), "equations")
    label = printable(str(arguments.kinematics if what == "kinematics" else arguments.model))
    progress = Progress(
        f"{'kinematics of' if what == 'kinematics' else 'deriving'} {label if len(label) <= 60 else label[:57] + '...'}"
    )
    try:
        document = equations_document(
            arguments.model, what, progress=progress, format=arguments.format, form=arguments.form,
            keep_params=arguments.keep_params, gravity=arguments.gravity, lock=lock_values(arguments.lock),
            floating_base=arguments.floating_base, frame=arguments.kinematics, precision=arguments.precision,
            xacro_args=xacro_arguments(arguments.xacro_arg) or None, packages=package_arguments(arguments.package) or None,
            xacro_env=arguments.xacro_env, constraints=constraints_file(arguments),
        )  # fmt: skip
    finally:
        progress.close()
    return _emit(arguments, document.content, document.description)


def _emit(arguments: argparse.Namespace, output: str | bytes, what: str) -> int:
    if arguments.out:
        from robodyn.common.files import atomic_write_bytes, atomic_write_text

        if isinstance(output, bytes):
            atomic_write_bytes(arguments.out, output)
        else:
            atomic_write_text(arguments.out, output)
        print(f"wrote {arguments.out} ({what})", file=sys.stderr)
    else:
        print(output, end="")
    return 0


def _base_parameters(arguments: argparse.Namespace) -> int:
    from robodyn.ident import base_parameters
    from robodyn.ident.render import render_base_parameters

    if arguments.format not in ("text", "latex", "json"):
        raise InputError("--format", "text, latex or json with --base-parameters", repr(arguments.format))
    robot = load_robot(arguments)
    return _emit(arguments, render_base_parameters(base_parameters(robot), arguments.format), "base parameters")


def _export(arguments: argparse.Namespace) -> int:
    from robodyn.common.text import printable
    from robodyn.export import module_source

    robot = load_robot(arguments)
    progress = Progress(f"exporting {printable(robot.name)[:60]}")
    try:
        source = module_source(robot, arguments.format, keep_params=arguments.keep_params, progress=progress)
    finally:
        progress.close()
    return _emit(arguments, source, f"{arguments.format} module, {robot.nv} joints, {len(robot.frame_names)} frames")


def run(arguments: argparse.Namespace) -> int:
    """Run ``robodyn equations`` with the parsed ``arguments``; return the exit status.

    Args:
        arguments: The command line parsed by the parser :func:`add_parser` built.
    """
    if arguments.constraints and not (arguments.derivation or arguments.symbolic or arguments.lecture):
        raise InputError(
            "--constraints",
            "given only with --derivation or --symbolic (the other outputs are the open tree's)",
            "it without them",
        )
    _refuse_unread(arguments)
    if arguments.base_parameters:
        return _base_parameters(arguments)
    if arguments.format in ("casadi", "jax"):
        return _export(arguments)
    if arguments.symbolic or arguments.lecture or arguments.derivation:
        return _symbolic(arguments)
    from robodyn.dynamics.terms import dynamics_terms
    from robodyn.equations.output import check_precision

    check_precision(arguments.precision)
    robot = load_robot(arguments)
    q = state(robot, arguments.q, "q", robot.nq, robot.default_configuration())
    v = state(robot, arguments.v, "v", robot.nv, np.zeros(robot.nv))
    a = state(robot, arguments.a, "a", robot.nv, np.zeros(robot.nv))
    terms = dynamics_terms(robot, q, v, a)
    return _emit(
        arguments,
        (json_text(terms.to_dict()) if arguments.json else terms.text(precision=arguments.precision)) + "\n",
        "tau, M, C, G",
    )


def _output(arguments: argparse.Namespace) -> str:
    """Which output the options ask for: its label in :data:`_READS` (the dispatch of :func:`run`)."""
    if arguments.base_parameters:
        return "--base-parameters"
    if arguments.format in ("casadi", "jax"):
        return "--format casadi or jax"
    for name in ("lecture", "derivation", *(("kinematics", "christoffel") if arguments.symbolic else ())):
        if getattr(arguments, name):
            return f"--{name}"
    if arguments.symbolic:
        return "--symbolic"
    return "the numbers at one state as JSON" if arguments.json else "the numbers at one state"


def _refuse_unread(arguments: argparse.Namespace) -> None:
    """Refuse the options given that the output asked for does not read (one line naming them all).

    Raises:
        InputError: Naming the options and the output.
    """
    output = _output(arguments)
    reads = _READS[output] - ({"precision"} if arguments.format not in ("text", "latex", "pdf") else set())
    unread = [name for name in _NOT_GIVEN if name not in reads and _given(arguments, name)]
    if unread:
        flags = ["--no-check-inertia" if name == "check_inertia" else f"--{name.replace('_', '-')}" for name in unread]
        them = "it" if len(flags) == 1 else "them"
        hint = {"the numbers at one state": "; --symbolic derives the equations"}.get(output, "")
        hint += (
            f"; --format {arguments.format} writes every digit" if "precision" in unread and arguments.format != "text" else ""
        )
        raise InputError(", ".join(flags), f"left out with {output} (it does not read {them}{hint})", "given")


def _given(arguments: argparse.Namespace, name: str) -> bool:
    value = getattr(arguments, name)
    if name == "floating_base":
        return value is True  # --fixed-base: every output models a fixed base or reads it
    return value != _NOT_GIVEN[name]
