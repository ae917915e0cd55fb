"""Every option of `robodyn equations --symbolic` alone, read back, and crossed pairwise.

The equations written (text, JSON or a Python module) are evaluated here at random states
— the text and JSON split by hand and their expressions run with ``math``, the module
executed — and compared with the Robot loaded with the same options (``mass_matrix``,
``nonlinear_effects − gravity``, ``gravity``): what an option does shows in the numbers,
and what it must not do (gravity lost with a lock, parameters kept but not substituted)
fails. Each option alone is checked against the run with none, then a pairwise-covering set
(tests/pairwise.py). Derivations are slow (seconds each on these 3-D robots): each distinct
one is made once for the module (the library's derivation memoised in a fixture), the
renderings from it as the runs ask.
"""

from __future__ import annotations

import functools
import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

import robodyn.equations.document as document_module
from tests.cli.option_runs import GRAVITY, model_arguments, refused, robot_of, run
from tests.pairwise import pairwise, uncovered_pairs

pytestmark = pytest.mark.slow

#: The joints each run locks: the oblique robot always its prismatic joint (three joints, a derivation
#: of a second, not four), ``--lock`` one more (the xacro arm's names carry its prefix argument).
ALWAYS = {"oblique": {"j_extend": 0.1}, "xacro": {}}
LOCKED = {"oblique": {"j_twist": 0.3}, "xacro": {"r_slide": 0.05}}
ANCHORED = {"oblique": "end_effector", "xacro": "r_wrist"}
#: Each option's values; the first is the default (the option left out).
FACTORS: dict[str, tuple | list] = {
    "model": ("xacro", "oblique"),
    "format": ("text", "json", "python"),
    "keep_params": (False, True),
    "gravity": (None, GRAVITY),
    "lock": (None, "one"),
    "precision": (None, 3),
    "out": (None, "file"),
    "base": (None, "fixed"),
    "constraints": (None, "anchor"),
}
DEFAULT = {name: values[0] for name, values in FACTORS.items()}


def valid(run: dict) -> bool:
    """Code needs numbers (no kept parameters); digits only for text."""
    if run.get("keep_params") and run.get("format", "text") == "python":
        return False
    return not (run.get("precision") and run.get("format", "text") != "text")


RUNS = pairwise(FACTORS, valid)
_DERIVED: dict = {}


@pytest.fixture(autouse=True)
def derive_once(monkeypatch):
    """The library's derivation memoised for the module (its renderings are not)."""
    derive = _DERIVED.setdefault("derive", document_module.derive_equations)

    def memoised(source, **options):
        options.pop("progress", None)
        key = (str(source), repr(sorted(options.items())))
        if key not in _DERIVED:
            _DERIVED[key] = derive(source, **options)
        return _DERIVED[key]

    monkeypatch.setattr(document_module, "derive_equations", memoised)


def test_the_runs_cover_every_pair_and_are_few():
    assert uncovered_pairs(RUNS, FACTORS, valid) == [] and all(valid(run) for run in RUNS)
    assert len(RUNS) <= 10  # not the 768 of all combinations


def arguments_of(options: dict, folder: Path, out: Path | None) -> list[str]:
    flags = ["--symbolic", "--format", options["format"], *(["--keep-params"] if options["keep_params"] else [])]
    flags += ["--gravity=" + ",".join(map(str, options["gravity"]))] if options["gravity"] else []
    flags += ["--lock=" + ",".join(f"{k}={v}" for k, v in locks(options).items())] if locks(options) else []
    flags += ["--precision", str(options["precision"])] if options["precision"] else []
    flags += ["--fixed-base"] if options["base"] else []
    flags += ["--out", str(out)] if out else []
    if options["constraints"]:
        (folder / "anchor.yaml").write_text(
            f"anchor:\n  - name: tip\n    frame1: {ANCHORED[options['model']]}\n    point1: [0.05, 0, 0]\n"
        )
        flags += ["--constraints", str(folder / "anchor.yaml")]
    return ["equations", *model_arguments(options["model"]), *flags]


def locks(options: dict) -> dict[str, float]:
    return ALWAYS[options["model"]] | (LOCKED[options["model"]] if options["lock"] else {})


MATH = {"sin": math.sin, "cos": math.cos, "tan": math.tan, "sqrt": math.sqrt, "exp": math.exp, "pi": math.pi}


def read_text(text: str) -> dict:
    """The text split by hand: joints and their symbols, gravity, parameters, the
    intermediate variables and the entries of M, C qd and G."""
    joints = re.findall(r"(\S+) \(q = (\S+)\)", next(line for line in text.splitlines() if line.startswith("joints: ")))
    gravity = re.search(r"^gravity: \((.*)\)", text, re.M)
    parameters = re.search(r"^parameters: (.*)$", text, re.M)
    n = len(joints)
    entries = {
        key: re.findall(rf"^{pattern} = (.*)$", text, re.M)
        for key, pattern in (("M", r"M\[\d+,\d+\]"), ("Cv", r"\(C qd\)\[\d+\]"), ("G", r"G\[\d+\]"))
    }
    return {
        "joint_names": [name for name, _ in joints], "q": [symbol for _, symbol in joints],
        "qd": ["qd" + symbol[1:] for _, symbol in joints], "gravity": [float(x) for x in gravity.group(1).split(",")] if gravity else None,
        "parameters": dict((k, float(v)) for k, v in (item.split(" = ") for item in parameters.group(1).split(", "))) if parameters else {},
        "assignments": re.findall(r"^  (\w+) = (.*)$", text, re.M),
        "M": [entries["M"][k * n : (k + 1) * n] for k in range(n)], "Cv": entries["Cv"], "G": entries["G"],
    }  # fmt: skip


def evaluator(document: dict):
    """A function of (q, qd) giving M, C qd and G by running the document's expressions."""
    steps = [(name, compile(expression, name, "eval")) for name, expression in document["assignments"]]
    outputs = {
        key: [[compile(e, key, "eval") for e in (row if isinstance(row, list) else [row])] for row in document[key]]
        for key in ("M", "Cv", "G")
    }

    def terms(q, qd):
        scope = (
            dict(document["parameters"]) | dict(zip(document["q"], q, strict=True)) | dict(zip(document["qd"], qd, strict=True))
        )
        for name, code in steps:
            scope[name] = eval(code, MATH, scope)
        values = {
            key: np.array([[float(eval(code, MATH, scope)) for code in row] for row in rows]) for key, rows in outputs.items()
        }
        return values["M"], values["Cv"].ravel(), values["G"].ravel()

    return terms


def module_terms(text: str):
    """The generated module, executed: its joint names and a function of (q, qd) giving M, C qd, G."""
    scope: dict = {}
    exec(compile(text, "generated", "exec"), scope)
    return scope["JOINT_NAMES"], lambda q, qd: (scope["mass_matrix"](q), scope["coriolis_forces"](q, qd), scope["gravity"](q))


def check_run(options: dict, folder: Path) -> tuple[str, str]:
    """Run the command and evaluate what it wrote against the Robot with the same options."""
    out = folder / f"equations.{options['format']}" if options["out"] else None
    code, printed, err = run(arguments_of(options, folder, out))
    assert code == 0, err
    if out is not None:
        assert printed == "" and f"wrote {out}" in err
        printed = out.read_text()
    assert ("'tip'" in err) == bool(options["constraints"])  # the open tree's equations, said so
    robot = robot_of({"model": options["model"], "gravity": options["gravity"], "lock": locks(options)})
    if options["format"] == "python":
        names, terms = module_terms(printed)
    else:
        document = json.loads(printed) if options["format"] == "json" else read_text(printed)
        names, terms = document["joint_names"], evaluator(document)
        assert document["gravity"] == list(options["gravity"] or (0.0, 0.0, -9.81))
        assert bool(document["parameters"]) == options["keep_params"]
    assert sorted(names) == sorted(robot.joint_names)
    order = [robot.joint_names.index(name) for name in names]
    digits = 3 * 10.0 ** (1 - (options["precision"] or 6)) if options["format"] == "text" else 1e-9
    rng = np.random.default_rng(39)
    for _ in range(2):
        q, v = robot.random_configuration(rng), rng.normal(size=robot.nv)
        expected = (robot.mass_matrix(q), robot.nonlinear_effects(q, v) - robot.gravity(q), robot.gravity(q))
        for name, value, wanted in zip(("M", "C v", "G"), terms(q[order], v[order]), expected, strict=True):
            wanted = wanted[np.ix_(order, order)] if wanted.ndim == 2 else wanted[order]
            np.testing.assert_allclose(value, wanted, rtol=digits, atol=digits * np.abs(wanted).max(), err_msg=name)
    return printed, err


#: Each option alone against the run with none: whether the text written changes.
ALONE = [
    ("model", "oblique", True), ("format", "json", True), ("format", "python", True), ("keep_params", True, True),
    ("gravity", GRAVITY, True), ("lock", "one", True), ("precision", 3, True), ("out", "file", False),
    ("base", "fixed", False), ("constraints", "anchor", False),
]  # fmt: skip


@functools.cache
def base_written() -> str:
    """The equations of the run with no option (no file written: its folder unused), once for the module."""
    return check_run(DEFAULT, Path("unused"))[0]


@pytest.mark.parametrize(("option", "value", "changes"), ALONE, ids=[f"{name}={value}" for name, value, _ in ALONE])
def test_each_option_alone_writes_its_equations_and_nothing_else(option, value, changes, tmp_path):
    written, _ = check_run(DEFAULT | {option: value}, tmp_path)
    base = base_written()
    assert (written != base) == changes


def test_gravity_is_not_lost_with_a_lock_negative_control(tmp_path):
    """The checker bites: the run with a lock and gravity evaluated against the Robot without the gravity fails."""
    options = DEFAULT | {"lock": "one", "gravity": GRAVITY, "format": "json"}
    written, _ = check_run(options, tmp_path)
    with pytest.raises(AssertionError, match="G"):
        check_run_against(written, options | {"gravity": None})


def check_run_against(written: str, options: dict) -> None:
    document = json.loads(written)
    robot = robot_of({"model": options["model"], "lock": locks(options)})
    order = [robot.joint_names.index(name) for name in document["joint_names"]]
    q = robot.random_configuration(np.random.default_rng(1))
    wanted = robot.gravity(q)[order]
    np.testing.assert_allclose(evaluator(document)(q[order], np.zeros(robot.nv))[2], wanted, rtol=1e-9, err_msg="G")


#: What --symbolic refuses, one stderr line each.
REFUSED = [
    ["--format", "python", "--keep-params"], ["--format", "json", "--precision", "3"], ["--floating-base"],
    ["--form", "closed"], ["--json"], ["--q", "0,0,0"], ["--strict"], ["--max-dof", "12"], ["--no-check-inertia"],
]  # fmt: skip


@pytest.mark.parametrize("flags", REFUSED, ids=[" ".join(flags) for flags in REFUSED])
def test_each_refused_combination_is_one_stderr_line(flags):
    refused(["equations", *model_arguments("xacro"), "--symbolic", *flags])


@pytest.mark.parametrize("options", RUNS, ids=[str(k) for k in range(len(RUNS))])
def test_the_options_crossed_pairwise_write_the_robots_equations(options, tmp_path):
    check_run(options, tmp_path)
