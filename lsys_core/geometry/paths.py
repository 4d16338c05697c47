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
from lsys_core.geometry.pathdata import PathTable, parse_path, parse_paths

__all__ = [
    "ArrayPath",
    "RawPath",
    "arc_cubics",
    "arrays_from_table",
    "assemble",
    "cubics_from_d",
    "cubics_from_path",
    "cubics_from_table",
    "d_from_cubics",
    "path_from_d",
    "paths_from_ds",
    "raw_from_segments",
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
#: Exceptions svgelements raises on values it cannot handle (shared with the importer).
SVGELEMENTS_ERRORS = (
    ValueError,
    TypeError,
    IndexError,
    KeyError,
    AttributeError,
    ZeroDivisionError,
    OverflowError,
)


class RawPath(NamedTuple):
    """Segments collected from path data before conversion to arrays.

    ``pts`` holds one 4-tuple of complex per segment: ``p0 c1 c2 p3`` for cubics,
    ``p0 q q p3`` for quadratics and ``p0 p0 p3 p3`` for lines (``kinds`` says which);
    ``subs`` the subpath of each segment and ``closed`` one flag per subpath.
    """

    kinds: list[int]
    pts: list[tuple[complex, complex, complex, complex]]
    subs: list[int]
    closed: list[bool]


def _empty() -> tuple[np.ndarray, np.ndarray, tuple[bool, ...]]:
    return np.zeros((0, 4), dtype=complex), np.zeros(0, dtype=np.intp), ()


def _close(raw: RawPath, cur: complex, start: complex) -> None:
    """Close the current subpath: add a line back to ``start`` unless it ends there."""
    if abs(cur - start) > _CLOSE_TOL * max(abs(cur), abs(start)):
        raw.kinds.append(_LINE)
        raw.pts.append((cur, cur, start, start))
        raw.subs.append(len(raw.closed) - 1)
    elif cur != start:  # rounding noise (e.g. after arcs): end exactly at the start
        last = raw.pts[-1]
        raw.pts[-1] = (last[0], last[1], last[2], start)
    raw.closed[-1] = True


def raw_from_segments(path) -> RawPath:
    """Collect the segments of an svgelements path (or iterable of its segments).

    Zero-length segments and subpaths without segments are dropped; arcs are
    converted to cubics (a zero-radius arc to a line).
    """
    from svgelements import Arc, Close, CubicBezier, Move, QuadraticBezier

    raw = RawPath([], [], [], [])
    kinds, pts, subs, closed = raw
    start = 0j  # start point of the current subpath
    pending = True  # a new subpath begins with the next drawn segment
    for seg in path:
        kind = type(seg)
        if kind is Move:
            end = seg.end
            start = complex(end.x, end.y)
            pending = True
            continue
        if seg.start is None or seg.end is None:
            continue
        p0 = complex(seg.start.x, seg.start.y)
        p3 = complex(seg.end.x, seg.end.y)
        if kind is Close:
            if not pending:
                _close(raw, p0, start)
            pending = True  # drawing after Z starts a new subpath at the same point
            continue
        if kind is CubicBezier:
            c1, c2 = seg.control1, seg.control2
            row = (p0, complex(c1.x, c1.y), complex(c2.x, c2.y), p3)
            code = _CUBIC
        elif kind is QuadraticBezier:
            c = complex(seg.control.x, seg.control.y)
            row = (p0, c, c, p3)
            code = _QUAD
        elif kind is Arc:
            curves = list(seg.as_cubic_curves()) if seg.rx and seg.ry else []
            if curves:
                if pending:
                    closed.append(False)
                    pending = False
                    start = p0
                for cb in curves:
                    kinds.append(_CUBIC)
                    pts.append(
                        (
                            complex(cb.start.x, cb.start.y),
                            complex(cb.control1.x, cb.control1.y),
                            complex(cb.control2.x, cb.control2.y),
                            complex(cb.end.x, cb.end.y),
                        )
                    )
                    subs.append(len(closed) - 1)
                continue
            row = (p0, p0, p3, p3)  # zero radius: the arc is a straight line (SVG 1.1 F.6.2)
            code = _LINE
        else:  # Line and any other linear segment
            row = (p0, p0, p3, p3)
            code = _LINE
        if row[0] == row[1] == row[2] == row[3]:
            continue
        if pending:
            closed.append(False)
            pending = False
            start = p0
        kinds.append(code)
        pts.append(row)
        subs.append(len(closed) - 1)
    return raw


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


def _to_arrays(raw: RawPath) -> tuple[np.ndarray, np.ndarray, tuple[bool, ...]]:
    if not raw.pts:
        return _empty()
    cubics = np.array(raw.pts, dtype=complex).reshape(-1, 4)
    _elevate(cubics, np.array(raw.kinds, dtype=np.int8))
    return cubics, np.array(raw.subs, dtype=np.intp), tuple(raw.closed)


def cubics_from_path(path) -> tuple[np.ndarray, np.ndarray, tuple[bool, ...]]:
    """Convert an svgelements path (or any iterable of its segments) to cubic arrays.

    Parameters
    ----------
    path : svgelements.Path or iterable of svgelements segments
        The path, with its transform already applied to the points.

    Returns
    -------
    cubics : ndarray of complex, shape (k, 4)
        Control points of every drawn segment; zero-length segments are dropped.
    subpaths : ndarray of int, shape (k,)
        Subpath index of each segment (subpaths without segments are dropped).
    closed : tuple of bool
        Whether each subpath ends with ``Z``.  A closing segment back to the
        subpath's start is added to ``cubics`` when the subpath does not end there.
    """
    return _to_arrays(raw_from_segments(path))


def _elevate(cubics: np.ndarray, kinds: np.ndarray) -> None:
    """Turn line and quadratic rows (``p0 p0 p3 p3`` / ``p0 q q p3``) into exact cubics, in place."""
    with np.errstate(invalid="ignore", over="ignore"):
        _elevate_rows(cubics, kinds)


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
    out = []
    sub_lo = 0
    for p in range(n_paths):
        a, b = int(bounds[p]), int(bounds[p + 1])
        n_sub = int(sub[b - 1]) + 1 if b > a else 0
        out.append(ArrayPath(cub[a:b], sub[a:b], tuple(closed[sub_lo : sub_lo + n_sub])))
        sub_lo += n_sub
    return out


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
        setup = _arc_setup(pts[curved, 0], pts[curved, 3], table.arc[sel])
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
        _fill_arcs(cub, offset[curved], setup, pts[curved, 0], pts[curved, 3])
        seg_row = np.repeat(np.arange(n), slots)
    seg_sub = sub[seg_row]
    change = np.ones(seg_sub.size, dtype=bool)
    change[1:] = seg_sub[1:] != seg_sub[:-1]  # subpath numbers never decrease: renumber the runs
    subpaths = np.cumsum(change) - 1
    return cub, subpaths, closed_sub[seg_sub[change]].tolist(), table.path[seg_row]


#: Arcs converted at a time (bounds the temporary memory of the conversion).
_ARC_CHUNK = 65536


class _ArcSetup(NamedTuple):
    """Centre parameterisation of arcs (SVG F.6.5) and the number of cubic pieces of each."""

    cx: np.ndarray
    cy: np.ndarray
    rx: np.ndarray
    ry: np.ndarray
    cphi: np.ndarray
    sphi: np.ndarray
    theta1: np.ndarray
    dtheta: np.ndarray
    pieces: np.ndarray


def _arc_setup(p0: np.ndarray, p3: np.ndarray, arc: np.ndarray) -> _ArcSetup:
    """Convert endpoint to centre parameterisation (radii grown where too small), vectorised."""
    rx, ry = np.abs(arc[:, 0]), np.abs(arc[:, 1])
    phi = np.deg2rad(np.mod(arc[:, 2], 360.0))
    large, sweep = arc[:, 3] != 0, arc[:, 4] != 0
    cphi, sphi = np.cos(phi), np.sin(phi)
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        hx, hy = (p0.real - p3.real) / 2.0, (p0.imag - p3.imag) / 2.0
        x1, y1 = cphi * hx + sphi * hy, -sphi * hx + cphi * hy
        grow = np.sqrt(np.maximum((x1 / rx) ** 2 + (y1 / ry) ** 2, 1.0))
        rx, ry = rx * grow, ry * grow
        num = (rx * ry) ** 2 - (rx * y1) ** 2 - (ry * x1) ** 2
        den = (rx * y1) ** 2 + (ry * x1) ** 2
        coef = np.sqrt(np.maximum(num / den, 0.0))
        coef = np.where(large == sweep, -coef, coef)
        cxp, cyp = coef * rx * y1 / ry, -coef * ry * x1 / rx
        cx = cphi * cxp - sphi * cyp + (p0.real + p3.real) / 2.0
        cy = sphi * cxp + cphi * cyp + (p0.imag + p3.imag) / 2.0
        theta1 = np.arctan2((y1 - cyp) / ry, (x1 - cxp) / rx)
        theta2 = np.arctan2((-y1 - cyp) / ry, (-x1 - cxp) / rx)
        dtheta = np.mod(theta2 - theta1, 2 * np.pi)
        dtheta = np.where(~sweep & (dtheta > 0), dtheta - 2 * np.pi, dtheta)
        dtheta = np.where(np.isfinite(dtheta), dtheta, 0.0)
        count = np.maximum(np.ceil(np.abs(dtheta) / (np.pi / 4) - 1e-9), 1).astype(np.intp)
    return _ArcSetup(cx, cy, rx, ry, cphi, sphi, theta1, dtheta, count)


def _arc_pieces(a: _ArcSetup, p0: np.ndarray, p3: np.ndarray) -> np.ndarray:
    """Return the cubic pieces of arcs (all pieces of the first arc, then of the next...)."""
    count = a.pieces
    # Boundary angles: count + 1 per arc; piece j of an arc runs from boundary j to j + 1.
    nb = count + 1
    own = np.repeat(np.arange(count.size), nb)
    j = np.arange(own.size) - np.repeat(np.cumsum(nb) - nb, nb)
    delta = a.dtheta / count
    ang = a.theta1[own] + j * delta[own]
    ca, sa = np.cos(ang), np.sin(ang)
    rx, ry, c, s = a.rx[own], a.ry[own], a.cphi[own], a.sphi[own]
    with np.errstate(invalid="ignore", over="ignore"):
        ex, ey = rx * ca, ry * sa  # point on the axis-aligned ellipse
        dx, dy = -rx * sa, ry * ca  # its tangent (per radian)
        pt = (a.cx[own] + c * ex - s * ey) + 1j * (a.cy[own] + s * ex + c * ey)
        tan = (c * dx - s * dy) + 1j * (s * dx + c * dy)
        k = (4.0 / 3.0 * np.tan(delta / 4.0))[own]
    is_start = np.ones(own.size, dtype=bool)
    is_start[np.cumsum(nb) - 1] = False
    b = np.flatnonzero(is_start)  # the boundary starting each piece
    cubics = np.empty((b.size, 4), dtype=complex)
    with np.errstate(invalid="ignore", over="ignore"):
        cubics[:, 0] = pt[b]
        cubics[:, 1] = pt[b] + k[b] * tan[b]
        cubics[:, 2] = pt[b + 1] - k[b] * tan[b + 1]
        cubics[:, 3] = pt[b + 1]
    first = np.cumsum(count) - count
    cubics[first, 0] = p0  # exact end points
    cubics[first + count - 1, 3] = p3
    return cubics


def _slice_setup(a: _ArcSetup, sl: slice) -> _ArcSetup:
    return _ArcSetup(*(f[sl] for f in a))


def arc_cubics(p0: np.ndarray, p3: np.ndarray, arc: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Approximate elliptical arcs (SVG endpoint parameterisation) by cubics, vectorised.

    Parameters
    ----------
    p0, p3 : ndarray of complex, shape (n,)
        Start and end points (distinct); radii must be non-zero.
    arc : ndarray, shape (n, 5)
        ``rx ry phi(degrees) large-arc-flag sweep-flag`` per arc.

    Returns
    -------
    cubics : ndarray of complex, shape (m, 4)
        Pieces of at most 45 degrees each (error below 5e-6 of the radius).
    owner : ndarray of int, shape (m,)
        The arc each piece belongs to (pieces of one arc are consecutive, in drawing order).
    """
    setup = _arc_setup(p0, p3, arc)
    cubics = np.empty((int(setup.pieces.sum()), 4), dtype=complex)
    _fill_arcs(cubics, np.cumsum(setup.pieces) - setup.pieces, setup, p0, p3)
    return cubics, np.repeat(np.arange(p0.size), setup.pieces)


def _fill_arcs(out: np.ndarray, slot: np.ndarray, setup: _ArcSetup, p0: np.ndarray, p3: np.ndarray) -> None:
    """Write the pieces of every arc into ``out`` from row ``slot[i]`` on, a chunk of arcs at a time."""
    for i in range(0, p0.size, _ARC_CHUNK):
        sl = slice(i, i + _ARC_CHUNK)
        part = _slice_setup(setup, sl)
        pieces = _arc_pieces(part, p0[sl], p3[sl])
        within = np.arange(pieces.shape[0]) - np.repeat(np.cumsum(part.pieces) - part.pieces, part.pieces)
        out[np.repeat(slot[sl], part.pieces) + within] = pieces


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


def _collinear_thirds(cubics: np.ndarray, tol: float) -> np.ndarray:
    """Return a mask of segments whose control points lie at 1/3 and 2/3 of the chord."""
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
    scale = float(np.max(np.abs(cubics))) or 1.0
    tol = 1e-9 * scale
    xy = np.stack([cubics.real, cubics.imag], axis=-1) + 0.0  # (k, 4, 2); + 0.0 turns -0.0 into 0.0
    xy[np.abs(xy) < 1e-12 * scale] = 0.0

    p_start = cubics[:, 0]
    first = np.ones(k, dtype=bool)
    first[1:] = (subpaths[1:] != subpaths[:-1]) | (np.abs(p_start[1:] - cubics[:-1, 3]) > tol)
    last = np.ones(k, dtype=bool)
    last[:-1] = subpaths[1:] != subpaths[:-1]
    is_line = _collinear_thirds(cubics, tol)
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
    pieces = np.where(is_line, f"L{pair} ", f"C{pair} {pair} {pair} ")
    pieces[as_z] = ""
    text = np.char.add(np.char.add(np.where(first, f"M{pair} ", ""), pieces), np.where(seg_closed, "Z ", ""))
    template = "".join(text.tolist())
    # Per segment, the numbers its commands write: start (M), controls (C), end (L, C).
    use_c = ~is_line & ~as_z
    mask = np.stack([first, use_c, use_c, ~as_z], axis=1)  # (k, 4) over p0, c1, c2, p3
    values = xy[mask]  # row-major: segment by segment, points in order
    return (template % tuple(values.ravel().tolist())).rstrip()
