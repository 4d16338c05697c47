"""Terminal shapes parsed once: cubic arrays of path data, cached by the path text.

A terminal keeps its shape as SVG path data (what the ``.lsys`` file says is what is drawn), and
many stages need its arrays: fidelity and shape similarity, pivots, validation, SVG export and
raster rendering.  :func:`shape_arrays` parses each distinct path text once and hands every later
caller the same read-only arrays.  The cache is bounded by the number of segments it holds, so a
session that edits many shapes does not grow without limit; a shape larger than that bound is
kept alone in a slot of its own (the last one asked for), since a scene of one huge path asks
for it from several stages (seven parses of a 10^6-line path took 14 s of a 35 s inference).
"""

from __future__ import annotations

import re
import threading
from collections import OrderedDict
from collections.abc import Sequence

import numpy as np

from lsys_core.geometry.pathdata import parse_paths
from lsys_core.geometry.paths import arrays_from_table, cubics_from_d
from lsys_core.parallel import runs

__all__ = ["CACHE_SEGMENTS", "PASS_CHARS", "ptp_at", "shape_arrays", "shapes_arrays"]

#: Characters of path data parsed in one pass by :func:`shapes_arrays` (the lexer's temporaries
#: are some 30 bytes a character: 1.2 MB of texts in one pass peaked at 40 MiB).
PASS_CHARS = 1 << 16
#: Segments kept in the cache at most (about 72 bytes each); a larger shape has a slot of its own.
CACHE_SEGMENTS = 250_000

_Arrays = tuple[np.ndarray, np.ndarray, tuple[bool, ...]]

_cache: OrderedDict[str, _Arrays] = OrderedDict()
_held = 0  # segments in the cache
_large: tuple[str, _Arrays] | None = None  # the last shape too large for the cache
_lock = threading.Lock()  # the editor renders while a worker thread infers
#: A character that is not part of absolute ``M``/``L``/``C``/``Z`` path data.
_NOT_ABSOLUTE = re.compile(r"[^MLCZ0-9eE.+\-,\s]")


def shape_arrays(d: str) -> _Arrays:
    """Return the cubic arrays of path data ``d``, parsing each distinct text only once.

    Parameters
    ----------
    d : str
        SVG path data; blank text is an empty shape.

    Returns
    -------
    cubics : ndarray of complex, shape (k, 4)
    subpaths : ndarray of int, shape (k,)
    closed : tuple of bool
        As :func:`~lsys_core.geometry.paths.cubics_from_d` returns them, but read-only: they are
        shared by every caller asking for the same text.

    Raises
    ------
    SvgError
        If the path data cannot be parsed (not cached: every call raises again).
    """
    hit = _cached(d)
    if hit is not None:
        return hit
    if d.strip():
        cubics, subpaths, closed = cubics_from_d(d)
    else:
        cubics, subpaths, closed = np.zeros((0, 4), complex), np.zeros(0, np.intp), ()
    cubics.setflags(write=False)
    subpaths.setflags(write=False)
    return _keep(d, (cubics, subpaths, closed))


def _cached(d: str) -> _Arrays | None:
    """The arrays of ``d`` if they are cached (the cache's most recent entry from now on)."""
    with _lock:
        hit = _cache.get(d)
        if hit is not None:
            _cache.move_to_end(d)
            return hit
        if _large is not None and _large[0] == d:
            return _large[1]
    return None


def _keep(d: str, arrays: _Arrays) -> _Arrays:
    """Put the read-only arrays of ``d`` into the cache (or the large slot) and return them."""
    global _held, _large
    k = len(arrays[0])
    if k > CACHE_SEGMENTS:
        with _lock:
            _large = (d, arrays)
        return arrays
    with _lock:
        if d not in _cache:
            _cache[d] = arrays
            _held += k
            while _held > CACHE_SEGMENTS:
                _, old = _cache.popitem(last=False)
                _held -= len(old[0])
    return arrays


def shapes_arrays(ds: Sequence[str]) -> list[_Arrays | None]:
    """Return the cubic arrays of many path data texts, parsing the new absolute ones in one pass.

    Parameters
    ----------
    ds : sequence of str
        SVG path data texts.

    Returns
    -------
    list
        Per text, what :func:`shape_arrays` returns for it, or None where it raises
        (unreadable path data).
    """
    out: list[_Arrays | None] = [None] * len(ds)
    batch: dict[str, list[int]] = {}
    for i, d in enumerate(ds):
        hit = _cached(d)
        if hit is not None:
            out[i] = hit
        elif d.strip() and _NOT_ABSOLUTE.search(d) is None:
            batch.setdefault(d, []).append(i)
        else:
            out[i] = _one(d)
    texts = list(batch)
    for lo, hi in runs([len(d) + 1 for d in texts], PASS_CHARS + 1):  # each text and a separator
        _parse_pass(texts[lo:hi], batch, out)
    return out


def _parse_pass(texts: list[str], where: dict[str, list[int]], out: list[_Arrays | None]) -> None:
    """Parse absolute texts together; put each one's arrays at its places ``where[d]`` in ``out``."""
    table = parse_paths(texts)
    for d, error, path in zip(texts, table.errors, arrays_from_table(table, len(texts)), strict=True):
        if error is not None:
            arrays = _one(d)  # raises the reader's error, or reads what the pass refused
        else:
            # copies: a cached shape owns its memory, not a view of the whole pass's array
            cubics, subpaths = path.cubics.copy(), path.subpaths.copy()
            cubics.setflags(write=False)
            subpaths.setflags(write=False)
            arrays = _keep(d, (cubics, subpaths, path.closed))
        for i in where[d]:
            out[i] = arrays


def _one(d: str) -> _Arrays | None:
    try:
        return shape_arrays(d)
    except Exception:  # unreadable path data (as primitive() and compact_path_data() treat it)
        return None


def ptp_at(values: np.ndarray, starts: np.ndarray) -> np.ndarray:
    """Peak to peak of each ``(k, 4)`` block of rows (a shape's segments) starting at ``starts`` (exact: max - min)."""
    return np.maximum.reduceat(values.max(axis=1), starts) - np.minimum.reduceat(values.min(axis=1), starts)
