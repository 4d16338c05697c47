"""Writing outputs: regular files atomically, devices, FIFOs and symbolic links through, all or nothing."""

from __future__ import annotations

import contextlib
import errno
import os
import secrets
import stat
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import BinaryIO

from lsys_core.errors import LsysError
from lsys_core.io.read import CHUNK
from lsys_core.quoting import quote_name

__all__ = ["OutputClosed", "Target", "check_outputs", "write_atomic", "write_files_atomic"]

#: Where an output goes: a path, an open binary stream, or a file descriptor.
Target = str | os.PathLike | BinaryIO | int


class OutputClosed(LsysError):
    """The reader of a pipe went away while an output was written to it (``EPIPE``).

    A command line ends quietly on this, the way Unix tools do when ``head`` has read enough.
    """


# ---------------------------------------------------------------------------
# Checking outputs before work starts


def _identity(path: str | os.PathLike) -> tuple[int, int] | None:
    """Return ``(device, inode)`` of what ``path`` resolves to, or None if nothing is there."""
    try:
        st = os.stat(path)
    except (OSError, ValueError):
        return None
    return None if stat.S_ISCHR(st.st_mode) else (st.st_dev, st.st_ino)


def _key(target: Target) -> object:
    """Return what identifies an output's file (None for character devices, which may repeat)."""
    if not isinstance(target, str | os.PathLike):
        return ("stream", target if isinstance(target, int) else id(target))
    if _is_char_device(target):
        return None
    ident = _identity(target)
    return ident if ident is not None else os.path.normcase(os.path.realpath(target))


def _is_char_device(path: str | os.PathLike) -> bool:
    try:
        return stat.S_ISCHR(os.stat(path).st_mode)
    except (OSError, ValueError):
        return False


def _check_distinct(targets: Iterable[Target]) -> None:
    """Refuse one output given twice (also through a symbolic link or another path to it)."""
    seen: set[object] = set()
    for target in targets:
        key = _key(target)
        if key is None:
            continue
        if key in seen:
            name = quote_name(target) if isinstance(target, str | os.PathLike) else "standard output"
            raise LsysError(f"cannot write {name}: the same file is given twice as an output")
        seen.add(key)


def check_outputs(
    outputs: Sequence[Target | None], inputs: Sequence[str | os.PathLike | BinaryIO] = ()
) -> None:
    """Refuse, before any work, outputs that cannot be written or would destroy an input.

    An output is refused when it is a folder, when its folder is missing, when it is
    given twice (also through another name of the same file), or when it is one of
    the ``inputs`` (the same file, compared by device and inode as ``cp`` does).
    Character devices (``/dev/null``) may be both, and streams are not checked.

    Raises
    ------
    LsysError
        ``cannot write NAME: reason``.
    """
    given = [t for t in outputs if t is not None]
    _check_distinct(given)
    in_ids = {}
    for source in inputs:
        if isinstance(source, str | os.PathLike) and (ident := _identity(source)) is not None:
            in_ids[ident] = source
    for path in given:
        if not isinstance(path, str | os.PathLike):
            continue
        label = quote_name(path)
        ident = _identity(path)
        if ident is not None and ident in in_ids:
            raise LsysError(f"cannot write {label}: it is the input file {quote_name(in_ids[ident])}")
        if Path(path).is_dir():
            raise LsysError(f"cannot write {label}: Is a directory")
        parent = Path(os.path.realpath(path)).parent
        if not parent.is_dir():
            reason = "Not a directory" if parent.exists() else "No such file or directory"
            raise LsysError(f"cannot write {label}: {reason}")


# ---------------------------------------------------------------------------
# Writing


def write_atomic(path: Target, data: str | bytes) -> None:
    """Write ``data`` to one target; see :func:`write_files_atomic`.

    Parameters
    ----------
    path : str, os.PathLike, binary stream or int
        The file to create or replace (written through when it is a device, FIFO or
        symbolic link), or a stream or file descriptor to write to.
    data : str or bytes
        The content; a ``str`` is encoded as UTF-8 (newlines written as given).

    Raises
    ------
    LsysError
        ``cannot write PATH: reason`` when the file cannot be written.
    OutputClosed
        The reader of a pipe went away.
    """
    write_files_atomic([(path, data)])


@dataclass
class _Output:
    """One output: what it is called in messages and how it is written."""

    label: str
    payload: bytes
    stream: BinaryIO | int | None = None  # written to directly
    device: str | None = None  # opened and written through
    final: Path | None = None  # replaced by a renamed temporary file
    temp: str | None = None


def write_files_atomic(files: Iterable[tuple[Target, str | bytes]]) -> None:
    """Write several outputs as one step: all of them, or no file changed.

    Every regular file's payload is first written and flushed to a temporary file
    beside its target; then streams and devices are written; only when all of that
    succeeded are the temporary files renamed into place.  If anything fails, every
    temporary file is removed and no regular file is touched.  (A device or a stream
    written before the failure cannot be taken back; a rename failing half-way needs a
    target that turned into a directory meanwhile.)

    Parameters
    ----------
    files : iterable of (target, data)
        Targets (see :data:`Target`) and contents (``str`` is encoded as UTF-8).

    Raises
    ------
    LsysError
        ``cannot write NAME: reason`` for the first target that cannot be written, or
        when one file is given twice.
    OutputClosed
        The reader of a pipe went away (``EPIPE``).
    """
    files = list(files)
    _check_distinct(t for t, _ in files)
    outputs = [_classify(t, d.encode("utf-8") if isinstance(d, str) else bytes(d)) for t, d in files]
    current = outputs[0] if outputs else None
    try:
        for current in outputs:
            if current.final is not None:
                _stage(current)
        for current in outputs:
            if current.final is None:
                _write_through(current)
        for current in outputs:
            if current.final is not None and current.temp is not None:
                os.replace(current.temp, current.final)
                current.temp = None
                _fsync_dir(current.final.parent)
    except BrokenPipeError:
        raise OutputClosed(
            f"cannot write {current.label if current else 'output'}: the reader went away"
        ) from None
    except OSError as exc:
        reason = exc.strerror or str(exc) or type(exc).__name__
        raise LsysError(f"cannot write {current.label if current else 'output'}: {reason}") from None
    finally:
        for out in outputs:
            if out.temp is not None:
                with contextlib.suppress(OSError):
                    os.unlink(out.temp)


def _classify(target: Target, payload: bytes) -> _Output:
    """Decide how a target is written (see the module docstring)."""
    if isinstance(target, int):
        return _Output(
            "standard output" if target == 1 else f"file descriptor {target}", payload, stream=target
        )
    if not isinstance(target, str | os.PathLike):
        return _Output("standard output", payload, stream=target)
    label = quote_name(target)
    try:
        st = os.stat(target)  # follows symbolic links
    except FileNotFoundError:
        st = None
    except OSError as exc:
        raise LsysError(f"cannot write {label}: {exc.strerror or exc}") from None
    if st is not None and stat.S_ISDIR(st.st_mode):
        raise LsysError(f"cannot write {label}: Is a directory")
    if st is not None and not stat.S_ISREG(st.st_mode):
        return _Output(label, payload, device=os.fspath(target))
    return _Output(label, payload, final=Path(os.path.realpath(target)))


def _stage(out: _Output) -> None:
    """Write a regular file's payload to a temporary file beside it, flushed to disk."""
    assert out.final is not None
    fd, out.temp = _create_temp(out.final.parent)
    with os.fdopen(fd, "wb") as fh:
        fh.write(out.payload)
        fh.flush()
        os.fsync(fh.fileno())
    _copy_mode(out.final, out.temp)


def _write_through(out: _Output) -> None:
    """Write a payload to a stream, a file descriptor or a device/FIFO opened for writing."""
    if out.device is not None:
        fd = os.open(out.device, os.O_WRONLY | getattr(os, "O_NOCTTY", 0) | getattr(os, "O_BINARY", 0))
        try:
            _write_fd(fd, out.payload)
        finally:
            os.close(fd)
    elif isinstance(out.stream, int):
        _write_fd(out.stream, out.payload)
    elif out.stream is not None:
        out.stream.write(out.payload)
        out.stream.flush()


def _write_fd(fd: int, data: bytes) -> None:
    view = memoryview(data)
    while view:
        n = os.write(fd, view[:CHUNK])
        view = view[n:]


def _create_temp(directory: Path) -> tuple[int, str]:
    """Create a new temporary file in ``directory``: a short name, whatever the target's length."""
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0)
    for _ in range(100):
        tmp = os.path.join(directory, f".lsys-{secrets.token_hex(4)}.tmp")
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
