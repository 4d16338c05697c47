"""Safe file output: every file the library writes is replaced atomically.

A crash, a full disk or a permission error never leaves a half-written file:
data goes to a temporary file in the target's directory, is flushed to disk,
and only then renamed over the target with :func:`os.replace`.
:func:`write_files_atomic` does this for several files at once, renaming only
when every one of them is safely on disk.
"""

from __future__ import annotations

import contextlib
import errno
import os
import secrets
from collections.abc import Iterable
from pathlib import Path

from lsys_core.errors import LsysError

__all__ = ["write_atomic", "write_files_atomic"]


def write_atomic(path: str | os.PathLike, data: str | bytes) -> None:
    """Write ``data`` to ``path`` atomically.

    The data is written to a temporary file in the same directory, flushed with
    ``fsync`` and moved over ``path`` with :func:`os.replace`.  On any failure the
    temporary file is removed and an existing file at ``path`` is left byte for
    byte as it was.

    Parameters
    ----------
    path : str or os.PathLike
        The file to create or replace.
    data : str or bytes
        The content; a ``str`` is encoded as UTF-8 (newlines written as given).

    Raises
    ------
    LsysError
        ``cannot write PATH: reason`` when the file cannot be written.
    """
    write_files_atomic([(path, data)])


def write_files_atomic(files: Iterable[tuple[str | os.PathLike, str | bytes]]) -> None:
    """Write several files as one step: all of them, or none.

    Every payload is first written and flushed to a temporary file beside its
    target; only when all of them are on disk are they renamed into place.  If any
    temporary file cannot be written, every temporary file is removed and no target
    is touched.  (A rename failing half-way, after the first succeeded, needs a
    target that turned into a directory meanwhile; targets that are directories
    are refused before anything is written.)

    Parameters
    ----------
    files : iterable of (path, data)
        Targets and contents (``str`` is encoded as UTF-8).

    Raises
    ------
    LsysError
        ``cannot write PATH: reason`` for the first target that cannot be written, or
        when one path is given twice.
    """
    items = [(Path(p), d.encode("utf-8") if isinstance(d, str) else bytes(d)) for p, d in files]
    seen: set[str] = set()
    for target, _ in items:
        key = os.path.normcase(os.path.abspath(target))
        if key in seen:
            raise LsysError(f"cannot write {target}: the same file is given twice as an output")
        seen.add(key)
    temps: list[tuple[str, Path]] = []
    target = items[0][0] if items else Path(".")
    try:
        for target, payload in items:
            if target.is_dir():
                raise IsADirectoryError(errno.EISDIR, os.strerror(errno.EISDIR), str(target))
            directory = target.parent if str(target.parent) else Path(".")
            fd, tmp_name = _create_temp(directory, target.name)
            temps.append((tmp_name, target))
            with os.fdopen(fd, "wb") as fh:
                fh.write(payload)
                fh.flush()
                os.fsync(fh.fileno())
            _copy_mode(target, tmp_name)
        while temps:
            tmp_name, target = temps[0]
            os.replace(tmp_name, target)
            temps.pop(0)
            _fsync_dir(target.parent if str(target.parent) else Path("."))
    except OSError as exc:
        reason = exc.strerror or str(exc) or type(exc).__name__
        raise LsysError(f"cannot write {target}: {reason}") from exc
    finally:
        for tmp_name, _ in temps:
            with contextlib.suppress(OSError):
                os.unlink(tmp_name)


def _create_temp(directory: Path, name: str) -> tuple[int, str]:
    """Create a new temporary file next to the target; the umask applies as for any new file."""
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0)
    for _ in range(100):
        tmp = os.path.join(directory, f".{name}.{secrets.token_hex(6)}.tmp")
        try:
            return os.open(tmp, flags, 0o666), tmp
        except FileExistsError:
            continue
    raise FileExistsError(errno.EEXIST, "no free temporary file name", str(directory))


def _copy_mode(target: Path, tmp_name: str) -> None:
    """Give the temporary file the permissions of the file it replaces, if there is one."""
    try:
        mode = target.stat().st_mode & 0o7777
    except OSError:
        return
    with contextlib.suppress(OSError):
        os.chmod(tmp_name, mode)


def _fsync_dir(directory: Path) -> None:
    """Flush the directory entry of a rename to disk where the platform allows it."""
    if os.name != "posix":
        return
    with contextlib.suppress(OSError):
        fd = os.open(directory, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
