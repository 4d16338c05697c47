"""Path data written compactly: every number rounded to a millionth of the shape's size.

The numbers are cut out of the text by one regular-expression split and written by one
``%``-format of all of them (no Python call per number): a path of 10^6 lines took 12 s
with a callback per number and takes about 2 s so.  Long path data is done in pieces of
about a MiB, split before command letters, so the lists of pieces stay small.

:func:`compact_paths` does many short texts at once the same way: their sizes by array
reductions over all of them, and the texts of one number of decimals joined into pieces of
about 64 KiB (a NUL between two texts, no part of a number, parts them again).  10,000 small
leaves took 0.41 s one by one (numpy's fixed cost per call) and take 0.24 s so.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterator

import numpy as np

from lsys_core.errors import LsysError
from lsys_core.geometry.shapes import ptp_at, shape_arrays, shapes_arrays
from lsys_core.parallel import runs

__all__ = ["PATH_PRECISION", "compact_path_data", "compact_paths"]

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
    return "".join(_rounded(piece, _decimals(size)) for piece in _pieces(d))


def _decimals(size: float) -> int:
    """Decimals written for a shape of extent ``size`` (> 0)."""
    return max(0, -math.floor(math.log10(size * PATH_PRECISION)))


def compact_paths(ds: list[str], block: int = 1 << 16) -> list[str]:
    """Return :func:`compact_path_data` of every text, the texts of one precision done together.

    ``block`` is about the most characters rounded at once.
    """
    out = list(ds)
    arrays = shapes_arrays(ds)
    todo = []
    for i, (d, a) in enumerate(zip(ds, arrays, strict=True)):
        if len(d) > block or "\0" in d:
            out[i] = compact_path_data(d)  # in pieces / not to be joined
        elif a is not None and a[0].size and "a" not in d.lower():
            todo.append(i)
    if not todo:
        return out
    parts = [arrays[i][0] for i in todo]  # type: ignore[index]
    starts = np.concatenate([[0], np.cumsum([c.shape[0] for c in parts])[:-1]])
    cubics = np.concatenate(parts)
    x, y = cubics.real, cubics.imag
    with np.errstate(invalid="ignore"):
        finite = np.logical_and.reduceat(np.isfinite(cubics).all(axis=1), starts)
        size = np.maximum(
            np.maximum(ptp_at(x, starts), ptp_at(y, starts)),
            np.maximum.reduceat(np.abs(cubics).max(axis=1), starts),
        )
    groups: dict[int, list[int]] = {}
    for i, ok, s in zip(todo, finite.tolist(), size.tolist(), strict=True):
        if ok and s > 0:
            groups.setdefault(_decimals(s), []).append(i)
    for decimals, members in groups.items():
        for lo, hi in runs([len(ds[i]) + 1 for i in members], block + 1):  # each text and a NUL
            # NUL is no part of a number: the texts come apart where they were joined
            chunk = members[lo:hi]
            for i, text in zip(
                chunk, _rounded("\0".join(ds[i] for i in chunk), decimals).split("\0"), strict=True
            ):
                out[i] = text
    return out


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
