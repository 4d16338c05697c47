"""Paths and paints for :mod:`lsys_core.render.raster`: styles, terminal outlines, batched geometry.

The helpers turn a terminal's SVG path data and CSS style into arrays and skia objects,
flatten and tile outlines for draft mode, and find the runs of non-overlapping instances
that full mode may draw as batched paths.  skia is imported inside the functions.
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from lsys_core.derive.paint import css_decls as parse_style  # one splitter of style text
from lsys_core.errors import LsysError

#: In draft mode, a curve needing more lines than this is left to skia's own subdivision.
DRAFT_MAX_LINES = 8
#: Full mode stops looking for runs of disjoint instances when boxes sharing a grid cell would give more than this
#: many candidate pairs per instance (a dense scene, where runs would be short anyway).
FULL_MAX_PAIRS = 8

_VERB_MOVE, _VERB_LINE, _VERB_CUBIC, _VERB_CLOSE = 0, 1, 4, 5
_BUCKETS_PER_OCTAVE = 4  # draft mode groups instances by scale in quarter octaves


def _number(text: str | None, default: float) -> float:
    if text is None:
        return default
    t = text.strip().lower().removesuffix("px")
    try:
        if t.endswith("%"):
            v = float(t[:-1]) / 100.0
        else:
            v = float(t)
    except ValueError:
        return default
    return v if math.isfinite(v) else default


@lru_cache(maxsize=256)
def _rgba(color: str, opacity: float) -> tuple[int, int, int, int] | None:
    """Parse a CSS colour into RGBA bytes with ``opacity`` applied; None for ``none``."""
    c = color.strip()
    if not c or c.lower() in ("none", "transparent"):
        return None
    from svgelements import Color

    col = Color(c)
    if col.value is None:
        return None
    alpha = col.alpha * max(0.0, min(1.0, opacity))
    return (col.red, col.green, col.blue, round(alpha))


@dataclass
class _Paints:
    """What a style draws: fill and stroke colours and stroke geometry."""

    fill: tuple[int, int, int, int] | None
    stroke: tuple[int, int, int, int] | None
    width: float
    cap: str
    join: str
    miter: float
    evenodd: bool


@lru_cache(maxsize=1024)
def _paints(style: str) -> _Paints:
    """Interpret a terminal's style as SVG would (fill black and no stroke by default)."""
    decl = parse_style(style)
    opacity = max(0.0, min(1.0, _number(decl.get("opacity"), 1.0)))
    fill = _rgba(decl.get("fill", "black"), opacity * _number(decl.get("fill-opacity"), 1.0))
    stroke = _rgba(decl.get("stroke", "none"), opacity * _number(decl.get("stroke-opacity"), 1.0))
    width = max(0.0, _number(decl.get("stroke-width"), 1.0))
    if width == 0.0:
        stroke = None
    return _Paints(
        fill=fill if fill is None or fill[3] > 0 else None,
        stroke=stroke if stroke is None or stroke[3] > 0 else None,
        width=width,
        cap=decl.get("stroke-linecap", "butt").lower(),
        join=decl.get("stroke-linejoin", "miter").lower(),
        miter=max(1.0, _number(decl.get("stroke-miterlimit"), 4.0)),
        evenodd=decl.get("fill-rule", "nonzero").lower() == "evenodd",
    )


def _skia_paint(rgba, antialias: bool, stroke: _Paints | None = None, width: float = 1.0):
    import skia

    paint = skia.Paint()
    paint.setAntiAlias(antialias)
    r, g, b, a = rgba
    paint.setARGB(a, r, g, b)
    if stroke is None:
        paint.setStyle(skia.Paint.kFill_Style)
        return paint
    paint.setStyle(skia.Paint.kStroke_Style)
    paint.setStrokeWidth(width)
    paint.setStrokeCap(
        {"round": skia.Paint.kRound_Cap, "square": skia.Paint.kSquare_Cap}.get(
            stroke.cap, skia.Paint.kButt_Cap
        )
    )
    paint.setStrokeJoin(
        {"round": skia.Paint.kRound_Join, "bevel": skia.Paint.kBevel_Join}.get(
            stroke.join, skia.Paint.kMiter_Join
        )
    )
    paint.setStrokeMiter(stroke.miter)
    return paint


# ---------------------------------------------------------------------------
# Building skia paths from arrays


@dataclass
class _Geometry:
    """A terminal's outline as skia path ingredients in its local frame.

    ``points``/``verbs`` keep every curve; the per-segment arrays let :func:`_flatten`
    replace curves by lines for a given scale.
    """

    points: np.ndarray  # complex, (m,)
    verbs: np.ndarray  # uint8, (v,)
    radius: float  # max |p| of the control points (for culling)
    cubics: np.ndarray  # complex, (k, 4): the segments
    first: np.ndarray  # bool, (k,): segment starts a contour (a move precedes it)
    closed: np.ndarray  # bool, (k,): a close follows the segment
    is_line: np.ndarray  # bool, (k,): segment is straight
    bend: np.ndarray  # float, (k,): max |second difference| of the control points


_EMPTY = _Geometry(
    np.zeros(0, complex),
    np.zeros(0, np.uint8),
    0.0,
    np.zeros((0, 4), complex),
    *(np.zeros(0, bool),) * 3,
    np.zeros(0),
)


def _geometry(d: str) -> _Geometry:
    """Turn path data into skia points and verbs (lines where control points sit at thirds)."""
    from lsys_core.geometry.paths import collinear_thirds
    from lsys_core.geometry.shapes import shape_arrays

    try:
        cubics, subpaths, closed = shape_arrays(d)
    except LsysError:
        return _EMPTY
    k = len(cubics)
    if k == 0 or not np.isfinite(cubics).all():
        return _EMPTY
    scale = float(np.abs(cubics).max()) or 1.0
    is_line = collinear_thirds(cubics, 1e-9 * scale)
    first = np.ones(k, dtype=bool)
    first[1:] = (subpaths[1:] != subpaths[:-1]) | (cubics[1:, 0] != cubics[:-1, 3])
    last = np.ones(k, dtype=bool)
    last[:-1] = first[1:]
    flags = np.asarray(closed, dtype=bool)
    seg_closed = last & (flags[subpaths] if flags.size else False)
    # Per segment: optional move, then line (1 point) or cubic (3 points), then optional close.
    pts_mask = np.zeros((k, 4), dtype=bool)
    pts_mask[:, 0] = first
    pts_mask[:, 1] = ~is_line
    pts_mask[:, 2] = ~is_line
    pts_mask[:, 3] = True
    points = cubics[pts_mask]
    v = np.where(is_line, _VERB_LINE, _VERB_CUBIC)
    parts = np.stack([np.where(first, _VERB_MOVE, -1), v, np.where(seg_closed, _VERB_CLOSE, -1)], axis=1)
    verbs = parts[parts >= 0].astype(np.uint8)
    second = np.abs(cubics[:, :2] - 2 * cubics[:, 1:3] + cubics[:, 2:])
    return _Geometry(
        points, verbs, float(np.abs(points).max()), cubics, first, seg_closed, is_line, second.max(axis=1)
    )


def _flatten(geo: _Geometry, scale: float, tolerance: float) -> tuple[np.ndarray, np.ndarray]:
    """Return points and verbs of ``geo`` with curves replaced by lines where few lines do.

    A curve drawn at ``scale`` pixels per unit is split into ``n`` equal parameter steps, with
    ``n`` from Wang's formula (chords within ``tolerance`` pixels of the curve); when ``n``
    exceeds :data:`DRAFT_MAX_LINES` the curve is kept and skia subdivides it.
    """
    k = len(geo.cubics)
    if k == 0:
        return geo.points, geo.verbs
    with np.errstate(invalid="ignore", over="ignore"):
        need = np.sqrt(0.75 * geo.bend * (scale / tolerance))
    n = np.where(geo.is_line, 1, np.ceil(np.nan_to_num(need, nan=np.inf, posinf=np.inf).clip(1, 1e6)))
    curve = n > DRAFT_MAX_LINES  # kept as a cubic: 3 points, one verb
    n = np.where(curve, 3, n).astype(np.intp)  # points of the segment after its optional move
    first = geo.first.astype(np.intp)
    # points
    starts = np.concatenate([[0], np.cumsum(first + n)[:-1]])
    body = starts + first
    points = np.empty(int(starts[-1] + first[-1] + n[-1]), complex)
    points[starts[geo.first]] = geo.cubics[geo.first, 0]
    seg = np.repeat(np.arange(k), n)
    step = np.arange(seg.size) - np.repeat(np.cumsum(n) - n, n)  # 0 .. n-1 within each segment
    t = (step + 1) / n[seg]
    c = geo.cubics[seg]
    u = 1.0 - t
    on_curve = u**3 * c[:, 0] + 3 * u * u * t * c[:, 1] + 3 * u * t * t * c[:, 2] + t**3 * c[:, 3]
    control = c[np.arange(seg.size), np.minimum(step + 1, 3)]  # a kept cubic's c1, c2, end
    points[body[seg] + step] = np.where(curve[seg], control, on_curve)
    # verbs
    lines = np.where(curve, 1, n)
    closes = geo.closed.astype(np.intp)
    vstarts = np.concatenate([[0], np.cumsum(first + lines + closes)[:-1]])
    verbs = np.empty(int(vstarts[-1] + first[-1] + lines[-1] + closes[-1]), np.uint8)
    verbs[vstarts[geo.first]] = _VERB_MOVE
    vseg = np.repeat(np.arange(k), lines)
    vstep = np.arange(vseg.size) - np.repeat(np.cumsum(lines) - lines, lines)
    verbs[vstarts[vseg] + first[vseg] + vstep] = np.where(curve[vseg], _VERB_CUBIC, _VERB_LINE)
    verbs[(vstarts + first + lines)[geo.closed]] = _VERB_CLOSE
    return points, verbs


def _groups(symbol: np.ndarray, bucket: np.ndarray) -> list[np.ndarray]:
    """Split positions into groups of equal ``(symbol, bucket)``, each in increasing order."""
    if symbol.size == 0:
        return []
    s0, b0 = symbol.min(), bucket.min()
    key = (symbol - s0) * (int(bucket.max() - b0) + 1) + (bucket - b0)
    if key.max() == key.min():
        return [np.arange(symbol.size)]
    if key.max() < np.iinfo(np.int16).max:
        key = key.astype(np.int16)  # a stable sort of small integers is a radix sort
    order = np.argsort(key, kind="stable")
    cuts = np.flatnonzero(np.diff(key[order])) + 1
    return np.split(order, cuts)


def _rectangles_overlap(d: np.ndarray, u1, w1, h1, u2, w2, h2) -> np.ndarray:
    """Return whether rectangles overlap or touch (separating axis test along their four sides).

    Rectangle ``k`` has half sides ``w_k`` along the unit direction ``u_k`` and ``h_k`` across it;
    their centres are ``d`` apart (complex numbers as points and directions).
    """
    rel = u2 * u1.conjugate()
    c, s = np.abs(rel.real), np.abs(rel.imag)
    d1 = d * u1.conjugate()  # d in the frame of rectangle 1
    d2 = d * u2.conjugate()
    return (
        (np.abs(d1.real) <= w1 + w2 * c + h2 * s)
        & (np.abs(d1.imag) <= h1 + w2 * s + h2 * c)
        & (np.abs(d2.real) <= w2 + w1 * c + h1 * s)
        & (np.abs(d2.imag) <= h2 + w1 * s + h1 * c)
    )


def _disjoint_runs(
    center: np.ndarray, u: np.ndarray, w: np.ndarray, h: np.ndarray, min_length: int
) -> list[tuple[int, int]]:
    """Return ``(start, stop)`` of the runs of consecutive rectangles that pairwise do not overlap.

    Rectangle ``k`` is centred on ``center[k]`` with half sides ``w[k]`` along the unit direction
    ``u[k]`` and ``h[k]`` across it (complex numbers as points and directions).  Rectangles are
    cut greedily into maximal runs, in order: a run ends before the first rectangle that overlaps
    (or touches) an earlier one of the run; only runs of at least ``min_length`` are returned.
    Pairs to test are found through a grid of cells as large as a typical axis-aligned bound, so
    the work stays linear; a rectangle spanning more than three cells a side counts as overlapping
    its neighbours in the order, and a scene whose bounds crowd the cells (more than
    :data:`FULL_MAX_PAIRS` candidate pairs per rectangle) has no runs.
    """
    n = center.size
    if n < max(min_length, 2):
        return [(0, n)] if 0 < n >= min_length else []
    ex = w * np.abs(u.real) + h * np.abs(u.imag)
    ey = w * np.abs(u.imag) + h * np.abs(u.real)
    x0, x1 = center.real - ex, center.real + ex
    y0, y1 = center.imag - ey, center.imag + ey
    cell = max(2 * float(np.median(ex)), 2 * float(np.median(ey)), 0.25)  # pixels
    if not math.isfinite(cell):
        return []
    gx0, gy0 = np.floor(x0 / cell), np.floor(y0 / cell)
    gx1, gy1 = np.floor(x1 / cell), np.floor(y1 / cell)
    small = (gx1 - gx0 <= 2) & (gy1 - gy0 <= 2)
    if not small.any():
        return []
    ox, oy = gx0[small].min(), gy0[small].min()
    cols = int(gy1[small].max() - oy) + 1
    if (gx1[small].max() - ox + 3) * (cols + 3) * n >= 2.0**62:  # cell keys would overflow
        return []
    # (cell, rectangle) entries of the small ones, up to 3 x 3 cells each, sorted by cell then rectangle
    keys = []
    for dx in range(3):
        for dy in range(3):
            m = np.flatnonzero(small & (gx0 + dx <= gx1) & (gy0 + dy <= gy1))
            keys.append(((gx0[m] + dx - ox) * cols + (gy0[m] + dy - oy)).astype(np.int64) * n + m)
    cell_of, box = np.divmod(np.sort(np.concatenate(keys)), n)
    # candidate pairs: every two rectangles sharing a cell
    starts = np.flatnonzero(np.r_[True, cell_of[1:] != cell_of[:-1]])
    sizes = np.diff(np.r_[starts, cell_of.size])
    if int((sizes * (sizes - 1) // 2).sum()) > FULL_MAX_PAIRS * n:
        return []
    later = np.repeat(starts + sizes, sizes) - np.arange(cell_of.size) - 1  # entries after each
    first = np.repeat(np.arange(cell_of.size), later)
    second = first + 1 + np.arange(first.size) - np.repeat(np.cumsum(later) - later, later)
    i, j = box[first], box[second]  # i < j
    hit = (x0[i] <= x1[j]) & (x0[j] <= x1[i]) & (y0[i] <= y1[j]) & (y0[j] <= y1[i])
    i, j = i[hit], j[hit]
    hit = _rectangles_overlap(center[j] - center[i], u[i], w[i], h[i], u[j], w[j], h[j])
    big = np.flatnonzero(~small)
    i = np.concatenate([i[hit], big - 1, big])  # a big rectangle runs alone
    j = np.concatenate([j[hit], big, big + 1])
    keep = (i >= 0) & (j < n)
    # A run starting at s ends at the first j overlapping some i >= s of the run.
    stop = np.full(n + 1, n, dtype=np.int64)
    np.minimum.at(stop, i[keep], j[keep])
    stop = np.minimum.accumulate(stop[::-1])[::-1].tolist()
    runs, s = [], 0
    while s < n:
        e = stop[s]
        if e - s >= min_length:
            runs.append((s, e))
        s = e
    return runs


@lru_cache(maxsize=1)
def _serialization_works() -> bool:
    """Check once that skia reads paths in the layout :func:`_path_from_arrays` writes."""
    import skia

    pts = np.array([[1, 2], [3, 4], [5, 6], [7, 8], [9, 10]], dtype=np.float32)
    verbs = np.array([_VERB_MOVE, _VERB_LINE, _VERB_CUBIC, _VERB_CLOSE], dtype=np.uint8)
    path = skia.Path()
    try:
        if path.readFromMemory(_serialize(pts, verbs, evenodd=True)) == 0:
            return False
    except Exception:  # an incompatible skia: use the slow but safe builder
        return False
    ref = skia.Path()
    ref.moveTo(1, 2)
    ref.lineTo(3, 4)
    ref.cubicTo(5, 6, 7, 8, 9, 10)
    ref.close()
    ref.setFillType(skia.PathFillType.kEvenOdd)
    return path == ref


def _serialize(points_xy: np.ndarray, verbs: np.ndarray, evenodd: bool) -> bytes:
    """Write skia's path serialisation (version 5): header, counts, float32 points, verbs, padding."""
    pts = np.ascontiguousarray(points_xy, dtype=np.float32)
    header = struct.pack("<iiii", 5 | ((1 if evenodd else 0) << 8), len(pts), 0, len(verbs))
    pad = (-len(verbs)) % 4
    return header + pts.tobytes() + np.ascontiguousarray(verbs, dtype=np.uint8).tobytes() + b"\0" * pad


def _path_from_arrays(points: np.ndarray, verbs: np.ndarray, evenodd: bool):
    """Build a skia path from complex ``points`` and skia ``verbs`` (bulk when possible)."""
    xy = np.stack([points.real, points.imag], axis=-1).reshape(-1, 2)
    return _path_from_xy(xy, verbs, evenodd)


def _path_from_xy(xy: np.ndarray, verbs: np.ndarray, evenodd: bool):
    """Build a skia path from ``(m, 2)`` point coordinates and skia ``verbs`` (bulk when possible)."""
    import skia

    if _serialization_works():
        path = skia.Path()
        if path.readFromMemory(_serialize(xy, verbs, evenodd)):
            return path
    fill = skia.PathFillType.kEvenOdd if evenodd else skia.PathFillType.kWinding
    pts = [skia.Point(float(x), float(y)) for x, y in np.asarray(xy, dtype=np.float64).tolist()]
    return skia.Path.Make(pts, verbs.tolist(), [], fill)


# ---------------------------------------------------------------------------
# Views
