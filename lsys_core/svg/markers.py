"""Where markers go on a path and how they turn (SVG 1.1 implementation notes, F.5 'path' element).

Markers are repetition: each one becomes ordinary elements of the scene.  :func:`marker_points`
lists the vertices of a parsed path with the marker kind (start, mid, end) and the direction a
marker with ``orient="auto"`` takes there: the bisector of the incoming and outgoing tangents,
where zero-length segments take their direction from the nearest segment before (incoming) or
after (outgoing) that has one within the subpath.  Moves that start a later subpath are mid
vertices; a move followed by nothing is a lone point with a mid marker, as renderers draw it.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import replace
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from lsys_core.geometry import pathdata as pd
from lsys_core.geometry.pathdata import PathTable
from lsys_core.svg.paint import length, split_url
from lsys_core.svg.records import length_or
from lsys_core.svg.tree import local_name
from lsys_core.svg.values import Viewport, multiply, parse_viewbox, viewbox_transform

if TYPE_CHECKING:
    from lsys_core.svg.walk import Ctx, Reader

__all__ = ["MarkerPoint", "draw", "marker_points", "orient_angle"]

_EPS = 1e-9


class MarkerPoint(NamedTuple):
    """One marker position: ``kind`` is ``start``, ``mid`` or ``end``; ``angle`` in radians."""

    kind: str
    point: complex
    angle: float


class _Seg(NamedTuple):
    """A segment with its end points and tangents (None: a lone point, or no direction)."""

    start: complex
    end: complex
    t_in: complex | None  # tangent at the start
    t_out: complex | None  # tangent at the end
    lone: bool


def _tangents(p: tuple[complex, complex, complex, complex]) -> tuple[complex | None, complex | None]:
    """Start and end tangents of a cubic-like segment, skipping coincident control points."""
    p1, p2, p3, p4 = p

    def same(a: complex, b: complex) -> bool:
        return abs(a - b) <= _EPS * max(1.0, abs(a), abs(b))

    if same(p1, p2) and same(p1, p3) and same(p1, p4):
        return None, None
    t_in = next((q - p1 for q in (p2, p3, p4) if not same(q, p1)), None)
    t_out = next((p4 - q for q in (p3, p2, p1) if not same(q, p4)), None)
    return t_in, t_out


def _arc_tangents(row: np.ndarray, arc: np.ndarray) -> tuple[complex | None, complex | None]:
    """Tangents of an arc row (a straight line when a radius is zero)."""
    from lsys_core.geometry.arcs import arc_cubics

    p0, p3 = complex(row[0]), complex(row[3])
    if abs(p3 - p0) <= _EPS * max(1.0, abs(p0)):
        return None, None
    if arc[0] == 0 or arc[1] == 0:
        return p3 - p0, p3 - p0
    cubics, _ = arc_cubics(np.array([p0]), np.array([p3]), arc.reshape(1, 5))
    t_in, _ = _tangents(tuple(cubics[0]))
    _, t_out = _tangents(tuple(cubics[-1]))
    return t_in, t_out


def _segments(table: PathTable) -> list[_Seg]:
    """The segments and lone points of a parsed path, in order."""
    segs: list[_Seg] = []
    arc_i = 0
    state = "initial"
    cur = 0j
    for i in range(table.op.size):
        op = int(table.op[i])
        row = table.pts[i]
        if op == pd.MOVE:
            if state == "new":  # two moves in a row: the first is a lone point
                segs.append(_Seg(cur, cur, None, None, True))
            state = "initial" if state == "closed" else "new"
            cur = complex(row[3])
            continue
        if op == pd.ARC:
            t_in, t_out = _arc_tangents(row, table.arc[arc_i])
            arc_i += 1
            if t_in is None:
                continue  # an arc to its own start point is left out
        else:
            t_in, t_out = _tangents((complex(row[0]), complex(row[1]), complex(row[2]), complex(row[3])))
        segs.append(_Seg(complex(row[0]), complex(row[3]), t_in, t_out, False))
        cur = complex(row[3])
        state = "closed" if op == pd.CLOSE else "in"
    if state == "new":
        segs.append(_Seg(cur, cur, None, None, True))
    return segs


def _incoming(segs: list[_Seg], i: int) -> complex | None:
    for s in reversed(segs[: i + 1]):
        if s.lone:
            return None
        if s.t_out is not None:
            return s.t_out
    return None


def _outgoing(segs: list[_Seg], i: int) -> complex | None:
    for s in segs[i:]:
        if s.lone:
            return None
        if s.t_in is not None:
            return s.t_in
    return None


def _angle(v: complex | None) -> float:
    return 0.0 if v is None else math.atan2(v.imag, v.real)


def _bisect(a: float, b: float) -> float:
    """The direction halfway between two directions, on the side of the smaller turn."""
    a %= 2 * math.pi
    b %= 2 * math.pi
    half = (b - a) / 2
    return a + half - math.pi if abs(half) > math.pi / 2 else a + half


def marker_points(table: PathTable) -> list[MarkerPoint]:
    """Return the marker positions of a parsed path (see the module docstring)."""
    segs = _segments(table)
    out: list[MarkerPoint] = []
    in_subpath = False
    for i, s in enumerate(segs):
        if s.lone:
            if in_subpath:
                out.append(MarkerPoint("end", segs[i - 1].end, _angle(_incoming(segs, i - 1))))
            out.append(MarkerPoint("mid", s.start, 0.0))
            in_subpath = False
        elif not in_subpath:
            out.append(MarkerPoint("start", s.start, _angle(_outgoing(segs, i))))
            in_subpath = True
        else:
            inc, outg = _incoming(segs, i - 1), _outgoing(segs, i)
            if inc is not None and outg is not None:
                ang = _bisect(_angle(inc), _angle(outg))
            else:
                ang = _angle(inc if inc is not None else outg)
            out.append(MarkerPoint("mid", s.start, ang))
    if segs and not segs[-1].lone:
        ang = _angle(_incoming(segs, len(segs) - 1))
        if table.op.size and int(table.op[-1]) == pd.CLOSE:
            ang = _bisect(ang, _angle(_outgoing(segs, 0)))
        out.append(MarkerPoint("end", segs[-1].end, ang))
    return out


def orient_angle(orient: str | None, kind: str, auto: float) -> float | None:
    """The rotation (radians) of a marker from its ``orient`` attribute; None if unreadable."""
    text = (orient or "0").strip().lower()
    if text == "auto":
        return auto
    if text == "auto-start-reverse":
        return auto + math.pi if kind == "start" else auto
    units = {"deg": 1.0, "grad": 0.9, "rad": 180 / math.pi}
    for unit, factor in units.items():
        if text.endswith(unit):
            try:
                return math.radians(float(text[: -len(unit)]) * factor)
            except ValueError:
                return None
    try:
        return math.radians(float(text))
    except ValueError:
        return None


def _context_paint(decls: dict[str, str], kind: str):
    value = decls.get(kind, "none")
    if value == "none":
        return None
    if value.startswith("url("):
        return ("url", value[4:-1], 1.0)
    return ("color", value, 1.0)


def draw(reader: Reader, el: ET.Element, table: PathTable, ctx: Ctx, decls: dict[str, str]) -> None:
    """Draw the markers of a shape: each one's content becomes ordinary records of the scene."""
    style = ctx.style
    width = length(style.get("stroke-width"), ctx.vp, 1.0)
    if not math.isfinite(width) or width <= 0:
        return  # renderers draw no markers on a shape whose stroke has no width
    context = {"fill": _context_paint(decls, "fill"), "stroke": _context_paint(decls, "stroke")}
    for mp in marker_points(table):
        value = style.get(f"marker-{mp.kind}", "none")
        if value.strip().lower() == "none":
            continue
        ref, _ = split_url(value)
        marker = reader.tree.target(ref)
        if marker is None or local_name(marker.tag) != "marker" or id(marker) in ctx.uses:
            continue
        _instance(reader, marker, mp, ctx, width, context)


def _instance(
    reader: Reader, marker: ET.Element, mp: MarkerPoint, ctx: Ctx, width: float, context: dict
) -> None:
    """Draw one marker at one vertex."""
    from lsys_core.svg import group_effects

    mstyle = reader.style_at(marker)
    mw = length_or(marker.get("markerWidth"), ctx.vp, "x", 3.0)
    mh = length_or(marker.get("markerHeight"), ctx.vp, "y", 3.0)
    if mw <= 0 or mh <= 0:
        return
    angle = orient_angle(marker.get("orient"), mp.kind, mp.angle) or 0.0
    c, s = math.cos(angle), math.sin(angle)
    m = multiply(ctx.ctm, (c, s, -s, c, mp.point.real, mp.point.imag))
    if (marker.get("markerUnits") or "").strip() != "userSpaceOnUse":
        m = multiply(m, (width, 0.0, 0.0, width, 0.0, 0.0))
    vb = parse_viewbox(marker.get("viewBox"))
    if vb is not None:
        fit = viewbox_transform(vb, 0.0, 0.0, mw, mh, marker.get("preserveAspectRatio"))
        m = multiply(m, (fit[0], 0.0, 0.0, fit[3], 0.0, 0.0))
        content_vp = Viewport(vb[2], vb[3], ctx.vp.font_size, ctx.vp.root_font_size)
        clip_box = vb
    else:
        content_vp = Viewport(mw, mh, ctx.vp.font_size, ctx.vp.root_font_size)
        clip_box = (0.0, 0.0, mw, mh)
    rx = length_or(marker.get("refX"), content_vp, "x", 0.0)
    ry = length_or(marker.get("refY"), content_vp, "y", 0.0)
    m = multiply(m, (1.0, 0.0, 0.0, 1.0, -rx, -ry))
    clip = None
    if mstyle.get("overflow", "hidden").strip().lower() in ("hidden", "scroll"):
        x, y, w, h = clip_box
        a, b, cc, d, e, f = m
        corners = [complex(x, y), complex(x + w, y), complex(x + w, y + h), complex(x, y + h)]
        clip = reader.resources.clip_rect(
            [complex(a * p.real + cc * p.imag + e, b * p.real + d * p.imag + f) for p in corners]
        )
    inner = replace(
        ctx,
        ctm=m,
        style=mstyle,
        vp=content_vp,
        depth=ctx.depth + 1,
        uses=(*ctx.uses, id(marker)),
        chain=ctx.chain + "marker>",
        context=context,
    )
    start = len(reader.records)
    for child in marker:
        if isinstance(child.tag, str):
            reader.walk(child, inner)
    if len(reader.records) > start:
        group_effects.apply(reader, marker, {"opacity": mstyle.get("opacity", "1")}, inner, start, clip)
