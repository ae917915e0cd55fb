"""Family 1 of issue #14 (terminal part): one escaping function for every message."""

from __future__ import annotations

import re

import pytest

import robodyn
from robodyn.cli.app import main
from robodyn.common.text import is_printable, printable, quoted
from robodyn.exceptions import FrameError, InputError, OutputError, RobodynError, UnknownRobotError, URDFError

HOSTILE = "\n robodyn: ok: everything fine \x1b[31m red \x9b2J \u202e gnp.exe \r\x00\x7f\x85\u2028\u2066\ufeff"
RAW = re.compile("[\x00-\x09\x0b-\x1f\x7f-\x9f\u061c\u200b-\u200f\u2028-\u202e\u2060-\u2069\ufeff]")


def test_printable_escapes_every_unsafe_character_and_keeps_the_rest():
    text = printable(HOSTILE)
    assert not RAW.search(text) and "\n" not in text
    assert "\\n robodyn: ok" in text and "\\x1b[31m" in text and "\\x9b" in text and "\\u202e" in text
    assert printable("Größe 質量 ü ⟂ 'x'") == "Größe 質量 ü ⟂ 'x'"  # printable text of any script kept
    assert printable(text) == text  # idempotent
    assert is_printable(text) and not is_printable(HOSTILE)


def test_quoted_names_read_like_repr():
    assert quoted("link1") == "'link1'"
    assert quoted("a\nb") == repr("a\nb")
    assert quoted("it's") == "'it\\'s'"


@pytest.mark.parametrize(
    "error",
    [
        URDFError(HOSTILE, HOSTILE, HOSTILE),
        InputError(HOSTILE, HOSTILE, HOSTILE),
        UnknownRobotError(HOSTILE, [HOSTILE]),
        FrameError(HOSTILE, HOSTILE, [HOSTILE]),
        OutputError(HOSTILE, HOSTILE),
    ],
)
def test_every_robodyn_error_message_is_one_printable_line(error):
    message = str(error)
    assert not RAW.search(message) and "\n" not in message


def test_a_subclass_added_later_is_escaped_too():
    class NewError(RobodynError):
        pass

    assert str(NewError(HOSTILE)) == printable(HOSTILE)


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


def test_printable_lines_keeps_line_breaks_only():
    from robodyn.common.text import printable_lines

    table = "joint  tau\nj\x1b[31m  1.0\nk\u202e\r  2.0"
    assert printable_lines(table) == "joint  tau\nj\\x1b[31m  1.0\nk\\u202e\\r  2.0"
