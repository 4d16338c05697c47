"""Names in messages: quoted so that a message stays one honest line.

A file name or an element id may hold a newline, a terminal escape sequence or
invisible characters.  Printed raw, a one-line error becomes two lines, or moves
the cursor, or changes the colours of the terminal.  :func:`quote_name` writes
such names the way ``ls`` does (its ``shell-escape`` quoting style): plain names
as they are, names with spaces or shell characters in single quotes, and
characters that are not printable as ``$'\\n'``-style escapes, so the quoted name
can be pasted back into a shell.  :func:`printable` escapes what is left in a
whole message (a last line of defence where a name was not quoted).
"""

from __future__ import annotations

import itertools
import os

__all__ = ["printable", "quote_name"]

#: Characters a name may hold and still be printed without quotes (besides letters and digits).
_PLAIN = frozenset("-_./,+:@%^=")
_ESCAPES = {"\n": "\\n", "\t": "\\t", "\r": "\\r", "\x1b": "\\e", "\a": "\\a", "\b": "\\b", "\f": "\\f"}
_ESCAPES |= {"\v": "\\v", "\\": "\\\\", "'": "\\'"}


def _escape(ch: str) -> str:
    """Return the ``$'…'`` escape of one character."""
    if ch in _ESCAPES:
        return _ESCAPES[ch]
    code = ord(ch)
    if 0xDC80 <= code <= 0xDCFF:  # a byte that was not UTF-8, kept by os.fsdecode (surrogateescape)
        return f"\\x{code - 0xDC00:02x}"
    if code < 0x100:
        return f"\\x{code:02x}"
    return f"\\u{code:04x}" if code < 0x10000 else f"\\U{code:08x}"


def quote_name(name: str | bytes | os.PathLike) -> str:
    """Return ``name`` quoted for a one-line message, like ``ls --quoting-style=shell-escape``.

    Parameters
    ----------
    name : str, bytes or os.PathLike
        A file name, element id or other text from outside the program.

    Returns
    -------
    str
        ``name`` itself when it holds only letters, digits and ``-_./,+:@%^=``;
        otherwise single-quoted, with every character that is not printable
        (control characters, line and paragraph separators, bytes that are not
        UTF-8) written as a ``$'\\n'`` escape outside the quotes.

    Examples
    --------
    >>> quote_name("rules.lsys")
    'rules.lsys'
    >>> print(quote_name("my file.svg"))
    'my file.svg'
    >>> print(quote_name("a\\nb"))
    'a'$'\\n''b'
    """
    text = os.fsdecode(name) if isinstance(name, bytes | os.PathLike) else str(name)
    if text and all((ch.isalnum() and ch.isprintable()) or ch in _PLAIN for ch in text):
        return text
    parts = []
    for printable_run, run in itertools.groupby(text, key=str.isprintable):
        chars = "".join(run)
        if printable_run:
            parts.append("'" + chars.replace("'", "'\\''") + "'")
        else:
            parts.append("$'" + "".join(_escape(ch) for ch in chars) + "'")
    return "".join(parts) or "''"


def printable(message: str) -> str:
    """Return ``message`` with every character that is not printable written as an escape.

    Used on whole messages before they reach a terminal, so that no text from an
    input (an id inside a warning, a name that was not quoted) can break the line
    or send a control sequence.  Printable text, spaces included, is unchanged.
    """
    if message.isprintable():
        return message
    return "".join(ch if ch.isprintable() else _escape(ch) for ch in message)
