"""Issue 39, the compiled cache's own behaviour that compiling robots does not cross (mutmut's
survivors in ``robodyn/compiled/cache.py``): the folder's defaults (``$ROBODYN_CACHE``, else
``$XDG_CACHE_HOME/robodyn``, else ``~/.cache/robodyn``; an empty variable is unset; ``~``
expanded), the C source stored and read back byte for byte, a cache that cannot be written
skipped, the generator's files (``.py``, ``.c``, ``.h``; not ``__pycache__`` nor the layers
above the generator) and a change to a header changing the key, and the digest of text
parts (SHA-256 of each part and a separator, so parts never run together)."""

from __future__ import annotations

import hashlib
from pathlib import Path

import pytest

from robodyn.compiled import cache


@pytest.fixture
def clean_environment(monkeypatch, tmp_path):
    for name in ("ROBODYN_CACHE", "XDG_CACHE_HOME"):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    return monkeypatch


def test_the_folder_is_robodyn_cache_else_xdg_else_home(clean_environment, tmp_path):
    monkeypatch = clean_environment
    assert cache.cache_dir() == tmp_path / "home" / ".cache" / "robodyn" / "compiled"
    monkeypatch.setenv("XDG_CACHE_HOME", "")  # empty: unset
    assert cache.cache_dir() == tmp_path / "home" / ".cache" / "robodyn" / "compiled"
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert cache.cache_dir() == tmp_path / "xdg" / "robodyn" / "compiled"
    monkeypatch.setenv("ROBODYN_CACHE", "")
    assert cache.cache_dir() == tmp_path / "xdg" / "robodyn" / "compiled"
    monkeypatch.setenv("ROBODYN_CACHE", str(tmp_path / "mine"))
    assert cache.cache_dir() == tmp_path / "mine" / "compiled"
    monkeypatch.setenv("ROBODYN_CACHE", "~/cached")
    assert cache.cache_dir() == tmp_path / "home" / "cached" / "compiled"


def test_kernels_stored_are_read_back_byte_for_byte_and_a_missing_key_is_none(clean_environment, tmp_path):
    clean_environment.setenv("ROBODYN_CACHE", str(tmp_path / "c"))
    source = "/* ä kernel: 'quotes' and \\ */\nint f(void) { return 1; }\n"
    assert cache.cached_kernels("k1") is None
    with cache.locked("k1"):  # as the builders store: holding the key's lock (which makes the folder)
        cache.store_kernels("k1", source)
    assert (tmp_path / "c" / "compiled" / "src-k1.c").read_bytes() == source.encode("utf-8")
    assert cache.cached_kernels("k1") == source
    assert cache.cached_kernels("k2") is None  # another key is another file
    cache.store_kernels("k1", "replaced")
    assert cache.cached_kernels("k1") == "replaced"


def test_a_cache_that_cannot_be_written_is_skipped(clean_environment, tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    clean_environment.setenv("ROBODYN_CACHE", str(blocker))  # cache_dir() under a file: every write fails
    cache.store_kernels("k", "int x;")  # no error
    assert cache.cached_kernels("k") is None


def test_the_digest_is_sha256_of_each_part_and_a_separator():
    expected = hashlib.sha256("ä".encode() + b"\0" + b"b" + b"\0").hexdigest()[:24]
    assert cache.digest("ä", "b") == expected
    assert cache.digest("ab", "c") != cache.digest("a", "bc")
    assert len(cache.digest()) == 24


def _tree(root: Path) -> None:
    for name in ("a.py", "b.c", "c.h", "notes.txt", "sub/z.h", "__pycache__/x.py", "sim/y.py", "cli/w.h"):
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(f"// {name}\n")


def test_the_generator_files_are_its_sources_and_a_header_changes_the_key(monkeypatch, tmp_path):
    _tree(tmp_path)
    monkeypatch.setattr(cache, "_ROOT", tmp_path)
    files = [path.relative_to(tmp_path).as_posix() for path in cache.generator_files()]
    assert files == ["a.py", "b.c", "c.h", "sub/z.h"]
    before = cache.generator_hash.__wrapped__()
    (tmp_path / "sim" / "y.py").write_text("changed above the generator")
    (tmp_path / "__pycache__" / "x.py").write_text("changed in a cache folder")
    (tmp_path / "notes.txt").write_text("changed, not a source")
    assert cache.generator_hash.__wrapped__() == before
    (tmp_path / "sub" / "z.h").write_text("#define CHANGED 1\n")
    changed = cache.generator_hash.__wrapped__()
    assert changed != before
    (tmp_path / "sub" / "z.h").rename(tmp_path / "sub" / "y.h")  # the same bytes under another name
    assert cache.generator_hash.__wrapped__() not in (before, changed)


def test_a_robots_key_includes_the_generators_hash(monkeypatch):
    import robodyn

    robot = robodyn.load("rp_arm")
    monkeypatch.setattr(cache, "_KEYS", {})
    first = cache.robot_key(robot)
    assert cache.robot_key(robot) == first  # memoised, the same
    monkeypatch.setattr(cache, "_KEYS", {})
    monkeypatch.setattr(cache, "generator_hash", lambda: "another generator")
    assert cache.robot_key(robot) != first
