"""Tokens of the ``.lsys`` text format (see ``docs/lsys-format.md``).

:func:`tokenize` splits text into lines of :class:`Tok` s, each line ending with an ``eol``
token; every error is a :class:`~lsys_core.errors.GrammarSyntaxError` with the 1-based line
and column of the offending character.
"""

from __future__ import annotations

import math
import re
from typing import NamedTuple

from lsys_core.errors import GrammarSyntaxError

__all__ = ["Tok", "fail", "number", "quote", "tokenize"]

_TOKEN = re.compile(
    r"""
      (?P<ws>[^\S\r\n]+)
    | (?P<nl>\r\n|\n|\r)
    | (?P<comment>\#[^\r\n]*)
    | (?P<str>"(?:[^"\\\r\n]|\\[^\r\n])*")
    | (?P<range>\d+\.\.\d+)
    | (?P<num>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)
    | (?P<name>[A-Za-z_][A-Za-z0-9_]*)
    | (?P<arrow>->|→)
    | (?P<punct>==|[-−+*∗()\[\]:>{},~])
    | (?P<eps>ε)
    """,
    re.VERBOSE,
)
_NUMBER_TAIL = re.compile(r"[A-Za-z0-9_.]+")
_ESCAPE = re.compile(r"\\(.)", re.DOTALL)
_ESCAPES = {"\\": "\\", '"': '"', "n": "\n", "r": "\r", "t": "\t"}
_QUOTING = str.maketrans({v: "\\" + k for k, v in _ESCAPES.items()})
_UNICODE_OPS = {"−": "-", "∗": "*"}  # the paper's minus and asterisk, as pasted from a PDF


class Tok(NamedTuple):
    """A token: kind (``num``, ``range``, ``name``, ``str``, ``arrow``, ``eps``, ``punct``, ``eol``), text, position."""

    kind: str
    text: str
    line: int
    col: int

    @property
    def pos(self) -> tuple[int, int]:
        """Return ``(line, column)``."""
        return self.line, self.col

    def shown(self) -> str:
        """Return the token as it reads in a message."""
        return "end of line" if self.kind == "eol" else f"'{self.text}'"


def fail(message: str, at: Tok | tuple[int, int]) -> GrammarSyntaxError:
    """Return the syntax error ``message`` at a token or ``(line, column)``."""
    line, col = at.pos if isinstance(at, Tok) else at
    return GrammarSyntaxError(message, line, col)


def tokenize(text: str) -> tuple[list[list[Tok]], list[tuple[int, str]], tuple[int, int]]:
    """Split ``text`` into non-empty lines of tokens, each ending with an ``eol`` token.

    Returns
    -------
    lines : list of list of Tok
    comments : list of tuple
        ``(line, text)`` of each comment, without ``#`` and surrounding blanks.
    end : tuple of int
        ``(line, column)`` just past the end of the text.
    """
    lines: list[list[Tok]] = []
    comments: list[tuple[int, str]] = []
    current: list[Tok] = []
    line, line_start, pos = 1, 0, 0
    if text.startswith("\ufeff"):
        pos = line_start = 1
    while pos < len(text):
        mt = _TOKEN.match(text, pos)
        col = pos - line_start + 1
        if mt is None:
            if text[pos] == '"':
                raise fail("unterminated string: add the closing '\"'", (line, col))
            raise fail(f"unexpected character {text[pos]!r}", (line, col))
        kind, raw = mt.lastgroup or "", mt.group()
        pos = mt.end()
        if kind == "nl":
            if current:
                lines.append([*current, Tok("eol", "", line, col)])
            current = []
            line, line_start = line + 1, pos
        elif kind == "comment":
            comments.append((line, raw[1:].strip()))
        elif kind in ("num", "range") and (tail := _NUMBER_TAIL.match(text, pos)):
            raise fail(f"bad number '{raw + tail.group()}'", (line, col))
        elif kind == "str":
            current.append(Tok("str", _unescape(raw, line, col), line, col))
        elif kind != "ws":
            current.append(Tok(kind, _UNICODE_OPS.get(raw, raw), line, col))
    end = (line, pos - line_start + 1)
    if current:
        lines.append([*current, Tok("eol", "", *end)])
    return lines, comments, end


def _unescape(raw: str, line: int, col: int) -> str:
    """Return the value of a quoted string token, resolving ``\\\\ \\" \\n \\r \\t``."""
    inner = raw[1:-1]
    if "\\" not in inner:
        return inner

    def resolve(mt: re.Match) -> str:
        esc = _ESCAPES.get(mt.group(1))
        if esc is None:
            where = (line, col + 1 + mt.start())
            raise fail(f"unknown escape '\\{mt.group(1)}' in string (use \\\\ for a backslash)", where)
        return esc

    return _ESCAPE.sub(resolve, inner)


def number(tok: Tok) -> float:
    """Return the value of a number token, refusing overflow to infinity."""
    v = float(tok.text)
    if not math.isfinite(v):
        raise fail(f"number out of range '{tok.text}'", tok)
    return v


def quote(s: str) -> str:
    """Return ``s`` double-quoted with backslash escapes."""
    return '"' + s.translate(_QUOTING) + '"'
