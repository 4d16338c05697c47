"""Vectorised lexing of SVG number lists and path data (no regular expressions, no per-number objects).

The text is classified byte by byte with a lookup table; number boundaries (``1-2``, ``1.5.5``,
``1e-3``) follow from shifted boolean arrays, malformed numbers (``1e``, ``.``, ``-``) are found
with a few gathers, and the values are read with whole-array operations (:mod:`.decimals`,
correctly rounded, like :func:`float`).  The text is processed
in chunks of about a megabyte cut at separators, so temporary memory is bounded whatever the length
(one chunk per worker at a time: :func:`lsys_core.parallel.jobs`); work is linear in the length and
the result holds three numbers per token.
"""

from __future__ import annotations

import itertools
import re
from typing import NamedTuple

import numpy as np

from lsys_core.errors import LimitError
from lsys_core.geometry.decimals import read_decimals
from lsys_core.parallel import jobs, pmap

__all__ = ["COMMAND_LETTERS", "Lexed", "lex", "numbers_from_text"]

_INVALID, _SPACE, _COMMA, _DIGIT, _DOT, _SIGN, _EXP, _LETTER = range(8)
#: Letters that are path commands (``e``/``E`` are exponents; other letters are errors).
COMMAND_LETTERS = b"MmZzLlHhVvCcSsQqTtAa"
#: Bytes per chunk (the text is cut at the first separator after this many bytes).
CHUNK = 1 << 20
#: Texts up to this many bytes are tried with :func:`_lex_short` first.
SHORT = 160

_CLASS = np.zeros(256, dtype=np.int8)
for _c in b" \t\r\n\f":
    _CLASS[_c] = _SPACE
_CLASS[ord(",")] = _COMMA
for _c in b"0123456789":
    _CLASS[_c] = _DIGIT
_CLASS[ord(".")] = _DOT
_CLASS[ord("+")] = _SIGN
_CLASS[ord("-")] = _SIGN
_CLASS[ord("e")] = _EXP
_CLASS[ord("E")] = _EXP
for _c in COMMAND_LETTERS:
    _CLASS[_c] = _LETTER


class Lexed(NamedTuple):
    """Tokens of a text: numbers with their byte offsets, command letters with theirs.

    ``errors`` holds the byte offsets of every character that is not part of a valid token and
    of every malformed number (those are left out of ``values``), in increasing order; ``error``
    is the first of them, or -1.
    """

    values: np.ndarray
    starts: np.ndarray
    letters: np.ndarray
    letter_pos: np.ndarray
    errors: np.ndarray

    @property
    def error(self) -> int:
        """The offset of the first error, or -1."""
        return int(self.errors[0]) if self.errors.size else -1

    def before(self, offset: int) -> Lexed:
        """Return the tokens that start before ``offset`` (the text as read up to an error)."""
        k = int(np.searchsorted(self.starts, offset))
        j = int(np.searchsorted(self.letter_pos, offset))
        return Lexed(self.values[:k], self.starts[:k], self.letters[:j], self.letter_pos[:j], self.errors)


def lex(
    text: str | bytes, *, letters: bool = True, chunk: int = CHUNK, max_numbers: int | None = None
) -> Lexed:
    """Split path data (``letters``) or a number list into numbers and command letters.

    Parameters
    ----------
    text : str or bytes
        The attribute value (or several, joined by newlines).  Non-ASCII characters are errors.
    letters : bool
        Whether path command letters are tokens (otherwise they are errors).
    chunk : int
        Bytes lexed at a time by each worker (bounds the temporary memory).
    max_numbers : int, optional
        Most numbers accepted (checked after each chunk, before more memory is used).

    Returns
    -------
    Lexed

    Raises
    ------
    LimitError
        The text holds more than ``max_numbers`` numbers.
    """
    raw = text.encode("ascii", "replace") if isinstance(text, str) else bytes(text)
    if len(raw) <= SHORT:
        quick = _lex_short(raw, letters)
        if quick is not None:
            if max_numbers is not None and quick.values.size > max_numbers:
                raise LimitError(f"more than {max_numbers:,} numbers in path data")
            return quick
    whole = np.frombuffer(raw, dtype=np.uint8)
    bounds = [0]
    while bounds[-1] < whole.size:
        bounds.append(_cut(whole, bounds[-1] + chunk))
    pieces = list(itertools.pairwise(bounds))
    parts: list[tuple[np.ndarray, ...]] = []
    count = 0
    step = jobs()  # chunks lexed at once, one a worker (the array operations release the GIL)
    for first in range(0, len(pieces), step):
        batch = pieces[first : first + step]
        for (a, _), (vals, starts, lets, lpos, errs) in zip(
            batch, pmap(lambda ab: _lex_chunk(whole[ab[0] : ab[1]], letters), batch), strict=True
        ):
            parts.append((vals, starts + a, lets, lpos + a, errs + a))
            count += vals.size
        if max_numbers is not None and count > max_numbers:
            raise LimitError(f"more than {max_numbers:,} numbers in path data")
    if not parts:
        z = np.zeros(0, dtype=np.int64)
        return Lexed(np.zeros(0), z, np.zeros(0, np.uint8), z, z)
    cols = [np.concatenate(col) for col in zip(*parts, strict=True)]
    return Lexed(cols[0], cols[1], cols[2], cols[3], cols[4])


_NUM = rb"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?"
_SEP = rb"[ \t\r\n\f,]*"
#: A text of well-formed numbers and separators (and command letters): the short path reads it.
#: Numbers are atomic groups: no backtracking into a number (``1.9.`` is not ``1.`` ``9.``).
_CLEAN = {
    True: re.compile(rb"(?:" + _SEP + rb"(?:(?>" + _NUM + rb")|[" + COMMAND_LETTERS + rb"]))*" + _SEP),
    False: re.compile(rb"(?:" + _SEP + rb"(?>" + _NUM + rb"))*" + _SEP),
}
_TOKEN = {
    True: re.compile(_NUM + rb"|[" + COMMAND_LETTERS + rb"]"),
    False: re.compile(_NUM),
}


def _lex_short(raw: bytes, letters: bool) -> Lexed | None:
    """Lex a short, well-formed text with a regular expression (None: not well-formed).

    For a few dozen bytes (a ``points`` list, a small path) the vectorised lexer's fixed cost of
    some 40 numpy calls dominates: on 3,000 small polygons it took 0.45 of 2.3 s of SVG import.
    A well-formed text has the same tokens either way (greedy numbers split where the vectorised
    lexer splits them: ``1.5.5``, ``1-2``, ``1e5.5``); anything else (an error to locate) goes
    the vectorised way.
    """
    if _CLEAN[letters].fullmatch(raw) is None:
        return None
    values, starts, lets, lpos = [], [], [], []
    for m in _TOKEN[letters].finditer(raw):
        token = m.group()
        if token[0] in COMMAND_LETTERS:
            lets.append(token[0])
            lpos.append(m.start())
        else:
            values.append(float(token))
            starts.append(m.start())
    z = np.zeros(0, dtype=np.int64)
    return Lexed(
        np.array(values, dtype=float),
        np.array(starts, dtype=np.int64),
        np.array(lets, dtype=np.uint8),
        np.array(lpos, dtype=np.int64),
        z,
    )


def numbers_from_text(text: str) -> tuple[np.ndarray, int]:
    """Return the numbers of a list such as ``points="1,2 3-4"`` up to the first error, and its offset (-1)."""
    lexed = lex(text, letters=False)
    if lexed.errors.size:
        lexed = lexed.before(lexed.error)
    return lexed.values, lexed.error


def _cut(b: np.ndarray, at: int) -> int:
    """Return a chunk end at or after ``at``: just after a separator or before a letter (or the end)."""
    if at >= b.size:
        return b.size
    window = _CLASS[b[at : at + 4096]]
    while True:
        hit = np.flatnonzero((window == _SPACE) | (window == _COMMA) | (window == _LETTER))
        if hit.size:
            return at + int(hit[0])
        at += window.size
        if at >= b.size:
            return b.size
        window = _CLASS[b[at : at + 65536]]


def _lex_chunk(b: np.ndarray, letters: bool):
    """Lex one chunk (no token crosses its ends): values, starts, letters, their offsets, errors."""
    cls = _CLASS[b]
    if not letters:
        cls = np.where(cls == _LETTER, np.int8(_INVALID), cls)
    invalid = np.flatnonzero(cls == _INVALID)
    if invalid.size:
        cls = np.where(cls == _INVALID, np.int8(_SPACE), cls)  # an error, then read on
    n = cls.size
    numeric = (cls >= _DIGIT) & (cls <= _EXP)
    prev_num = np.zeros(n, dtype=bool)
    prev_num[1:] = numeric[:-1]
    prev_exp = np.zeros(n, dtype=bool)
    prev_exp[1:] = cls[:-1] == _EXP
    piece = numeric & (~prev_num | ((cls == _SIGN) & ~prev_exp))
    # A dot splits when its piece already holds a dot or an exponent ("1.5.5", "1e5.5").
    de = np.flatnonzero((cls == _DOT) | (cls == _EXP))
    start = piece
    if de.size > 1:
        pid = np.cumsum(piece, dtype=np.int32)
        cur, prev = de[1:], de[:-1]
        split = cur[(cls[cur] == _DOT) & (pid[cur] == pid[prev])]
        if split.size:
            start = piece.copy()
            start[split] = True
    starts = np.flatnonzero(start)
    # Token ends: the next token start or the end of the run of number characters.
    nonnum = np.flatnonzero(~numeric)
    run_end = np.append(nonnum, n)[np.searchsorted(nonnum, starts)]
    ends = np.minimum(np.append(starts[1:], n), run_end)
    bad = _malformed(cls, starts, ends)
    errors = invalid
    if bad.any():
        errors = np.union1d(invalid, starts[bad])
        # Leave malformed numbers out: their characters become separators.
        tok = np.cumsum(start, dtype=np.int32) - 1
        numeric = numeric & ~bad[np.maximum(tok, 0)]
        starts, ends = starts[~bad], ends[~bad]
    lpos = np.flatnonzero(cls == _LETTER)
    values = _values(b, numeric, starts, ends)
    return values, starts.astype(np.int64), b[lpos], lpos.astype(np.int64), errors.astype(np.int64)


def _malformed(cls, starts, ends) -> np.ndarray:
    """Mark the malformed number tokens: no mantissa digit, or a bad or second exponent."""
    bad = np.zeros(starts.size, dtype=bool)
    if starts.size == 0:
        return bad
    n = cls.size
    pad = np.append(cls, np.int8(_SPACE))

    def at(i):
        return pad[np.minimum(i, n)]

    m = starts + (at(starts) == _SIGN)  # first mantissa character
    cm, cm1 = at(m), at(m + 1)
    bad |= ~(((cm == _DIGIT) | ((cm == _DOT) & (cm1 == _DIGIT))) & (m < ends))
    exps = np.flatnonzero(cls == _EXP)
    if exps.size:
        tok = np.searchsorted(starts, exps, side="right") - 1  # every exponent lies in a token
        after, after2 = at(exps + 1), at(exps + 2)
        ok = (after == _DIGIT) | ((after == _SIGN) & (after2 == _DIGIT))
        dup = np.zeros(exps.size, dtype=bool)
        dup[1:] = tok[1:] == tok[:-1]
        bad[tok[~ok | dup]] = True
    return bad


def _values(b: np.ndarray, numeric: np.ndarray, starts: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """Read the token values (:func:`~lsys_core.geometry.decimals.read_decimals`)."""
    return read_decimals(b, numeric, starts, ends)
