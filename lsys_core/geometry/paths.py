"""Path geometry as arrays of cubic Bézier segments, and SVG path data in and out.

Every shape is kept as ``cubics``, a ``(k, 4)`` complex array of control points
``p0, c1, c2, p3`` per segment, with ``subpaths`` (``(k,)`` int: the subpath of
each segment, numbered from 0) and ``closed`` (one bool per subpath).  Lines
become cubics with control points at 1/3 and 2/3, quadratics are degree-elevated
exactly and arcs are approximated by cubics (error far below 1e-6 of the radius).
A closed subpath ends with an explicit segment back to its start (unless it
already ends there), so the segments alone describe the outline.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from lsys_core.errors import LimitError, SvgError
from lsys_core.geometry import pathdata as pd
from lsys_core.geometry.arcs import arc_cubics, arc_setup, fill_arcs
from lsys_core.geometry.pathdata import PathTable, parse_path, parse_paths

__all__ = [
    "ArrayPath",
    "arc_cubics",
    "arrays_from_table",
    "assemble",
    "collinear_thirds",
    "consecutive",
    "cubics_from_d",
    "cubics_from_table",
    "d_from_cubics",
    "path_from_d",
    "paths_from_ds",
]

#: Segment kinds collected while walking a path (converted to cubics at the end).
_LINE, _QUAD, _CUBIC = 0, 1, 2

#: Relative distance below which a closing segment is rounding noise.
_CLOSE_TOL = 1e-10

#: Largest coordinate magnitude accepted anywhere (import, terminal path data): beyond it, float
#: arithmetic on poses loses all precision.
MAX_COORD = 1e12

#: Default significant digits of numbers written into path data (relative error <= 5e-9).
DEFAULT_PRECISION = 9
#: Segments written at once by :func:`d_from_cubics`.
_WRITE_BLOCK = 1 << 15
#: Rows turned into cubics at once by :func:`_elevate`.
_ELEVATE_BLOCK = 1 << 16


def _empty() -> tuple[np.ndarray, np.ndarray, tuple[bool, ...]]:
    return np.zeros((0, 4), dtype=complex), np.zeros(0, dtype=np.intp), ()


class ArrayPath(NamedTuple):
    """One path as cubic arrays: ``cubics`` (k, 4), ``subpaths`` (k,) and ``closed`` per subpath."""

    cubics: np.ndarray
    subpaths: np.ndarray
    closed: tuple[bool, ...]


def path_from_d(d: str) -> tuple[ArrayPath, str | None]:
    """Parse path data leniently, as SVG draws it: up to the first error; return the error too."""
    table = parse_path(d)
    return ArrayPath(*cubics_from_table(table)), table.error


def paths_from_ds(ds: list[str]) -> list[tuple[ArrayPath, str | None]]:
    """Parse the path data of many paths in one pass (see :func:`path_from_d`)."""
    table = parse_paths(ds)
    return list(zip(arrays_from_table(table, len(ds)), table.errors, strict=True))


def assemble(paths: list[ArrayPath]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Concatenate paths into one cubic array.

    Returns
    -------
    cubics : ndarray of complex, shape (K, 4)
        The segments of all paths, one after another.
    subpaths : ndarray of int, shape (K,)
        Subpath of each segment within its own path.
    counts : ndarray of int, shape (len(paths),)
        Number of segments of each path.
    """
    counts = np.fromiter((p.cubics.shape[0] for p in paths), dtype=np.intp, count=len(paths))
    if int(counts.sum()) == 0:
        return np.zeros((0, 4), dtype=complex), np.zeros(0, dtype=np.intp), counts
    cubics = np.concatenate([p.cubics for p in paths])
    subpaths = np.concatenate([p.subpaths for p in paths]).astype(np.intp)
    return cubics, subpaths, counts


def _elevate(cubics: np.ndarray, kinds: np.ndarray) -> None:
    """Turn line and quadratic rows (``p0 p0 p3 p3`` / ``p0 q q p3``) into exact cubics, in place.

    Works in blocks of :data:`_ELEVATE_BLOCK` rows: the temporaries stay a few MiB for any path.
    """
    with np.errstate(invalid="ignore", over="ignore"):
        for lo in range(0, kinds.size, _ELEVATE_BLOCK):
            _elevate_rows(cubics[lo : lo + _ELEVATE_BLOCK], kinds[lo : lo + _ELEVATE_BLOCK])


def _elevate_rows(cubics: np.ndarray, kinds: np.ndarray) -> None:
    line = kinds == _LINE
    if line.any():
        p0, p3 = cubics[line, 0], cubics[line, 3]
        d = p3 - p0
        cubics[line, 1] = p0 + d / 3.0
        cubics[line, 2] = p0 + 2.0 * d / 3.0
    quad = kinds == _QUAD
    if quad.any():
        p0, q, p3 = cubics[quad, 0], cubics[quad, 1], cubics[quad, 3]
        cubics[quad, 1] = p0 + 2.0 / 3.0 * (q - p0)
        cubics[quad, 2] = p3 + 2.0 / 3.0 * (q - p3)


def cubics_from_table(table: PathTable) -> tuple[np.ndarray, np.ndarray, tuple[bool, ...]]:
    """Convert a parsed path (:func:`~lsys_core.geometry.pathdata.parse_path`) to cubic arrays.

    Moves and zero-length segments are dropped, arcs become cubics (a zero-radius arc a line), a
    ``Z`` adds the line back to the subpath's start unless the subpath ends there (within rounding
    noise, the last point is snapped to the start), and drawing after ``Z`` starts a new subpath.

    Returns
    -------
    cubics : ndarray of complex, shape (k, 4)
    subpaths : ndarray of int, shape (k,)
        Subpath of each segment, numbered from 0 (subpaths without segments are dropped).
    closed : tuple of bool
        Whether each subpath ends with ``Z``.
    """
    cub, sub, closed, _ = _convert(table)
    return cub, sub, tuple(closed)


def arrays_from_table(
    table: PathTable, n_paths: int, max_segments: int | None = None, name: str = "the path data"
) -> list[ArrayPath]:
    """Convert a table of several paths (:func:`~lsys_core.geometry.pathdata.parse_paths`).

    Returns one :class:`ArrayPath` per path (see :func:`cubics_from_table`); their arrays are
    views of one array.

    Raises
    ------
    LimitError
        The paths have more than ``max_segments`` cubic segments (checked before allocating them).
    """
    cub, sub, closed, seg_path = _convert(table, max_segments, name)
    bounds = np.searchsorted(seg_path, np.arange(n_paths + 1))
    # Subpaths are numbered per path: subtract each path's first subpath number.
    first_sub = np.append(sub, 0)[bounds[:-1]]
    sub = sub - np.repeat(first_sub, np.diff(bounds))
    # Each path's subpath count, and where its flags start, as plain lists: indexing numpy
    # scalars path by path was most of this function's 3 microseconds per path.
    n_sub = np.where(bounds[1:] > bounds[:-1], np.append(sub, 0)[np.maximum(bounds[1:] - 1, 0)] + 1, 0)
    sub_at = np.concatenate([[0], np.cumsum(n_sub)]).tolist()
    at = bounds.tolist()
    # Made by ``tuple.__new__`` (what the named tuple's own ``__new__`` calls, one Python call
    # less) over zipped bounds: 47 -> 36 ms for 50,052 paths.
    new = tuple.__new__
    return [
        new(ArrayPath, (cub[a:b], sub[a:b], tuple(closed[c:d])))
        for a, b, c, d in zip(at, at[1:], sub_at, sub_at[1:], strict=False)
    ]


def _convert(
    table: PathTable, max_segments: int | None = None, name: str = ""
) -> tuple[np.ndarray, np.ndarray, list[bool], np.ndarray]:
    """Rows to cubics: ``(cubics, subpath numbers, closed flag per subpath, path of each segment)``."""
    op, pts = table.op, table.pts
    n = op.size
    if n == 0:
        c, s, _ = _empty()
        return c, s, [], s
    is_move = op == pd.MOVE
    is_close = op == pd.CLOSE
    after_close = np.zeros(n, dtype=bool)
    after_close[1:] = is_close[:-1]
    begins = is_move | (after_close & ~is_move)
    sub = np.cumsum(begins) - 1
    # A closing segment within rounding noise of its start: snap the previous end point instead.
    cl = np.flatnonzero(is_close)
    if cl.size:
        p0, p3 = pts[cl, 0], pts[cl, 3]
        tiny = (p0 != p3) & (np.abs(p0 - p3) <= _CLOSE_TOL * np.maximum(np.abs(p0), np.abs(p3)))
        if tiny.any():
            pts = pts.copy()
            prev = cl - 1
            snap = tiny & (prev >= 0) & ~is_move[np.maximum(prev, 0)] & ~is_close[np.maximum(prev, 0)]
            pts[prev[snap], 3] = p3[snap]
            pts[cl[tiny], 0] = pts[cl[tiny], 3]
    kinds = np.full(n, _LINE, dtype=np.int8)
    kinds[op == pd.QUAD] = _QUAD
    kinds[op == pd.CUBIC] = _CUBIC
    arc_rows = np.flatnonzero(op == pd.ARC)  # table.arc has one row per arc row, in order
    rows = ~is_move
    degenerate = (pts[:, 0] == pts[:, 1]) & (pts[:, 1] == pts[:, 2]) & (pts[:, 2] == pts[:, 3])
    rows &= ~degenerate
    curved = np.zeros(0, dtype=np.intp)
    if arc_rows.size:
        rx, ry = np.abs(table.arc[:, 0]), np.abs(table.arc[:, 1])
        sel = (rx > 0) & (ry > 0) & ~degenerate[arc_rows]
        curved = arc_rows[sel]
        rows[curved] = False
    closed_sub = np.zeros(int(sub[-1]) + 1, dtype=bool)
    closed_sub[sub[is_close]] = True
    keep = np.flatnonzero(rows)
    if curved.size == 0:
        cub = pts[keep]
        _elevate(cub, kinds[keep])
        seg_row = keep
    else:
        # Every kept row takes one slot, every curved arc as many as it has pieces, in row order.
        setup = arc_setup(pts[curved, 0], pts[curved, 3], table.arc[sel])
        slots = rows.astype(np.intp)
        slots[curved] = setup.pieces
        offset = np.cumsum(slots) - slots
        if max_segments is not None and int(slots.sum()) > max_segments:
            raise LimitError(f"{name} has more than {max_segments:,} path segments")
        cub = np.empty((int(slots.sum()), 4), dtype=complex)
        plain = pts[keep]
        _elevate(plain, kinds[keep])
        cub[offset[keep]] = plain
        del plain
        fill_arcs(cub, offset[curved], setup, pts[curved, 0], pts[curved, 3])
        seg_row = np.repeat(np.arange(n), slots)
    seg_sub = sub[seg_row]
    del sub, keep
    change = np.ones(seg_sub.size, dtype=bool)
    change[1:] = seg_sub[1:] != seg_sub[:-1]  # subpath numbers never decrease: renumber the runs
    subpaths = np.cumsum(change)
    subpaths -= 1
    return cub, subpaths, closed_sub[seg_sub[change]].tolist(), table.path[seg_row]


def consecutive(arrays: list[np.ndarray]) -> np.ndarray | None:
    """The arrays one after another as a view, when they are consecutive pieces of one array.

    ``arrays`` are ``(k, 4)`` arrays (the elements of a scene are pieces of the array the reader
    placed them in); returns the view of the array that owns their memory that they tile, in
    order (empty ones aside), or None (then :func:`numpy.concatenate` is the way to join them).
    """
    full = [c for c in arrays if c.shape[0]]
    if not full:
        return None
    owner = full[0] if full[0].base is None else full[0].base
    if not isinstance(owner, np.ndarray) or not owner.flags.c_contiguous:
        return None
    size = owner.itemsize
    origin = owner.__array_interface__["data"][0]
    lo = at = full[0].__array_interface__["data"][0]
    for c in full:
        mine = c if c.base is None else c.base
        same = mine is owner and c.dtype == owner.dtype and c.ndim == 2 and c.shape[1] == 4
        if not same or not c.flags.c_contiguous or c.__array_interface__["data"][0] != at:
            return None
        at += c.nbytes
    return owner.reshape(-1)[(lo - origin) // size : (at - origin) // size].reshape(-1, 4)


def cubics_from_d(d: str) -> tuple[np.ndarray, np.ndarray, tuple[bool, ...]]:
    """Parse SVG path data into cubic arrays (see :func:`cubics_from_table`).

    Raises
    ------
    SvgError
        If the path data has an error anywhere (this reader is strict: it reads rule files).
    """
    table = parse_path(d)
    if table.error is not None:
        if table.error.startswith("a number beyond"):
            raise SvgError("path data has non-finite or huge coordinates")
        snippet = d if len(d) <= 40 else d[:37] + "..."
        raise SvgError(f"invalid path data {snippet!r}: {table.error}")
    return cubics_from_table(table)


def collinear_thirds(cubics: np.ndarray, tol) -> np.ndarray:
    """Return a mask of segments whose control points lie at 1/3 and 2/3 of the chord.

    Such a cubic is a straight segment drawn at constant speed (path data writes it ``L``).
    ``tol`` is a distance, one for all or one per segment.
    """
    p0, c1, c2, p3 = cubics.T
    d = p3 - p0
    return (np.abs(c1 - (p0 + d / 3.0)) <= tol) & (np.abs(c2 - (p0 + 2.0 * d / 3.0)) <= tol)


def d_from_cubics(
    cubics: np.ndarray,
    subpaths: np.ndarray | None = None,
    closed: tuple[bool, ...] | list[bool] = (),
    precision: int = DEFAULT_PRECISION,
) -> str:
    """Write cubic arrays as compact absolute SVG path data.

    Segments whose control points sit at 1/3 and 2/3 of their chord are written as
    ``L``; a closed subpath's final straight segment back to its start is written
    as ``Z``.  Numbers have ``precision`` significant digits (relative error at most
    ``0.5 * 10**(1 - precision)``), and values below ``1e-12`` of the path's extent
    are written as ``0``.

    Parameters
    ----------
    cubics : ndarray of complex, shape (k, 4)
    subpaths : ndarray of int, shape (k,), optional
        Subpath of each segment (default: one subpath).
    closed : sequence of bool
        Whether each subpath is closed (missing entries: open).
    precision : int
        Significant digits of the numbers written.

    Returns
    -------
    str
        Path data such as ``"M0 0 L10 0 C12 1 12 4 10 5 Z"`` (empty for no segments).
    """
    cubics = np.asarray(cubics, dtype=complex).reshape(-1, 4)
    k = len(cubics)
    if k == 0:
        return ""
    subpaths = np.zeros(k, dtype=np.intp) if subpaths is None else np.asarray(subpaths).reshape(k)
    blocks = [slice(lo, lo + _WRITE_BLOCK) for lo in range(0, k, _WRITE_BLOCK)]
    scale = float(np.max([np.abs(cubics[part]).max() for part in blocks])) or 1.0
    tol = 1e-9 * scale

    p_start = cubics[:, 0]
    first = np.ones(k, dtype=bool)
    first[1:] = (subpaths[1:] != subpaths[:-1]) | (np.abs(p_start[1:] - cubics[:-1, 3]) > tol)
    last = np.ones(k, dtype=bool)
    last[:-1] = subpaths[1:] != subpaths[:-1]
    is_line = collinear_thirds(cubics, tol)
    sub_start = p_start[first][np.cumsum(first) - 1]  # start of the contour of each segment
    n_sub = int(subpaths.max()) + 1
    closed_arr = np.zeros(n_sub, dtype=bool)
    flags = np.asarray(tuple(closed)[:n_sub], dtype=bool)
    closed_arr[: flags.size] = flags
    seg_closed = closed_arr[subpaths] & last
    # The last straight segment of a closed subpath, back to its start, is implied by Z
    # (unless it is the contour's only segment).
    as_z = seg_closed & is_line & (np.abs(cubics[:, 3] - sub_start) <= tol) & ~first

    num = f"%.{int(precision)}g"
    pair = f"{num} {num}"
    # Per segment, the numbers its commands write: start (M), controls (C), end (L, C).
    use_c = ~is_line & ~as_z
    mask = np.stack([first, use_c, use_c, ~as_z], axis=1)  # (k, 4) over p0, c1, c2, p3
    out = []
    for part in blocks:  # blocks: fixed-width string arrays of 10^6 segments take GiBs
        xy = np.stack([cubics[part].real, cubics[part].imag], axis=-1)  # (b, 4, 2)
        xy += 0.0  # turns -0.0 into 0.0
        xy[np.abs(xy) < 1e-12 * scale] = 0.0
        pieces = np.where(is_line[part], f"L{pair} ", f"C{pair} {pair} {pair} ")
        pieces[as_z[part]] = ""
        text = np.char.add(
            np.char.add(np.where(first[part], f"M{pair} ", ""), pieces), np.where(seg_closed[part], "Z ", "")
        )
        values = xy[mask[part]]  # row-major: segment by segment, points in order
        out.append("".join(text.tolist()) % tuple(values.ravel().tolist()))
    out[-1] = out[-1].rstrip()  # every segment writes a command: only the last piece ends in blanks
    return "".join(out)
