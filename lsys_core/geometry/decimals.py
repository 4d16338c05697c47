"""Exact values of lexed decimal numbers, read with whole-array numpy operations.

The lexer (:mod:`.numbers`) knows where every number token of a chunk of text starts and ends.
A token of at most :data:`FAST_DIGITS` digits and no exponent has an integer mantissa ``M <
10**15 < 2**53`` and ``f <= 15`` digits after its point; ``M`` and ``10**f`` are exact doubles,
so the one division ``M / 10**f`` is the correctly rounded value of the decimal, the value
:func:`float` gives (Clinger's fast path).  ``M`` is summed from its digits' exact terms ``d *
10**k`` (every partial sum is an integer below ``2**53``: exact in any order).  Other tokens
(exponents, longer mantissas: rare in drawings) are read by :func:`float`.

numpy's text parser (``np.fromstring``), used before, holds the GIL while it reads: two workers
lexing two chunks were slower than one (the path data of a 50,052-leaf grid, 5.2 MB: 160 ms with
one thread, 195 ms with two).  These operations release it, and read that grid's 500,520 numbers
in about 80 ms where the text parser took about 100 (one thread, the same process, alternating).
"""

from __future__ import annotations

import numpy as np

__all__ = ["BLOCK", "FAST_DIGITS", "read_decimals"]

#: Tokens read at a time (bounds the temporary memory: about 25 bytes a digit).
BLOCK = 1 << 12
#: Mantissa digits a token may have to be read without :func:`float`.
FAST_DIGITS = 15

_POW10 = np.array([10.0**k for k in range(FAST_DIGITS + 1)])
#: ``d * 10**k`` at ``k * 256 + ord(str(d))`` (zero for other bytes).
_TERMS = np.zeros((FAST_DIGITS + 1) * 256)
_TERMS.reshape(-1, 256)[:, 48:58] = _POW10[:, None] * np.arange(10.0)
_IS_DIGIT = np.zeros(256, dtype=bool)
_IS_DIGIT[48:58] = True


def read_decimals(b: np.ndarray, numeric: np.ndarray, starts: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """Return the value of every number token of a lexed chunk, as :func:`float` reads it.

    Parameters
    ----------
    b : ndarray of uint8
        The chunk's bytes.
    numeric : ndarray of bool
        Which bytes belong to a number token (each token's bytes, nothing between tokens).
    starts, ends : ndarray of int
        Each token's first byte and the byte after its last, in increasing order; every token
        is a well-formed number (``[+-]`` digits with at most one point, an optional exponent).

    Returns
    -------
    ndarray of float, shape (len(starts),)
    """
    values = np.empty(starts.size)
    for lo in range(0, starts.size, BLOCK):
        hi = min(lo + BLOCK, starts.size)
        a, z = int(starts[lo]), int(ends[hi - 1])
        values[lo:hi] = _read_block(b[a:z], numeric[a:z], starts[lo:hi] - a, ends[lo:hi] - a)
    return values


def _read_block(b: np.ndarray, numeric: np.ndarray, starts: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """:func:`read_decimals` of a block of tokens (``b`` from the first token's start on)."""
    n_tok = starts.size
    pos = np.flatnonzero(_IS_DIGIT[b] & numeric)  # every digit of every token, in order
    first = np.searchsorted(pos, starts)  # each token's first digit (index in ``pos``)
    counts = np.diff(first, append=pos.size)
    last = first + counts - 1
    # Each digit's term ``d * 10**k``, k the digits after it in its token, from a table by
    # ``k * 256 + byte`` (k beyond the table only in slow tokens): 4 + 8 bytes a digit.
    index = np.repeat(last.astype(np.int32), counts)
    index -= np.arange(pos.size, dtype=np.int32)
    np.minimum(index, FAST_DIGITS, out=index)
    index <<= 8
    index += b[pos]
    terms = _TERMS.take(index)
    del index
    mantissa = (
        np.add.reduceat(terms, np.minimum(first, max(pos.size - 1, 0))) if pos.size else np.zeros(n_tok)
    )
    slow = (counts > FAST_DIGITS) | (counts == 0)
    scale = np.zeros(n_tok, dtype=np.int64)
    dots = np.flatnonzero((b == ord(".")) & numeric)
    if dots.size:
        dot_tok = np.searchsorted(starts, dots, side="right") - 1  # (a token has at most one point)
        scale[dot_tok] = last[dot_tok] + 1 - np.searchsorted(pos, dots)
    exps = np.flatnonzero(((b == ord("e")) | (b == ord("E"))) & numeric)
    if exps.size:
        slow[np.searchsorted(starts, exps, side="right") - 1] = True
    values = mantissa / _POW10.take(scale, mode="clip")
    np.negative(values, out=values, where=b[starts] == ord("-"))
    if slow.any():
        raw = b.tobytes()
        for i in np.flatnonzero(slow).tolist():
            values[i] = float(raw[starts[i] : ends[i]])
    return values
