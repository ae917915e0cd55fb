"""robodyn.common.text: every escape against hostile names, and each escaping helper defined once.

Also here:

- Family 1 of issue #14 (terminal part): one escaping function for every message.
"""

from __future__ import annotations

import ast
import io
import json
import re
import sys
import unicodedata
from pathlib import Path

import numpy as np
import pytest

import robodyn
from robodyn.cli.app import main
from robodyn.common import text
from robodyn.common.text import (
    comment_text,
    identifier,
    is_printable,
    json_text,
    latex_text,
    printable,
    printable_lines,
    quoted,
)
from robodyn.exceptions import FrameError, InputError, OutputError, RobodynError, UnknownRobotError, URDFError

ROBODYN = Path(text.__file__).resolve().parent.parent
#: Names that try to forge lines, recolour or clear the terminal, reverse text, end strings,
#: run TeX or leave a comment.
HOSTILE = [
    "j1\x1b[31m red \x1b[2J\x1b]0;title\x07",  # ANSI colour, clear screen, OSC title
    "gnp.\u202eexe",  # right-to-left override
    "a\nrobodyn: ok: everything fine",  # a forged line
    "nul\x00byte\x7fdel\x9bcsi",  # NUL, DEL, C1 CSI
    "back\\slash\\n not a newline",
    "tex $\\input{/etc/passwd}$ ^_&%#~ {}",
    'quotes \' " """ */ /* ??/',
    "cr\rline\u2028sep\u2029para\u2066iso\u2069\ufeff\u200bzw",
    "tag\U000e0041\U000e0042 nbsp\u00a0soft\u00adhyphen",
    "lone \ud800 surrogate",
]
#: Printable text of several scripts: kept as it is by the terminal escape.
READABLE = "Größe 質量 ü ⟂ 'x' é\u0301 Ωμέγα кулак"
#: The categories a terminal must never receive raw: controls, format characters
#: (bidi, zero-width, tags), separators other than the space, surrogates, private use,
#: unassigned.
UNSAFE_CATEGORIES = {"Cc", "Cf", "Cs", "Co", "Cn", "Zl", "Zp", "Zs"}
#: Every escaping helper of robodyn, and the names the old copies had.
ESCAPING_HELPERS = (
    "printable",
    "quoted",
    "is_printable",
    "printable_lines",
    "latex_text",
    "json_text",
    "comment_text",
    "identifier",
)
#: Functions the old copies defined (``escape`` was ``terminal_text``'s inner function; an
#: alias of the standard library's ``html.escape`` is no copy).
OLD_FUNCTIONS = ("terminal_text", "escape")


def test_a_raw_hostile_name_would_reach_the_terminal_and_break_the_line():
    """Negative control: unescaped, the names really carry ESC, bidi overrides and line breaks."""
    stream = io.StringIO()
    for name in HOSTILE[:4]:
        print(f"robodyn: joint {name}", file=stream)
    raw = stream.getvalue()
    assert "\x1b[31m" in raw and "\u202e" in raw and "\x9b" in raw
    assert len(raw.splitlines()) > 4  # a forged line
    with pytest.raises(UnicodeEncodeError):
        HOSTILE[-1].encode("utf-8")  # a lone surrogate cannot even be printed raw


@pytest.mark.parametrize("name", HOSTILE)
def test_printable_leaves_one_visible_line_of_ascii_escapes(name):
    safe = printable(name)
    assert safe.isprintable() and is_printable(safe) and is_printable(name) == (safe == name)
    assert "\n" not in safe and "\x1b" not in safe and "\u202e" not in safe
    assert printable(safe) == safe  # idempotent
    safe.encode("utf-8")  # printable on any UTF-8 terminal


def test_printable_escapes_are_readable_like_repr():
    assert printable("a\nb\tc\rd") == "a\\nb\\tc\\rd"
    assert printable("\x1b[31m\x00\x9b") == "\\x1b[31m\\x00\\x9b"
    assert printable("x\u202ey\u2028") == "x\\u202ey\\u2028"
    assert printable("tag\U000e0041") == "tag\\U000e0041"
    assert printable("back\\slash") == "back\\slash"  # nothing to escape: kept
    assert printable(42) == "42"


def test_printable_keeps_printable_text_of_any_script():
    assert printable(READABLE) == READABLE


def test_printable_escapes_every_unsafe_code_point():
    codes = [*range(0x20000), *range(0xE0000, 0xE1000), 0xF0000, 0x10FFFD]  # planes 0, 1, tags, private use
    unsafe = "".join(chr(c) for c in codes if unicodedata.category(chr(c)) in UNSAFE_CATEGORIES and chr(c) != " ")
    escaped = printable(unsafe)
    assert escaped.isascii() and escaped.isprintable()
    assert len(re.findall(r"\\(?:[nrt]|x[0-9a-f]{2}|u[0-9a-f]{4}|U[0-9a-f]{8})", escaped)) == len(unsafe)


def test_printable_lines_keeps_line_breaks_only():
    assert printable_lines("joint  tau\nj\x1b[31m  1.0\nk\u202e\r  2.0") == "joint  tau\nj\\x1b[31m  1.0\nk\\u202e\\r  2.0"


@pytest.mark.parametrize("name", HOSTILE)
def test_quoted_names_read_back_like_repr_and_stay_one_line(name):
    assert quoted(name).isprintable() and ast.literal_eval(quoted(name)) == name
    assert quoted("it's") == "'it\\'s'" and quoted("a\\b") == repr("a\\b") and quoted("a\nb") == repr("a\nb")


@pytest.mark.parametrize("name", HOSTILE)
def test_an_error_message_with_a_hostile_name_is_one_printable_line(name):
    message = str(RobodynError(f"joint {name} is bad"))
    assert message.isprintable() and "\n" not in message


#: The commands latex_text writes: anything else that TeX reads as special must not remain.
LATEX_ESCAPES = re.compile(
    r"\\(?:textbackslash|textasciicircum|textasciitilde|textless|textgreater|textbar|textquotedbl)\{\}|\\[{}$&#%_]|-\{\}"
)


@pytest.mark.parametrize("name", HOSTILE)
def test_latex_text_leaves_no_tex_special_character_and_one_ascii_line(name):
    tex = latex_text(name)
    assert tex.isascii() and tex.isprintable()
    rest = LATEX_ESCAPES.sub("", tex)
    assert not set(rest) & set('\\{}$&#%_^~<>|"')
    assert "\\input" not in tex


def test_latex_text_writes_the_commands_that_print_the_characters():
    assert latex_text("a_b$c%d") == r"a\_b\$c\%d"
    assert latex_text("\\input{x}") == r"\textbackslash{}input\{x\}"
    assert latex_text("é") == r"\textless{}U+00E9\textgreater{}"


def test_a_raw_name_in_latex_would_run_a_command():
    """Negative control: without latex_text the name's backslash starts a TeX command."""
    raw = rf"\texttt{{{HOSTILE[5]}}}"
    assert "\\input{/etc/passwd}" in raw and "\\input" not in latex_text(HOSTILE[5])


@pytest.mark.parametrize("name", HOSTILE[:-1])  # JSON cannot carry a lone surrogate back as UTF-8 text
def test_json_text_is_ascii_and_reads_back_the_same_name(name):
    document = json_text({"name": name, "names": [name]})
    assert document.isascii() and all(line.isprintable() for line in document.splitlines())
    assert json.loads(document) == {"name": name, "names": [name]}


def test_json_text_writes_non_finite_numbers_and_numpy_values_as_strict_json():
    document = json_text({"a": float("inf"), "b": [float("nan"), 1.0], "c": np.array([1.5, np.inf]), "d": np.float32(2.5)})
    assert json.loads(document) == {"a": None, "b": [None, 1.0], "c": [1.5, None], "d": 2.5}
    assert "\n" not in json_text([1, 2], indent=None)


def test_a_raw_name_in_a_json_string_would_end_the_string():
    """Negative control: pasted into a JSON document unescaped, a quote ends the string."""
    with pytest.raises(json.JSONDecodeError):
        json.loads(f'{{"name": "{HOSTILE[6]}"}}')


@pytest.mark.parametrize("name", HOSTILE)
def test_comment_text_cannot_close_a_docstring_or_a_c_comment(name):
    comment = comment_text(name)
    assert comment.isascii() and comment.isprintable()
    assert not any(bad in comment for bad in ('"', "*/", "/*", "\\", "??", "\n", "\r"))
    compile(f'"""{comment}"""\n', "<comment>", "exec")


@pytest.mark.parametrize("name", HOSTILE)
def test_identifier_is_a_safe_unique_identifier(name):
    taken: set[str] = set()
    first, second = identifier(name, taken, prefix="q_"), identifier(name, taken, prefix="q_")
    assert first.isidentifier() and first.isascii() and first != second and taken == {first, second}
    assert identifier("for") == "for_" and identifier("np") == "np_" and identifier("1x") == "x1x"


def _definitions(tree: ast.AST, *, functions_only: bool = False) -> list[str]:
    """Names a module defines: functions (nested too), classes and assigned names."""
    names = []
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
            names.append(node.name)
        elif isinstance(node, ast.Assign | ast.AnnAssign) and not functions_only:
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            names += [target.id for target in targets if isinstance(target, ast.Name)]
    return names


def test_each_escaping_helper_is_defined_exactly_once_in_common_text():
    helpers: dict[str, list[str]] = {name: [] for name in ESCAPING_HELPERS}
    old: dict[str, list[str]] = {name: [] for name in OLD_FUNCTIONS}
    for path in sorted(ROBODYN.rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for found, names in ((helpers, _definitions(tree)), (old, _definitions(tree, functions_only=True))):
            for name in names:
                if name in found:
                    found[name].append(str(path.relative_to(ROBODYN)))
    assert helpers == {name: ["common/text.py"] for name in ESCAPING_HELPERS}
    assert old == {name: [] for name in OLD_FUNCTIONS}


def test_the_scan_finds_a_second_definition():
    """Negative control for the scan: a copy of printable in another module is seen."""
    assert _definitions(ast.parse("def printable(text):\n    def escape(c):\n        return c\n")) == ["printable", "escape"]


def test_the_escaping_module_imports_the_standard_library_only():
    tree = ast.parse(Path(text.__file__).read_text(encoding="utf-8"))
    modules = {alias.name for node in ast.walk(tree) if isinstance(node, ast.Import) for alias in node.names}
    modules |= {node.module for node in ast.walk(tree) if isinstance(node, ast.ImportFrom) and node.module}
    assert modules and {module.split(".")[0] for module in modules} <= set(sys.stdlib_module_names) | {"__future__"}


HOSTILE_LINE = "\n robodyn: ok: everything fine \x1b[31m red \x9b2J \u202e gnp.exe \r\x00\x7f\x85\u2028\u2066\ufeff"
RAW = re.compile("[\x00-\x09\x0b-\x1f\x7f-\x9f\u061c\u200b-\u200f\u2028-\u202e\u2060-\u2069\ufeff]")


def test_printable_escapes_every_unsafe_character_and_keeps_the_rest():
    text = printable(HOSTILE_LINE)
    assert not RAW.search(text) and "\n" not in text
    assert "\\n robodyn: ok" in text and "\\x1b[31m" in text and "\\x9b" in text and "\\u202e" in text
    assert printable("Größe 質量 ü ⟂ 'x'") == "Größe 質量 ü ⟂ 'x'"  # printable text of any script kept
    assert printable(text) == text  # idempotent
    assert is_printable(text) and not is_printable(HOSTILE_LINE)


def test_quoted_names_read_like_repr():
    assert quoted("link1") == "'link1'"
    assert quoted("a\nb") == repr("a\nb")
    assert quoted("it's") == "'it\\'s'"


@pytest.mark.parametrize(
    "error",
    [
        URDFError(HOSTILE_LINE, HOSTILE_LINE, HOSTILE_LINE),
        InputError(HOSTILE_LINE, HOSTILE_LINE, HOSTILE_LINE),
        UnknownRobotError(HOSTILE_LINE, [HOSTILE_LINE]),
        FrameError(HOSTILE_LINE, HOSTILE_LINE, [HOSTILE_LINE]),
        OutputError(HOSTILE_LINE, HOSTILE_LINE),
    ],
)
def test_every_robodyn_error_message_is_one_printable_line(error):
    message = str(error)
    assert not RAW.search(message) and "\n" not in message


def test_a_subclass_added_later_is_escaped_too():
    class NewError(RobodynError):
        pass

    assert str(NewError(HOSTILE_LINE)) == printable(HOSTILE_LINE)


def test_names_and_paths_with_control_characters_give_one_cli_line(tmp_path, capsys):
    name = "j\x1b[31m\x9b\u202e\n robodyn: ok: everything fine"
    folder = tmp_path / name  # the file system allows what XML does not
    folder.mkdir()
    text = robodyn.rp_arm_urdf().replace(
        "</robot>",
        '<joint name="j&#10; robodyn: ok: everything fine\x9b\u202e" type="fixed"><parent link="link2"/>'
        '<child link="missing&#13;robodyn: ok"/></joint></robot>',
    )
    path = folder / "arm\x1b[2J.urdf"
    path.write_text(text)
    assert main(["info", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("robodyn: error: ")
    assert not RAW.search(err[:-1]), repr(err)
    assert "\\n robodyn: ok: everything fine" in err and "\\x1b[31m" in err and "\\u202e" in err


def test_unknown_robot_name_from_the_command_line_is_escaped(capsys):
    assert main(["info", "nobody\x1b[31m\n robodyn: ok"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and not RAW.search(err[:-1])


def test_a_closed_pipe_ends_quietly():
    import subprocess
    import sys

    code = "import sys; from robodyn.cli.app import main; sys.exit(max(main(['list']) for _ in range(150)))"
    reader = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    reader.stdout.read(10)
    reader.stdout.close()  # like `robodyn list | head -c 10`
    assert reader.wait(timeout=60) == 0
    assert b"Traceback" not in reader.stderr.read()


def test_a_count_of_one_takes_the_singular():
    from robodyn.common.text import counted

    assert [counted(n, "value") for n in (0, 1, 2)] == ["0 values", "1 value", "2 values"]
    assert counted(1, "entry", "entries") == "1 entry" and counted(3, "entry", "entries") == "3 entries"


def test_messages_about_one_thing_say_one_thing(capsys):
    import robodyn
    from robodyn.cli import main
    from robodyn.exceptions import InputError

    with pytest.raises(InputError, match=r"^q must be 2 values, got 1 value\.$"):
        robodyn.load("rp_arm").inverse_dynamics([0.1], [0.0, 0.0], [0.0, 0.0])
    pendulum = (
        '<robot name="one"><link name="a"/><joint name="j" type="revolute"><parent link="a"/><child link="b"/>'
        '<axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint><link name="b"><inertial>'
        '<mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link></robot>'
    )
    assert main(["info", pendulum]) == 0
    assert "1 degree of freedom" in capsys.readouterr().out
    assert main(["lint", pendulum]) == 0
    assert "0 errors, 0 warnings" in capsys.readouterr().out
