"""Bounded reading: a size limit checked before and while reading, text checked chunk by chunk."""

from __future__ import annotations

import codecs
import contextlib
import os
import stat
from typing import BinaryIO

from lsys_core.errors import LimitError, LsysError
from lsys_core.quoting import quote_name

__all__ = ["CHUNK", "MAX_TEXT_BYTES", "read_bytes", "read_text"]

#: Largest text file (``.lsys`` rules, parameter files) :func:`read_text` accepts by default, in bytes.
MAX_TEXT_BYTES = 20_000_000
#: Bytes read at a time; every chunk is checked before the next is read.
CHUNK = 1 << 20


def read_bytes(source: str | os.PathLike | BinaryIO, *, limit: int, name: str | None = None) -> bytes:
    """Read a whole file, a device or a stream, refusing more than ``limit`` bytes.

    A regular file larger than ``limit`` is refused before reading (its size is known);
    anything else (pipes, devices, standard input) is read in chunks and refused as soon
    as it passes ``limit``, so memory stays below ``limit + CHUNK``.

    Parameters
    ----------
    source : str, os.PathLike or binary stream
        A path, or an open stream such as ``sys.stdin.buffer``.
    limit : int
        Largest accepted size in bytes.
    name : str, optional
        Name used in messages (default: the quoted path).

    Raises
    ------
    LsysError
        ``cannot read NAME: reason`` when it cannot be opened or read.
    LimitError
        ``NAME is too large (…; the limit is LIMIT bytes)``.
    """
    return b"".join(_chunks(source, limit, name))


def read_text(
    source: str | os.PathLike | BinaryIO, *, limit: int = MAX_TEXT_BYTES, name: str | None = None
) -> str:
    """Read UTF-8 text like :func:`read_bytes`, failing on the first chunk that is not text.

    A NUL byte or a byte sequence that is not UTF-8 stops the reading at once (so
    ``/dev/zero`` or ``/dev/urandom`` fail on their first megabyte); the message gives
    its line and column.  A leading byte order mark is dropped.

    Raises
    ------
    LsysError
        ``NAME:LINE:COLUMN: unexpected character NUL (binary data, not text)`` or
        ``NAME:LINE:COLUMN: not UTF-8 text (byte 0xHH)``, besides the errors of
        :func:`read_bytes`.
    """
    label = name if name is not None else _label(source)
    decoder = codecs.getincrementaldecoder("utf-8")()
    parts: list[str] = []
    for chunk in _chunks(source, limit, label):
        try:
            text = decoder.decode(chunk)
        except UnicodeDecodeError as exc:
            good = chunk[: exc.start].decode("utf-8", errors="ignore")
            where = _where("".join(parts) + good)
            raise LsysError(f"{label}:{where}: not UTF-8 text (byte 0x{chunk[exc.start]:02x})") from None
        if "\x00" in text:
            where = _where("".join(parts) + text[: text.index("\x00")])
            raise LsysError(f"{label}:{where}: unexpected character NUL (binary data, not text)")
        parts.append(text)
    try:
        parts.append(decoder.decode(b"", final=True))
    except UnicodeDecodeError:
        raise LsysError(f"{label}:{_where(''.join(parts))}: not UTF-8 text (truncated at the end)") from None
    return "".join(parts).removeprefix("\ufeff")


def _where(before: str) -> str:
    """Return ``LINE:COLUMN`` (1-based) of the character that follows ``before``."""
    line = before.count("\n") + 1
    return f"{line}:{len(before) - (before.rfind(chr(10)) + 1) + 1}"


def _label(source: object) -> str:
    if isinstance(source, str | os.PathLike):
        return quote_name(source)
    return "standard input"


def _chunks(source: str | os.PathLike | BinaryIO, limit: int, name: str | None):
    label = name if name is not None else _label(source)
    try:
        fh: BinaryIO
        if isinstance(source, str | os.PathLike):
            fh = open(source, "rb")  # noqa: SIM115 (closed below)
            close = True
        else:
            fh, close = source, False
        try:
            with contextlib.suppress(OSError, AttributeError, ValueError):
                st = os.fstat(fh.fileno())
                if stat.S_ISREG(st.st_mode) and st.st_size > limit:
                    raise LimitError(f"{label} is too large ({st.st_size:,} bytes; the limit is {limit:,})")
            total = 0
            while True:
                chunk = fh.read(min(CHUNK, limit + 1 - total))
                if not chunk:
                    return
                total += len(chunk)
                if total > limit:
                    raise LimitError(f"{label} is too large (more than {limit:,} bytes, the limit)")
                yield chunk
        finally:
            if close:
                fh.close()
    except OSError as exc:
        raise LsysError(f"cannot read {label}: {exc.strerror or exc}") from None
