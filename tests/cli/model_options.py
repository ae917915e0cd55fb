"""The robots and shared model options the CLI option tests cross (``tests/cli/test_*_options.py``).

A run's model options are a dict: ``model`` (``"oblique"``: the 3-D test robot with oblique
non-unit axes, a prismatic joint and a fixed joint between moving ones; ``"xacro"``: the xacro
test arm with a mimic joint, read through ``--xacro-arg`` and ``--package``), ``base``
(``None``, ``"floating"``, ``"fixed"``), ``gravity`` (``None`` or a vector) and ``lock``
(``None`` or ``"locked"``: the model's :data:`LOCKS`). :func:`robot_of` loads the robot the
Python API gives for them, :func:`model_arguments` writes them as the command line does.
"""

from __future__ import annotations

from collections.abc import Sequence

import robodyn
from tests.cli.option_runs import GRAVITY, OBLIQUE, PACKAGE, XACRO, XACRO_ARGS, refused, run

__all__ = ["GRAVITY", "OBLIQUE", "PACKAGE", "XACRO", "XACRO_ARGS", "model_arguments", "robot_of", "run_command"]
#: The joint each model locks for ``lock="locked"``, at a non-zero position.
LOCKS = {"oblique": {"j_extend": 0.05}, "xacro": {"r_slide": 0.05}}


def robot_of(options: dict, model: str | None = None) -> robodyn.Robot:
    """The robot as the Python API loads it with the run's model options (``model``: the
    oblique robot's file, when a test uses a variant of it)."""
    keywords: dict = {"floating_base": {"floating": True, "fixed": False}.get(options.get("base") or "")}
    if options.get("gravity"):
        keywords["gravity"] = options["gravity"]
    if options.get("lock"):
        keywords["lock"] = LOCKS[options["model"]]
    if options["model"] == "xacro":
        return robodyn.load(XACRO, xacro_args=XACRO_ARGS, packages={"robodyn_test_arm": str(PACKAGE)}, **keywords)
    return robodyn.load(model or OBLIQUE, **keywords)


def model_arguments(options: dict, model: str | None = None) -> list[str]:
    """The model and its options on a command line (the model first)."""
    if options["model"] == "xacro":
        arguments = [str(XACRO), *(f"--xacro-arg={k}:={v}" for k, v in XACRO_ARGS.items())]
        arguments.append(f"--package=robodyn_test_arm={PACKAGE}")
    else:
        arguments = [str(model or OBLIQUE)]
    if options.get("base"):
        arguments.append(f"--{options['base']}-base")
    if options.get("gravity"):
        arguments.append("--gravity=" + ",".join(map(str, options["gravity"])))
    if options.get("lock"):
        arguments.append("--lock=" + ",".join(f"{k}={v}" for k, v in LOCKS[options["model"]].items()))
    return arguments


run_command = run


def refused_in_one_line(argv: Sequence[str], *names: str) -> None:
    """``robodyn ARGV`` exits 2 with one stderr line that names each of ``names``."""
    error = refused(list(argv))
    for name in names:
        assert name in error, (name, error)
