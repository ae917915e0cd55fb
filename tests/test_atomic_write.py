"""Atomic writes: an interrupted write leaves the previous file intact and nothing behind.

The write is made to fail at each stage (mid-write, at the flush to disk, at the rename,
by Ctrl-C), through :func:`robodyn.common.files.atomic_write_bytes` and through what
users call (``Trajectory.save``). A direct write (open the target, write) fails these
tests: the target would be truncated or half-written.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from robodyn.common.files import atomic_write_bytes, atomic_write_text
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
