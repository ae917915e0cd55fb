"""Atomic writes: an interrupted write leaves the previous file intact and nothing behind.

The write is made to fail at each stage (mid-write, at the flush to disk, at the rename,
by Ctrl-C), through :func:`robodyn.common.files.atomic_write_bytes` and through what
users call (``Trajectory.save``). A direct write (open the target, write) fails these
tests: the target would be truncated or half-written.

Also here:

- Family 4 of issue #14: outputs that never destroy (robodyn.common.files).
"""

from __future__ import annotations

import errno
import os
import stat
from pathlib import Path

import numpy as np
import pytest

from robodyn.common import files
from robodyn.common.files import OutputSet, atomic_write_bytes, atomic_write_text, temporary_prefix
from robodyn.exceptions import OutputError
from robodyn.trajectory import Trajectory

OLD = b"the previous content\n" * 100
NEW = b"new content that must never be seen half-written\n" * 1000


def _leftovers(folder: Path, name: str) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name != name)


@pytest.fixture
def target(tmp_path: Path) -> Path:
    path = tmp_path / "out.bin"
    path.write_bytes(OLD)
    path.chmod(0o640)
    return path


def _half_writer(monkeypatch, failure: BaseException) -> None:
    """Make ``os.write`` write half of what it is given, then fail (a full disk, Ctrl-C)."""
    real_write = os.write

    def write(descriptor, data):
        real_write(descriptor, bytes(data[: len(data) // 2]))
        raise failure

    monkeypatch.setattr(os, "write", write)


@pytest.mark.parametrize("failure", [OSError(28, "No space left on device"), KeyboardInterrupt()], ids=["full-disk", "ctrl-c"])
def test_failure_mid_write_keeps_the_previous_file(target, monkeypatch, failure):
    _half_writer(monkeypatch, failure)
    with pytest.raises(type(failure)):
        atomic_write_bytes(target, NEW)
    monkeypatch.undo()
    assert target.read_bytes() == OLD
    assert _leftovers(target.parent, target.name) == []


@pytest.mark.parametrize("stage", ["fsync", "replace", "fchmod"])
def test_failure_at_each_later_stage_keeps_the_previous_file(target, monkeypatch, stage):
    def fail(*args, **kwargs):
        raise OSError(5, f"{stage} failed")

    monkeypatch.setattr(os, stage, fail)
    with pytest.raises(OSError, match=stage):
        atomic_write_bytes(target, NEW)
    monkeypatch.undo()
    assert target.read_bytes() == OLD
    assert _leftovers(target.parent, target.name) == []


def test_the_target_is_never_opened_for_writing(target, monkeypatch):
    """The new content goes to another file that is renamed over the target in one step."""
    opened = []
    real_open = os.open

    def spy(path, flags, *args, **kwargs):
        if flags & (os.O_WRONLY | os.O_RDWR):
            opened.append(Path(path).name)
        return real_open(path, flags, *args, **kwargs)

    replaced = []
    real_replace = os.replace
    monkeypatch.setattr(os, "open", spy)
    monkeypatch.setattr(os, "replace", lambda src, dst: (replaced.append((Path(src).name, Path(dst))), real_replace(src, dst)))
    before = target.stat().st_ino
    atomic_write_bytes(target, NEW)
    assert target.read_bytes() == NEW
    assert target.name not in opened and opened  # a temporary file was written instead
    assert replaced == [(opened[0], target)]
    assert target.stat().st_ino != before  # a new file took the old one's place
    assert _leftovers(target.parent, target.name) == []


def test_success_keeps_permissions_and_never_creates_folders(target, tmp_path):
    atomic_write_bytes(target, NEW)
    assert target.read_bytes() == NEW and (target.stat().st_mode & 0o777) == 0o640
    fresh = tmp_path / "c.txt"
    assert atomic_write_text(fresh, "héllo") == fresh
    assert fresh.read_text(encoding="utf-8") == "héllo"
    mask = os.umask(0)
    os.umask(mask)
    assert (fresh.stat().st_mode & 0o777) == 0o666 & ~mask
    with pytest.raises(OutputError, match="does not exist"):
        atomic_write_text(tmp_path / "a" / "b" / "c.txt", "x")
    assert not (tmp_path / "a").exists()


@pytest.mark.parametrize("suffix", [".csv", ".npz"])
def test_trajectory_save_interrupted_keeps_the_previous_file(tmp_path, monkeypatch, suffix):
    path = tmp_path / f"run{suffix}"
    old = Trajectory(np.arange(3.0), np.zeros((3, 2)), np.zeros((3, 2)), np.zeros((3, 2)), np.zeros((3, 2)), ["a", "b"], "r")
    old.save(path)
    previous = path.read_bytes()
    new = Trajectory(np.arange(50.0), np.ones((50, 2)), np.ones((50, 2)), np.ones((50, 2)), np.ones((50, 2)), ["a", "b"], "r")
    _half_writer(monkeypatch, OSError(28, "full"))
    with pytest.raises(OSError):
        new.save(path)
    monkeypatch.undo()
    assert path.read_bytes() == previous
    assert _leftovers(tmp_path, path.name) == []
    np.testing.assert_array_equal(Trajectory.load(path).t, old.t)


def test_interrupt_just_after_the_rename_propagates_and_leaves_nothing(target, monkeypatch):
    """Ctrl-C between the rename and the return: the new file is in place, the interrupt
    (not a FileNotFoundError from cleaning up the renamed temporary file) reaches the caller."""
    real_replace = os.replace

    def replace_then_interrupt(src, dst):
        real_replace(src, dst)
        raise KeyboardInterrupt

    monkeypatch.setattr(os, "replace", replace_then_interrupt)
    with pytest.raises(KeyboardInterrupt):
        atomic_write_bytes(target, NEW)
    monkeypatch.undo()
    assert target.read_bytes() == NEW
    assert _leftovers(target.parent, target.name) == []


def _temporaries(folder: Path) -> list[str]:
    return sorted(name for name in os.listdir(folder) if ".robodyn-tmp-" in name)


def test_new_and_existing_regular_files_are_replaced(tmp_path):
    path = tmp_path / "a.csv"
    atomic_write_text(path, "one")
    path.chmod(0o640)
    atomic_write_text(path, "two")
    assert path.read_text() == "two"
    assert stat.S_IMODE(path.stat().st_mode) == 0o640  # the user's mode is kept
    assert _temporaries(tmp_path) == []


def test_dash_is_standard_output(capfd, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert atomic_write_text("-", "to stdout\n") is None
    assert capfd.readouterr().out == "to stdout\n"
    assert not (tmp_path / "-").exists()


def test_a_symlink_is_kept_and_its_target_replaced(tmp_path):
    target = tmp_path / "real.csv"
    target.write_text("old")
    link = tmp_path / "link.csv"
    link.symlink_to(target)
    atomic_write_text(link, "new")
    assert link.is_symlink() and os.readlink(link) == str(target)
    assert target.read_text() == "new"


@pytest.mark.parametrize("special", ["/dev/full", "/dev/null", "/dev/stdout"])
def test_special_files_are_refused_and_left_alone(special, tmp_path):
    if not os.path.exists(special):
        pytest.skip(f"no {special}")
    kind = os.lstat(special).st_mode
    with pytest.raises(OutputError, match="not a regular file"):
        atomic_write_text(special, "x")
    assert os.lstat(special).st_mode == kind  # neither the device nor the symlink was replaced


def test_a_symlink_to_a_device_is_refused(tmp_path):
    link = tmp_path / "out.csv"
    link.symlink_to("/dev/null")
    with pytest.raises(OutputError, match="not a regular file"):
        atomic_write_text(link, "x")
    assert link.is_symlink()
    assert _temporaries(tmp_path) == []


def test_a_fifo_is_refused_without_blocking(tmp_path):
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    with pytest.raises(OutputError, match="not a regular file"):
        atomic_write_text(fifo, "x")
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)


def test_a_directory_is_refused(tmp_path):
    with pytest.raises(OutputError, match="is a directory") as raised:
        atomic_write_text(tmp_path, "x")
    assert "\n" not in str(raised.value)


def test_a_missing_folder_is_never_created(tmp_path):
    with pytest.raises(OutputError, match="does not exist"):
        atomic_write_text(tmp_path / "missing" / "deeper" / "a.csv", "x")
    assert not (tmp_path / "missing").exists()


def test_a_read_only_folder_gives_one_line_and_keeps_the_file(tmp_path):
    path = tmp_path / "ro" / "a.csv"
    path.parent.mkdir()
    path.write_text("precious")
    path.parent.chmod(0o500)
    try:
        if os.access(path.parent, os.W_OK):  # root ignores permissions: make creation fail another way
            pytest.skip("running as root: permissions are not enforced")
        with pytest.raises(OutputError, match="permission denied"):
            atomic_write_text(path, "new")
    finally:
        path.parent.chmod(0o700)
    assert path.read_text() == "precious"


@pytest.mark.parametrize(
    ("code", "reason"), [(errno.EROFS, "read-only"), (errno.EPERM, "immutable"), (errno.EACCES, "permission denied")]
)
def test_folders_that_refuse_new_files_give_one_line(code, reason, tmp_path, monkeypatch):
    path = tmp_path / "a.csv"
    path.write_text("precious")
    real_open = os.open

    def refusing(name, flags, mode=0o777, **kwargs):
        if ".robodyn-tmp-" in str(name):
            raise OSError(code, os.strerror(code))
        return real_open(name, flags, mode, **kwargs)

    monkeypatch.setattr(files.os, "open", refusing)
    with pytest.raises(OutputError, match=reason) as raised:
        atomic_write_text(path, "new")
    assert "\n" not in str(raised.value)
    monkeypatch.undo()
    assert path.read_text() == "precious" and _temporaries(tmp_path) == []


def test_a_full_disk_keeps_the_previous_file(tmp_path, monkeypatch):
    path = tmp_path / "a.csv"
    path.write_text("precious")

    def full(descriptor, data):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(files.os, "write", full)
    with pytest.raises(OutputError, match="no space left") as raised:
        atomic_write_text(path, "new content")
    assert "\n" not in str(raised.value)
    monkeypatch.undo()
    assert path.read_text() == "precious"
    assert _temporaries(tmp_path) == []


def test_outputs_are_committed_together_or_not_at_all(tmp_path):
    first, second = tmp_path / "m.csv", tmp_path / "m.html"
    first.write_text("old csv")
    with pytest.raises(OutputError), OutputSet() as out:
        out.write_text(first, "new csv")
        out.write_text(tmp_path / "no_such_folder" / "m.html", "page")
    assert first.read_text() == "old csv"  # not replaced: the second output failed
    with pytest.raises(ZeroDivisionError), OutputSet() as out:
        out.write_text(first, "new csv")
        _ = 1 / 0  # any failure after staging, before the commit
    assert first.read_text() == "old csv"
    with OutputSet() as out:
        out.write_text(first, "new csv")
        out.write_bytes(second, b"page")
        assert first.read_text() == "old csv"  # nothing visible before the commit
    assert first.read_text() == "new csv" and second.read_bytes() == b"page"
    assert _temporaries(tmp_path) == []


def test_temporary_files_of_killed_runs_are_recognisable_and_cleaned(tmp_path):
    target = tmp_path / "f.csv"
    dead = 2**22 + 12345  # above Linux's default pid_max (4194304 is the hard maximum)
    while True:
        try:
            os.kill(dead, 0)
        except ProcessLookupError:
            break
        dead += 1
    stale = tmp_path / f"{temporary_prefix(target)}{dead}-abcd"
    stale.write_text("half")
    alive = tmp_path / f"{temporary_prefix(target)}{os.getppid()}-abcd"  # a running process's
    alive.write_text("in progress")
    atomic_write_bytes(target, b"done")
    assert not stale.exists() and alive.exists()
    assert target.read_bytes() == b"done"


def test_a_long_name_gets_a_temporary_name_that_fits(tmp_path):
    path = tmp_path / ("n" * 250)
    atomic_write_text(path, "x")
    assert path.read_text() == "x"


def test_outputs_together_makes_every_write_of_a_block_one_transaction(tmp_path):
    from robodyn.common.files import outputs_together

    csv, html = tmp_path / "m.csv", tmp_path / "m.html"
    csv.write_text("the user's old trajectory")
    with pytest.raises(RuntimeError), outputs_together():
        atomic_write_text(csv, "new trajectory")  # e.g. Trajectory.save
        raise RuntimeError("the recording is refused: no visual geometry")
    assert csv.read_text() == "the user's old trajectory" and not html.exists()
    with outputs_together():
        atomic_write_text(csv, "new trajectory")
        atomic_write_text(html, "page")
        assert csv.read_text() == "the user's old trajectory"
    assert csv.read_text() == "new trajectory" and html.read_text() == "page"
    assert _temporaries(tmp_path) == []


def test_dash_writes_a_command_output_to_stdout(tmp_path, capfd, monkeypatch):
    from robodyn.cli.app import main

    monkeypatch.chdir(tmp_path)
    assert main(["equations", "rp_arm", "--out", "-"]) == 0
    assert not (tmp_path / "-").exists()
    assert capfd.readouterr().out.strip()
