"""Tests of the whole-array decimal reader: every value as :func:`float` reads it, bit for bit."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from lsys_core.geometry import numbers
from lsys_core.geometry.decimals import BLOCK, FAST_DIGITS, read_decimals


def _lexed(text: str):
    """The bytes, number mask, starts and ends the lexer hands the reader for ``text``."""
    b = np.frombuffer(text.encode(), np.uint8)
    got = {}

    def spy(b, numeric, starts, ends):
        got.update(b=b, numeric=numeric, starts=starts, ends=ends)
        return read_decimals(b, numeric, starts, ends)

    old = numbers._values
    numbers._values = spy
    try:
        numbers._lex_chunk(b, True)
    finally:
        numbers._values = old
    return got


def _as_float(text: str) -> list[float]:
    lexed = _lexed(text)
    raw = text.encode()
    return [float(raw[s:e]) for s, e in zip(lexed["starts"].tolist(), lexed["ends"].tolist(), strict=True)]


def _check(text: str) -> None:
    lexed = _lexed(text)
    if "b" not in lexed:
        return
    got = read_decimals(lexed["b"], lexed["numeric"], lexed["starts"], lexed["ends"])
    want = np.array(_as_float(text), dtype=float)
    assert np.array_equal(got.view(np.int64), want.view(np.int64)), text  # bits: -0.0 too


_DIGITS = st.text("0123456789", min_size=0, max_size=22)
_NUMBER = st.builds(
    lambda sign, whole, dot, frac, exp: sign + whole + dot + frac + exp,
    st.sampled_from(["", "-", "+"]),
    _DIGITS,
    st.sampled_from(["", "."]),
    _DIGITS,
    st.sampled_from(["", "e5", "E-3", "e+300", "e-330", "e400"]),
)
_SEP = st.sampled_from([" ", ",", " , ", "\n", "L", "M", "-"])


@settings(max_examples=500, deadline=None)
@given(st.lists(st.tuples(_NUMBER, _SEP), max_size=40))
def test_values_are_those_float_reads(parts):
    _check("M" + "".join(n + s for n, s in parts))


def test_edges_of_the_exact_path():
    cases = [
        "0 -0 +0 -0.0 .0 0. -.0",
        "9" * FAST_DIGITS + " " + "9" * (FAST_DIGITS + 1) + " 0." + "0" * 30 + "1",
        "1." + "1" * (FAST_DIGITS - 1) + " 123456789012345.6 0.1 0.2 0.3 1e-5 2.5e+3",
        "1.5.5 1-2 1e5.5 3.14159265358979 -2.718281828459045",
        "00000000000000000000001 1." + "0" * 40,
    ]
    for text in cases:
        _check(text)


def test_blocks_give_the_same_values():
    rng = np.random.default_rng(1)
    values = rng.uniform(-1e6, 1e6, 3 * BLOCK + 17)
    text = " ".join(f"{v:.{rng.integers(0, 12)}f}" for v in values)
    _check(text)
