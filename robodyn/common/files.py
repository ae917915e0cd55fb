"""Output files that never destroy: all of a command's outputs are committed together.

Rules (each refusal is one :class:`~robodyn.exceptions.OutputError`, and whatever was at
the path before is left exactly as it was):

- ``-`` means standard output.
- An existing path must be a regular file (or a symlink to one: the file it points to is
  replaced, the link kept). A directory, a device (``/dev/full``), a FIFO, a socket or a
  link to one of them (``/dev/stdout``) is refused — use ``-`` for standard output.
- A new path's folder must exist; robodyn never creates folders.
- The content goes to a temporary file in the target's folder, named
  ``.<name>.robodyn-tmp-<pid>-<random>`` (recognisable; one left by a killed run is
  deleted by the next write to the same name once its process is gone), is flushed to
  disk and then renamed over the target. A full disk (ENOSPC), a read-only or immutable
  folder: an error, the temporary file removed.
- :class:`OutputSet` stages several outputs and renames them all only after every one of
  them was produced; an error before the commit (in robodyn or in any of the writes)
  discards them all. :func:`outputs_together` makes every write of a block one such
  transaction (the CLI runs each command in one).
"""

from __future__ import annotations

import contextlib
import contextvars
import errno
import os
import secrets
import stat
import sys
from collections.abc import Iterator
from pathlib import Path
from types import TracebackType

from robodyn.exceptions import OutputError

_TEMPORARY_TAG = ".robodyn-tmp-"
#: Longest target-name part of a temporary file's name (file names have at most 255 bytes).
_NAME_PART = 120


class OutputSet:
    """Outputs staged as temporary files and committed together (a transaction).

    Example::

        with OutputSet() as out:
            out.write_text("m.csv", csv_text)
            out.write_bytes("m.png", png_bytes)
        # both files replaced here, or neither (an exception inside the block)

    Methods raise :class:`~robodyn.exceptions.OutputError` at once for a path that is
    refused or cannot be written.
    """

    def __init__(self) -> None:
        self._staged: list[tuple[str, Path, Path]] = []  # (as given, temporary, target)
        self._stdout: list[bytes] = []
        self._done = False

    def __enter__(self) -> OutputSet:
        return self

    def __exit__(self, kind: type[BaseException] | None, error: BaseException | None, trace: TracebackType | None) -> None:
        if kind is None:
            self.commit()
        else:
            self.discard()

    def write_text(self, path: str | os.PathLike, text: str) -> Path | None:
        """Stage UTF-8 text for ``path`` (see :meth:`write_bytes`).

        Args:
            path: The file to write, or ``"-"`` for standard output.
            text: The file's contents.
        """
        return self.write_bytes(path, text.encode("utf-8"))

    def write_bytes(self, path: str | os.PathLike, data: bytes) -> Path | None:
        """Stage ``data`` for ``path``: checked and written to a temporary file now, renamed
        at :meth:`commit`.

        Args:
            path: The file to write, or ``"-"`` for standard output.
            data: The file's contents.

        Returns:
            The file that will be replaced, or ``None`` for standard output (``-``).
        """
        if self._done:
            raise RuntimeError("this OutputSet was already committed or discarded")
        if str(path) == "-":
            self._stdout.append(bytes(data))
            return None
        target = output_target(path)
        try:
            temporary = _write_temporary(target, data, str(path))
        except BaseException:
            self.discard()
            raise
        self._staged.append((str(path), temporary, target))
        return target

    def commit(self) -> None:
        """Rename every staged file over its target and write what goes to standard output."""
        if self._done:
            return
        self._done = True
        try:
            for given, temporary, target in self._staged:
                try:
                    os.replace(temporary, target)
                except OSError as error:
                    raise OutputError(given, _reason(error)) from None
        finally:
            for _, temporary, _ in self._staged:
                _remove(temporary)
        for data in self._stdout:
            sys.stdout.flush()
            stream = getattr(sys.stdout, "buffer", None)
            if stream is None:
                sys.stdout.write(data.decode("utf-8", "replace"))
            else:
                stream.write(data)
            sys.stdout.flush()

    def discard(self) -> None:
        """Drop every staged output (targets untouched)."""
        self._done = True
        for _, temporary, _ in self._staged:
            _remove(temporary)
        self._staged.clear()
        self._stdout.clear()


def output_target(path: str | os.PathLike) -> Path:
    """The file an output path will replace, after the checks of the module docstring.

    Args:
        path: The output path as given.

    Raises:
        OutputError: If the path is refused (special file, directory, missing folder).
    """
    given = str(path)
    if not given or "\x00" in given:
        raise OutputError(given, "not a valid file name")
    target = _resolve(given)  # through symlinks: replace what they point to
    try:
        status = os.stat(target)
    except FileNotFoundError:
        status = None
    except OSError as error:
        raise OutputError(given, _reason(error)) from None
    if status is not None:
        if stat.S_ISDIR(status.st_mode):
            raise OutputError(given, "it is a directory")
        if not stat.S_ISREG(status.st_mode):
            raise OutputError(given, "it is not a regular file (use - for standard output)")
        return target
    folder = target.parent
    if not folder.is_dir():
        raise OutputError(given, f"its folder {str(Path(given).parent)!r} does not exist (robodyn does not create folders)")
    return target


#: Folders of special files (devices, /proc/self/fd/N magic links): never written to, even
#: when a link there resolves to a regular file (``/dev/stdout`` redirected to a file).
_SYSTEM = ("/dev", "/proc", "/sys")


def _resolve(given: str) -> Path:
    """The real file behind ``given``, refusing a path or link hop into :data:`_SYSTEM`."""
    path = os.path.abspath(given)
    for _ in range(40):
        if _is_system(path) or _is_system(os.path.realpath(os.path.dirname(path))):
            raise OutputError(given, "it is not a regular file (use - for standard output)")
        if not os.path.islink(path):
            break
        path = os.path.normpath(os.path.join(os.path.dirname(path), os.readlink(path)))
    else:
        raise OutputError(given, "too many levels of symbolic links")
    real = os.path.realpath(path)
    if _is_system(real):
        raise OutputError(given, "it is not a regular file (use - for standard output)")
    return Path(real)


def _is_system(path: str) -> bool:
    return any(path == folder or path.startswith(folder + "/") for folder in _SYSTEM)


#: The transaction :func:`outputs_together` opened, if any.
_AMBIENT: contextvars.ContextVar[OutputSet | None] = contextvars.ContextVar("robodyn_outputs", default=None)


@contextlib.contextmanager
def outputs_together() -> Iterator[OutputSet]:
    """Make every :func:`atomic_write_bytes` / :func:`atomic_write_text` inside the block
    part of one :class:`OutputSet`: committed when the block ends normally, discarded
    when it raises. The CLI runs each command inside one, so that a command's outputs
    are all written or none is (``simulate --out m.csv --record m.html``).
    """
    outputs = OutputSet()
    token = _AMBIENT.set(outputs)
    try:
        with outputs:
            yield outputs
    finally:
        _AMBIENT.reset(token)


def atomic_write_bytes(path: str | os.PathLike, data: bytes) -> Path | None:
    """Write ``data`` to ``path`` atomically: a one-output :class:`OutputSet`, or staged in
    the enclosing :func:`outputs_together` block (then written when that block ends).

    Args:
        path: The file to write, or ``"-"`` for standard output.
        data: The file's contents.

    Returns:
        The file written (or to be written), or ``None`` for standard output (``-``).

    Raises:
        OutputError: If the path is refused or cannot be written; the old file is intact.
    """
    ambient = _AMBIENT.get()
    if ambient is not None:
        return ambient.write_bytes(path, data)
    with OutputSet() as outputs:
        target = outputs.write_bytes(path, data)
    return target


def atomic_write_text(path: str | os.PathLike, text: str) -> Path | None:
    """Write UTF-8 text atomically (see :func:`atomic_write_bytes`).

    Args:
        path: The file to write, or ``"-"`` for standard output.
        text: The file's contents.
    """
    return atomic_write_bytes(path, text.encode("utf-8"))


def temporary_prefix(target: Path) -> str:
    """Start of the names of the temporary files for ``target`` (in its folder).

    Args:
        target: The file to be replaced.
    """
    return f".{target.name[:_NAME_PART]}{_TEMPORARY_TAG}"


def _write_temporary(target: Path, data: bytes, given: str) -> Path:
    folder = target.parent
    _clean_stale(folder, temporary_prefix(target))
    temporary = folder / f"{temporary_prefix(target)}{os.getpid()}-{secrets.token_hex(4)}"
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_CLOEXEC", 0) | getattr(os, "O_NOFOLLOW", 0)
    try:
        descriptor = os.open(temporary, flags, 0o600)
    except OSError as error:
        raise OutputError(given, _reason(error)) from None
    try:
        try:
            existing = os.stat(target).st_mode & 0o777  # never copy setuid/setgid bits
        except FileNotFoundError:
            existing = 0o666 & ~_umask()
        os.fchmod(descriptor, existing)
        view = memoryview(data)
        while view:
            written = os.write(descriptor, view)
            view = view[written:]
        os.fsync(descriptor)
    except OSError as error:
        os.close(descriptor)
        _remove(temporary)
        raise OutputError(given, _reason(error)) from None
    except BaseException:
        os.close(descriptor)
        _remove(temporary)
        raise
    os.close(descriptor)
    return temporary


def _clean_stale(folder: Path, prefix: str) -> None:
    """Delete temporary files of ``prefix`` left by robodyn processes that no longer run."""
    with contextlib.suppress(OSError):
        for entry in os.scandir(folder):
            if not entry.name.startswith(prefix):
                continue
            owner = entry.name[len(prefix) :].split("-", 1)[0]
            if owner.isdigit() and not _alive(int(owner)) and entry.is_file(follow_symlinks=False):
                _remove(Path(entry.path))


def _alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # exists, owned by someone else
        return True
    return True


def _remove(path: Path) -> None:
    with contextlib.suppress(OSError):
        path.unlink()


def _reason(error: OSError) -> str:
    reasons = {
        errno.ENOSPC: "no space left on the device",
        errno.EACCES: "permission denied",
        errno.EPERM: "the operation is not permitted (an immutable file or folder?)",
        errno.EROFS: "the file system is read-only",
        errno.ENAMETOOLONG: "the file name is too long",
        errno.EISDIR: "it is a directory",
        errno.ENOTDIR: "a folder on the path is not a folder",
        errno.EDQUOT: "the disk quota is exceeded",
    }
    fallback = error.strerror or str(error)
    return reasons.get(error.errno, fallback) if error.errno is not None else fallback


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


__all__ = ["OutputSet", "atomic_write_bytes", "atomic_write_text", "output_target", "outputs_together", "temporary_prefix"]
