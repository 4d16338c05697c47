"""Shapes whose points overflow: skipped as non-finite, with no floating-point warning (found by hypothesis)."""

from __future__ import annotations

import warnings

import pytest

from tests.robustness.oracles import check_svg_import

HEAD = '<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink">'
BIG = "9999999999999999999999999999999999999999"


@pytest.mark.parametrize(
    "body",
    [
        '<polyline fill="red" points="0 0 0 1e999"/>',
        f'<polyline points="{BIG} 1.3189221016739936e+268 {BIG} {BIG}"/>',
        '<polygon points="1e300 1e300 -1e300 1e300 0 -1e300" fill="url(#g)"/><linearGradient id="g"/>',
    ],
)
def test_overflowing_points_are_skipped_quietly(body):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_svg_import(HEAD + body + "</svg>")
