"""Attribute numbers: the quick reader of short plain values agrees with the path-data lexer."""

from __future__ import annotations

import math
import random

import pytest

from lsys_core.geometry.numbers import numbers_from_text
from lsys_core.svg import values
from lsys_core.svg.colors import parse_color


def _lexer(text: str) -> list[float] | None:
    got, error = numbers_from_text(text)
    return None if error >= 0 else got.tolist()


@pytest.mark.parametrize("text", ["1", "-.5", "5.", "1e3", "1,2 3", " 1 , 2 ", "0 0 10 10", "+1E-2,3"])
def test_quick_path_reads_plain_lists(text):
    quick = values._quick_numbers(text.strip(), one=False)
    assert quick is not None
    assert quick == _lexer(text)


@pytest.mark.parametrize(
    "text", ["1-2", ".5.5", "1,,2", ",1", "1,", "1e400", "1e", "e5", "1_0", "inf", "nan"]
)
def test_quick_path_leaves_the_rest_to_the_lexer(text):
    assert values._quick_numbers(text, one=False) is None


def test_quick_path_agrees_with_the_lexer_on_random_text():
    rng = random.Random(7)
    alphabet = "0123456789+-.eE ,"
    read = 0
    for _ in range(20000):
        text = "".join(rng.choice(alphabet) for _ in range(rng.randint(1, 12))).strip()
        quick = values._quick_numbers(text, one=False)
        if quick is not None:
            read += 1
            assert quick == _lexer(text), text
    assert read > 1000  # the quick path is taken, not only refused


def test_single_numbers_and_lengths():
    assert values.parse_number(" 12.5 ") == 12.5
    assert values.parse_number("1 2") is None
    assert values.parse_number("1e400") is None
    rotated = values.parse_transform("rotate(1e999)")  # no math domain error: a non-finite matrix
    assert rotated is not None and all(math.isnan(v) for v in rotated)
    assert values.parse_length("3mm") == values.Length(3.0, "mm")
    assert parse_color("rgb(0 128 0 / 50%)") == (0.0, 128 / 255, 0.0, 0.5)
