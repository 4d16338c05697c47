"""Safe file output: every file the library writes is replaced atomically.

A crash, a full disk or a permission error never leaves a half-written file:
data goes to a temporary file in the target's directory, is flushed to disk,
and only then renamed over the target with :func:`os.replace`.
"""

from __future__ import annotations

import contextlib
import errno
import os
import secrets
from pathlib import Path

from .errors import LsysError

__all__ = ["write_atomic"]


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
    target = Path(path)
    payload = data.encode("utf-8") if isinstance(data, str) else bytes(data)
    directory = target.parent if str(target.parent) else Path(".")
    tmp_name: str | None = None
    try:
        fd, tmp_name = _create_temp(directory, target.name)
        with os.fdopen(fd, "wb") as fh:
            fh.write(payload)
            fh.flush()
            os.fsync(fh.fileno())
        _copy_mode(target, tmp_name)
        os.replace(tmp_name, target)
        tmp_name = None
        _fsync_dir(directory)
    except OSError as exc:
        reason = exc.strerror or str(exc) or type(exc).__name__
        raise LsysError(f"cannot write {target}: {reason}") from exc
    finally:
        if tmp_name is not None:
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
