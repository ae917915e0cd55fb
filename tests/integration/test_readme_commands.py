"""The README runs as written: every ``robodyn …`` command of it, in order, exits 0.

The commands run in a fresh temporary folder (the files they need are made by the
commands before them), through the CLI's ``main`` in this process; a comment after ``#``
is not part of a command.
"""

from __future__ import annotations

import shlex

import pytest

from robodyn.cli.app import main
from tests.conftest import ROOT

README = ROOT / "README.md"


def readme_commands() -> list[list[str]]:
    """Every ``robodyn`` command of the README's code blocks and inline code, in order."""
    commands = []
    fence = None  # the language of the code block we are in, if any
    for line in README.read_text(encoding="utf-8").splitlines():
        if line.startswith("```"):
            fence = None if fence is not None else (line[3:].strip() or "text")
            continue
        command = line.split(" #", 1)[0].strip()
        if fence in ("sh", "bash", "console", "text") and command.startswith("robodyn "):
            commands.append(shlex.split(command)[1:])
    return commands


def test_the_readme_has_commands():
    commands = readme_commands()
    assert len(commands) >= 10
    assert {command[0] for command in commands} >= {"list", "info", "equations", "check", "simulate", "whatif", "record"}


@pytest.mark.slow
def test_every_readme_command_exits_0(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    for command in readme_commands():
        status = main(command)
        captured = capsys.readouterr()
        assert status == 0, f"robodyn {shlex.join(command)} exited {status}: {captured.err.strip()}"
