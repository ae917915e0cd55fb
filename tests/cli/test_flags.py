"""Library errors name parameters; the command line names flags (issue 23).

The library says ``target``; ``robodyn`` maps it to ``--target`` through one table,
:data:`robodyn.cli.flags.FLAGS`.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

import robodyn
from robodyn.cli import main
from robodyn.cli.flags import FLAGS, error_text
from robodyn.exceptions import DerivationTooExpensiveError, InputError, SchedulerError
from robodyn.sim.experiment import run_simulation

PACKAGE = Path(robodyn.__file__).parent
#: Literals starting with ``--`` that are not robodyn's flags: matplotlib's dashed line
#: style, and the command-line flags of programs robodyn runs (Chromium, the C compiler).
NOT_OUR_FLAGS = {
    ("viz/plots.py", "--"),
    ("compiled/build.py", "--version"),
    ("compiled/simd.py", "--rds"),  # C source: the decrement --rds_level
    ("compiled/tangent_single.py", "--i"),  # C source: the decrement --i
}
#: Files whose every ``--`` literal is a flag of the program they run.
OTHER_PROGRAMS = {"viz/stills.py"}
#: A flag anywhere in a string: two dashes and a word, not part of a longer word or rule.
FLAG = re.compile(r"(?<![\w-])--[a-z][a-z0-9-]*")


def _dash_literals() -> set[tuple[str, str]]:
    found = set()
    for path in PACKAGE.rglob("*.py"):
        relative = path.relative_to(PACKAGE).as_posix()
        if relative.startswith("cli/") or relative in OTHER_PROGRAMS:
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"))
        docstrings = {
            id(node.body[0].value)
            for node in ast.walk(tree)
            if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef)
            and node.body
            and isinstance(node.body[0], ast.Expr)
            and isinstance(node.body[0].value, ast.Constant)
        }
        for node in ast.walk(tree):
            if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docstrings:
                found.update((relative, flag) for flag in FLAG.findall(node.value))
                if node.value == "--":
                    found.add((relative, "--"))
    return found


def test_no_string_of_the_library_outside_the_cli_names_a_flag():
    found = _dash_literals()
    assert found <= NOT_OUR_FLAGS, sorted(found - NOT_OUR_FLAGS)
    assert ("viz/plots.py", "--") in found  # the scan sees literals at all (a negative control)
    assert FLAG.findall("or use --format latex (check_inertia=False)") == ["--format"]  # and flags mid-sentence


def test_a_library_call_with_a_bad_target_names_the_parameter_target():
    robot = robodyn.load("rp_arm")
    with pytest.raises(InputError) as raised:
        run_simulation(robot, controller="task-space", target=[0.1, 0.2, 0.3, 0.4], duration=0.01)
    assert raised.value.argument == "target"
    assert str(raised.value).startswith("target must be X,Z or X,Y,Z") and "--" not in str(raised.value)


def test_the_cli_names_the_flag_target_for_the_same_error(capsys):
    argv = ["simulate", "rp_arm", "--controller", "task-space", "--target", "0.1,0.2,0.3,0.4", "--duration", "0.01"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("robodyn: error: --target must be X,Z or X,Y,Z") and err.count("\n") == 1


def test_a_passive_run_given_a_target_is_refused_naming_target_in_the_library_and_the_flag_in_the_cli(capsys):
    with pytest.raises(InputError, match=r"^target must be given only with a controller"):
        run_simulation(robodyn.load("rp_arm"), target=[0.1, 0.2], duration=0.01)
    assert main(["simulate", "rp_arm", "--target", "0.1,0.2", "--duration", "0.01"]) == 2
    assert "--target must be given only with a controller" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("error", "library", "cli"),
    [
        (DerivationTooExpensiveError("ur5", 6, 99.0, 10.0), "use form='compact'.", "use --form compact."),
        (SchedulerError("tcp://nowhere:1", "unreachable"), "scheduler='tcp://nowhere:1': unreachable.", "--scheduler 'tcp://"),
        (InputError("out", "a .csv, .npz or .parquet file", "'x.txt'"), "out must be a .csv", "--out must be a .csv"),
        (InputError("q", "7 values", "6 values"), "q must be 7 values", "q must be 7 values"),
    ],
)
def test_error_text_maps_parameters_to_flags_through_the_one_table(error, library, cli):
    assert library in str(error)
    assert cli in error_text(error)


def test_every_flag_of_the_table_is_a_flag_or_a_positional_argument_of_some_command():
    from robodyn.cli.app import build_parser

    parser = build_parser()
    commands = next(action for action in parser._actions if hasattr(action, "choices") and action.choices)
    known = {
        name
        for sub in commands.choices.values()
        for action in sub._actions
        for name in [*action.option_strings, action.dest.upper()]
    }
    assert set(FLAGS.values()) <= known, sorted(set(FLAGS.values()) - known)


def test_a_suggested_boolean_keyword_becomes_its_switch_on_the_command_line(capsys):
    from robodyn.cli import main
    from robodyn.equations import derive_equations

    with pytest.raises(InputError, match=r"\(floating_base=False\)"):
        derive_equations("solo12")
    assert main(["equations", "solo12", "--symbolic"]) == 2
    err = capsys.readouterr().err
    assert "(--fixed-base)" in err and "floating_base=" not in err


def test_a_refused_robot_is_named_as_the_model_argument_the_user_typed(capsys):
    from robodyn.cli.app import main

    assert main(["equations", "ur5", "--derivation"]) == 2  # 6 moving joints: too many to work step by step
    err = capsys.readouterr().err
    assert "MODEL must be a robot of at most 4 moving joints" in err and "source" not in err
