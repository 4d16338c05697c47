"""Path data written compactly: every number rounded to a millionth of the shape's size.

The numbers are cut out of the text by one regular-expression split and written by one
``%``-format of all of them (no Python call per number): a path of 10^6 lines took 12 s
with a callback per number and takes about 2 s so.  Long path data is done in pieces of
about a MiB, split before command letters, so the lists of pieces stay small.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterator

import numpy as np

from lsys_core.errors import LsysError
from lsys_core.geometry.shapes import shape_arrays

__all__ = ["PATH_PRECISION", "compact_path_data"]

#: Precision of the numbers in a terminal's path data, relative to the shape's size (a shape
#: 1,000 px wide is written to a thousandth of a pixel).
PATH_PRECISION = 1e-6
_NUMBER = re.compile(r"([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)")
#: Zeros at the end of a number written with a fixed number (> 0) of decimals, then a bare point:
#: replacements without group references, so the C engine does them without Python calls.
_TRAILING = re.compile(r"0+$", re.M)
_POINT = re.compile(r"\.$", re.M)
_NEGATIVE_ZERO = re.compile(r"^-0$", re.M)
_COMMAND = re.compile(r"[MLCZHVSQTmlczhvsqt]")


def compact_path_data(d: str) -> str:
    """Return path data with its numbers rounded to :data:`PATH_PRECISION` of the shape's size.

    Path data with arcs is left as it is (their flags may be written without separators).
    """
    if "a" in d.lower():
        return d
    try:
        cubics = shape_arrays(d)[0]
    except LsysError:
        return d
    if cubics.size == 0 or not np.isfinite(cubics).all():
        return d
    size = float(max(np.ptp(cubics.real), np.ptp(cubics.imag), np.abs(cubics).max()))
    if size <= 0:
        return d
    decimals = max(0, -math.floor(math.log10(size * PATH_PRECISION)))

    return "".join(_rounded(piece, decimals) for piece in _pieces(d))


def _pieces(d: str, size: int = 1 << 20) -> Iterator[str]:
    """Split path data before command letters about every ``size`` characters (bounded memory)."""
    start = 0
    while len(d) - start > size:
        cut = _COMMAND.search(d, start + size)
        if cut is None:
            break
        yield d[start : cut.start()]
        start = cut.start()
    yield d[start:]


def _rounded(d: str, decimals: int) -> str:
    """``d`` with every number written with ``decimals`` decimals, trailing zeros dropped."""
    parts = _NUMBER.split(d)  # text between numbers, number, text, …: no callback per number
    if len(parts) == 1:
        return d
    values = np.array(parts[1::2], dtype=float)
    text = "\n".join([f"%.{decimals}f"] * values.size) % tuple(values.tolist())
    text = _NEGATIVE_ZERO.sub("0", _POINT.sub("", _TRAILING.sub("", text)) if decimals else text)
    parts[1::2] = text.split("\n")
    return "".join(parts)
