"""What the tests of each command's options share: the two robots, their model arguments as
a user types them and as the Python API takes them, and one in-process run of ``robodyn``.

The robots: the oblique test robot (3-D, oblique non-unit axes, a prismatic joint, a fixed
joint between moving ones, Coulomb friction on ``j_twist``) and the xacro test arm (a mimic
joint, friction on its shoulder, read through ``--xacro-arg`` and ``--package``).
"""

from __future__ import annotations

import contextlib
import io
from collections.abc import Sequence

import robodyn
from robodyn.cli.app import main
from tests.conftest import ROOT

OBLIQUE = ROOT / "tests" / "data" / "robots" / "oblique.urdf"
PACKAGE = ROOT / "tests" / "data" / "packages" / "robodyn_test_arm"
XACRO = PACKAGE / "urdf" / "arm.urdf.xacro"
XACRO_ARGS = {"prefix": "r_", "upper_mass": "2.1"}
#: Not the default, not along an axis.
GRAVITY = (1.5, -2.0, -8.0)
#: Each file's <dynamics> (damping b in [N m s/rad], Coulomb friction f in [N m]), read off the files by eye.
FRICTION = {"oblique": {"j_twist": (0.1, 0.05)}, "xacro": {"r_shoulder": (0.4, 0.1)}}


def model_arguments(model: str) -> list[str]:
    """The model as a user types it: the file, and for the xacro arm its arguments and package."""
    if model == "xacro":
        return [str(XACRO), *(f"--xacro-arg={k}:={v}" for k, v in XACRO_ARGS.items()), f"--package=robodyn_test_arm={PACKAGE}"]
    return [str(OBLIQUE)]


def load_options(options: dict) -> dict:
    """The keywords of :func:`robodyn.load` for a run's ``model``, ``base``, ``gravity`` and ``lock``."""
    keywords: dict = {"floating_base": options["base"] == "floating" if options.get("base") else None}
    if options.get("gravity"):
        keywords["gravity"] = options["gravity"]
    if options.get("lock"):
        keywords["lock"] = options["lock"]
    if options["model"] == "xacro":
        keywords |= {"xacro_args": XACRO_ARGS, "packages": {"robodyn_test_arm": str(PACKAGE)}}
    return keywords


def source_of(options: dict):
    return XACRO if options["model"] == "xacro" else OBLIQUE


def robot_of(options: dict) -> robodyn.Robot:
    """The robot as the Python API loads it with the run's options."""
    return robodyn.load(source_of(options), **load_options(options))


def shared_flags(options: dict) -> list[str]:
    """The flags every model command takes, for the run's options (those it has)."""
    flags = []
    if options.get("gravity"):
        flags.append("--gravity=" + ",".join(map(str, options["gravity"])))
    if options.get("base"):
        flags.append(f"--{options['base']}-base")
    if options.get("inertia"):
        flags.append("--strict" if options["inertia"] == "strict" else "--no-check-inertia")
    if options.get("max_dof"):
        flags += ["--max-dof", str(options["max_dof"])]
    if options.get("lock"):
        flags.append("--lock=" + ",".join(f"{name}={value}" for name, value in options["lock"].items()))
    if options.get("json"):
        flags.append("--json")
    return flags


def run(argv: Sequence[str]) -> tuple[int, str, str]:
    """``robodyn ARGV`` in-process: its exit status, stdout and stderr."""
    stdout, stderr = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr):
        code = main([str(item) for item in argv])
    return code, stdout.getvalue(), stderr.getvalue()


def ok(argv: Sequence[str]) -> str:
    """The stdout of a run that must succeed."""
    code, out, err = run(argv)
    assert code == 0, f"{argv}: {err}"
    return out


def refused(argv: Sequence[str]) -> str:
    """The one stderr line of a run that must be refused (exit 2, nothing on stdout)."""
    code, out, err = run(argv)
    assert (code, out) == (2, ""), f"{argv}: {code} {out[:200]} {err}"
    assert err.count("\n") == 1 and err.startswith("robodyn: error: "), err
    return err
