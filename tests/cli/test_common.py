"""Terminal hygiene of the command line: progress only on a terminal, an error alone on
stderr (issue 29, item 9)."""

from __future__ import annotations

import io

import pytest

import robodyn.cli.common as cli_common
from robodyn.cli import main


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


@pytest.fixture
def no_delay(monkeypatch):
    monkeypatch.setattr(cli_common.Progress, "DELAY", 0.0)


def test_progress_draws_only_on_a_terminal(no_delay, monkeypatch):
    for stream, shown in ((_Terminal(), True), (io.StringIO(), False)):
        monkeypatch.setattr("sys.stderr", stream)
        progress = cli_common.Progress("deriving")
        progress("mass matrix", 3, 10)
        progress("mass matrix", 10, 10)
        progress.close()
        written = stream.getvalue()
        if shown:
            assert written.count("\r") == 2 and written.endswith("10/10\n")
        else:
            assert written == ""


def test_a_failed_write_prints_its_error_alone_on_a_captured_stderr(no_delay, capsys):
    # stderr captured (not a terminal), output to a full disk: one line, no carriage returns
    assert main(["equations", "rp_arm", "--symbolic", "--format", "python", "--out", "/dev/full"]) == 2
    err = capsys.readouterr().err
    assert "\r" not in err and err.count("\n") == 1 and err.startswith("robodyn: error:")
