"""Geometry of the basic shapes (rect, circle, ellipse, line, polyline, polygon) as cubic arrays.

Each function returns the shape in its own user coordinates as a
:class:`~lsys_core.geometry.pathdata.PathTable` (rows, for markers) or directly as cubics, the
way SVG 2 defines the equivalent path: a rectangle starts at ``(x + rx, y)`` and runs clockwise,
circles and ellipses start at their rightmost point.  Quarter ellipses are two cubics of 45
degrees each (radial error below 5e-6 of the radius).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Callable
from typing import NamedTuple

import numpy as np

from lsys_core.geometry import pathdata as pd
from lsys_core.geometry.numbers import numbers_from_text
from lsys_core.geometry.pathdata import PathTable
from lsys_core.geometry.paths import ArrayPath, cubics_from_table
from lsys_core.svg.values import Viewport, parse_length, to_user

__all__ = [
    "Geometry",
    "KeepAsIs",
    "capped_stroke",
    "draws_cap_dots",
    "ellipse_path",
    "polyline_table",
    "rect_path",
    "shape_geometry",
    "tight_bbox",
]

#: Cubics per quarter ellipse (two pieces of 45 degrees: radial error below 5e-6 of the radius).
_PER_QUARTER = 2
_EIGHTH = np.exp(1j * np.pi / 4 * np.arange(_PER_QUARTER * 4 + 1))
_K8 = 4.0 / 3.0 * np.tan(np.pi / 16)


def _line(p0: complex, p3: complex) -> tuple[complex, complex, complex, complex]:
    d = p3 - p0
    return (p0, p0 + d / 3.0, p0 + 2.0 * d / 3.0, p3)


def _quarter(c: complex, a: complex, b: complex) -> list[tuple[complex, complex, complex, complex]]:
    """Quarter ellipse around centre ``c`` from ``c + a`` to ``c + b`` (``a``, ``b`` conjugate radii)."""
    out = []
    for j in range(_PER_QUARTER):
        t0, t1 = np.pi / 2 * j / _PER_QUARTER, np.pi / 2 * (j + 1) / _PER_QUARTER
        p0 = c + a * np.cos(t0) + b * np.sin(t0)
        p3 = c + a * np.cos(t1) + b * np.sin(t1)
        d0 = -a * np.sin(t0) + b * np.cos(t0)
        d1 = -a * np.sin(t1) + b * np.cos(t1)
        out.append((complex(p0), complex(p0 + _K8 * d0), complex(p3 - _K8 * d1), complex(p3)))
    return out


def rect_path(x: float, y: float, w: float, h: float, rx: float, ry: float) -> ArrayPath:
    """A rectangle (rounded when ``rx``, ``ry`` > 0; both already clamped to half the sides)."""
    if rx <= 0 or ry <= 0:
        p = [complex(x, y), complex(x + w, y), complex(x + w, y + h), complex(x, y + h)]
        rows = [_line(p[i], p[(i + 1) % 4]) for i in range(4)]
    else:
        left, right, top, bottom = x, x + w, y, y + h
        rows = []
        if w > 2 * rx:
            rows.append(_line(complex(left + rx, top), complex(right - rx, top)))
        rows += _quarter(complex(right - rx, top + ry), -1j * ry, rx)
        if h > 2 * ry:
            rows.append(_line(complex(right, top + ry), complex(right, bottom - ry)))
        rows += _quarter(complex(right - rx, bottom - ry), rx, 1j * ry)
        if w > 2 * rx:
            rows.append(_line(complex(right - rx, bottom), complex(left + rx, bottom)))
        rows += _quarter(complex(left + rx, bottom - ry), 1j * ry, -rx)
        if h > 2 * ry:
            rows.append(_line(complex(left, bottom - ry), complex(left, top + ry)))
        rows += _quarter(complex(left + rx, top + ry), -rx, -1j * ry)
    cubics = np.array(rows, dtype=complex)
    return ArrayPath(cubics, np.zeros(len(rows), dtype=np.intp), (True,))


def ellipse_path(cx: float, cy: float, rx: float, ry: float) -> ArrayPath:
    """An ellipse (a circle when ``rx == ry``), starting at its rightmost point, clockwise."""
    c = complex(cx, cy)
    a, b = complex(rx, 0), complex(0, ry)
    rows = [*_quarter(c, a, b), *_quarter(c, b, -a), *_quarter(c, -a, -b), *_quarter(c, -b, a)]
    return ArrayPath(np.array(rows, dtype=complex), np.zeros(len(rows), dtype=np.intp), (True,))


def polyline_table(points: np.ndarray, closed: bool) -> PathTable:
    """Rows of a polyline or polygon (``points`` is a complex array; at least one point)."""
    n = points.size
    op = np.full(n, pd.LINE, dtype=np.int8)
    op[0] = pd.MOVE
    p0 = np.empty(n, dtype=complex)
    p0[0] = points[0]
    p0[1:] = points[:-1]
    pts = np.stack([p0, p0, points, points], axis=1)
    if closed:
        op = np.append(op, np.int8(pd.CLOSE))
        pts = np.vstack([pts, [[points[-1], points[-1], points[0], points[0]]]])
    arc = np.zeros((0, 5))
    return PathTable(op, pts, arc, np.zeros(op.size, dtype=np.intp), (None,))


def tight_bbox(cubics: np.ndarray) -> tuple[float, float, float, float] | None:
    """Return ``(xmin, ymin, xmax, ymax)`` of the curves themselves (not their control points)."""
    if cubics.shape[0] == 0:
        return None
    ext = [cubics[:, 0], cubics[:, 3]]
    for part in (cubics.real, cubics.imag):
        p0, p1, p2, p3 = part.T
        # Derivative / 3 = a t^2 + b t + c (huge coordinates may overflow: skipped later as such)
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            a = -p0 + 3 * p1 - 3 * p2 + p3
            b = 2 * (p0 - 2 * p1 + p2)
            c = p1 - p0
            disc = np.sqrt(np.maximum(b * b - 4 * a * c, 0.0))
            lin = np.abs(a) < 1e-12 * (np.abs(b) + np.abs(c) + 1e-300)
            t1 = np.where(lin, -c / b, (-b + disc) / (2 * a))
            t2 = np.where(lin, np.nan, (-b - disc) / (2 * a))
        for t in (t1, t2):
            ok = np.isfinite(t) & (t > 0) & (t < 1)
            tt = t[ok][:, None]
            seg = cubics[ok]
            pts = (
                (1 - tt) ** 3 * seg[:, :1]
                + 3 * (1 - tt) ** 2 * tt * seg[:, 1:2]
                + 3 * (1 - tt) * tt**2 * seg[:, 2:3]
                + tt**3 * seg[:, 3:4]
            )
            ext.append(pts.ravel())
    allp = np.concatenate(ext)
    return (
        float(allp.real.min()),
        float(allp.imag.min()),
        float(allp.real.max()),
        float(allp.imag.max()),
    )


class KeepAsIs(Exception):
    """A shape uses something renderers disagree on (e.g. ``rem`` units): keep the element as is."""


#: Units whose meaning depends on the renderer (not all of them know these): kept as is.
UNCERTAIN_UNITS = frozenset({"rem", "ch", "vw", "vh", "vmin", "vmax"})


def _len(el: ET.Element, name: str, vp: Viewport, axis: str, default: float | None) -> float | None:
    text = el.get(name)
    if text is None:
        return default
    got = parse_length(text)
    if got is None:
        return default
    if got.unit in UNCERTAIN_UNITS:
        raise KeepAsIs(f"{got.unit} units")
    return to_user(got, vp, axis)


def capped_stroke(style: dict[str, str]) -> bool:
    """Whether a style strokes with caps that show on a zero-length subpath (``round``, ``square``)."""
    if style.get("stroke", "none").strip().lower() == "none":
        return False
    return style.get("stroke-linecap", "butt").strip().lower() in ("round", "square")


def draws_cap_dots(style: dict[str, str], table: PathTable | None) -> bool:
    """Whether a stroke draws caps on a zero-length subpath (a dot or a square where it stands).

    SVG 2 strokes a subpath whose segments all have zero length when ``stroke-linecap`` is
    ``round`` or ``square``; the cubic geometry drops such segments, so the caller keeps the
    element as it is.
    """
    if table is None or table.op.size == 0 or not capped_stroke(style):
        return False
    op, pts = table.op, table.pts
    is_move = op == pd.MOVE
    after_close = np.zeros(op.size, dtype=bool)
    after_close[1:] = op[:-1] == pd.CLOSE
    sub = np.cumsum(is_move | after_close) - 1
    zero = (pts == pts[:, :1]).all(axis=1)
    drawing = ~is_move & (sub >= 0)
    n_draw = np.bincount(sub[drawing], minlength=int(sub.max()) + 1)
    n_long = np.bincount(sub[drawing & ~zero], minlength=n_draw.size)
    return bool(np.any((n_draw > 0) & (n_long == 0)))


class Geometry(NamedTuple):
    """A shape in its own user coordinates: cubics, and path rows for markers (paths and lines)."""

    path: ArrayPath
    table: PathTable | None


def shape_geometry(
    el: ET.Element,
    tag: str,
    vp: Viewport,
    path_of: Callable[[str, bool], tuple[ArrayPath, PathTable | None, str | None]],
    rows: bool = True,
) -> tuple[Geometry | None, str | None]:
    """Read a shape element; return its geometry (None: draws nothing) and why it may be empty.

    ``path_of(d, rows)`` returns the parsed path data (cubics, rows, error); the rows of a
    ``<path>`` (for markers and caps) are left out (None) unless ``rows``.

    Raises
    ------
    KeepAsIs
        The shape uses units renderers disagree on.
    """
    if tag == "path":
        path, table, error = path_of(el.get("d") or "", rows)
        if error and error.startswith("a number beyond"):
            return Geometry(path, table), "non-finite or huge coordinates"
        return Geometry(path, table), ("malformed path data" if error else None)
    if tag == "rect":
        w = _len(el, "width", vp, "x", 0.0)
        h = _len(el, "height", vp, "y", 0.0)
        if not w or not h or w <= 0 or h <= 0:
            return None, "degenerate (zero size)"
        x = _len(el, "x", vp, "x", 0.0) or 0.0
        y = _len(el, "y", vp, "y", 0.0) or 0.0
        rx = _len(el, "rx", vp, "x", None)
        ry = _len(el, "ry", vp, "y", None)
        rx = None if rx is None or rx < 0 else rx
        ry = None if ry is None or ry < 0 else ry
        if rx is None:
            rx = ry if ry is not None else 0.0
        if ry is None:
            ry = rx
        return Geometry(rect_path(x, y, w, h, min(rx, w / 2), min(ry, h / 2)), None), None
    if tag in ("circle", "ellipse"):
        cx = _len(el, "cx", vp, "x", 0.0) or 0.0
        cy = _len(el, "cy", vp, "y", 0.0) or 0.0
        if tag == "circle":
            rx = ry = _len(el, "r", vp, "o", 0.0)
        else:
            rx = _len(el, "rx", vp, "x", None)
            ry = _len(el, "ry", vp, "y", None)
            rx = None if rx is None or rx < 0 else rx  # negative: as if not given ("auto")
            ry = None if ry is None or ry < 0 else ry
            rx = ry if rx is None else rx
            ry = rx if ry is None else ry
        if not rx or not ry or rx <= 0 or ry <= 0:
            return None, "degenerate (zero size)"
        return Geometry(ellipse_path(cx, cy, rx, ry), None), None
    if tag == "line":
        p = [_len(el, k, vp, k[0], 0.0) or 0.0 for k in ("x1", "y1", "x2", "y2")]
        pts = np.array([complex(p[0], p[1]), complex(p[2], p[3])])
    else:  # polyline, polygon
        values, _ = numbers_from_text(el.get("points") or "")
        if values.size % 2:
            values = values[:-1]
        if values.size < 4:
            return None, "degenerate (zero size)"
        pts = np.empty(values.size // 2, complex)  # (1j * inf would warn: non-finite points are
        pts.real, pts.imag = values[0::2], values[1::2]  # skipped later, as in path data)
    table = polyline_table(pts, closed=tag == "polygon")
    return Geometry(ArrayPath(*cubics_from_table(table)), table), None
