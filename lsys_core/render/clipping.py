"""Clip paths (``clip-path="url(#id)"``) as skia paths, for what the own renderer draws one by one.

:func:`clip_region` returns the region a ``<clipPath>`` lets through for an element whose box
is ``bbox``: the union of its children's outlines (``<path>``, ``<rect>`` with rounded corners,
``<circle>``, ``<ellipse>``, ``<polygon>``, ``<polyline>`` and ``<text>``), each with its
transform and ``clip-rule``, under the clip path's own transform and ``clipPathUnits``, and
intersected with the region of a ``clip-path`` on the ``<clipPath>`` itself.  A reference to
nothing that is a clip path clips nothing (as librsvg does).  skia is imported inside the
functions.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Callable
from typing import Any

from lsys_core.render.kept_style import computed, lengths, transform_of
from lsys_core.render.kept_text import layout_text
from lsys_core.render.paint_servers import server_id
from lsys_core.render.paths import _geometry, _path_from_arrays
from lsys_core.svg.tree import local_name
from lsys_core.svg.values import IDENTITY, Matrix, multiply

__all__ = ["clip_region"]

#: Deepest chain of clip paths on clip paths followed.
MAX_NESTING = 8


def _matrix(m: Matrix):
    import skia

    return skia.Matrix.MakeAll(m[0], m[2], m[4], m[1], m[3], m[5], 0, 0, 1)


def _outline(el: ET.Element, tag: str, style: dict[str, str], find, viewport) -> Any:
    """A clip child's outline in its own user space (None: it adds nothing)."""
    import skia

    def one(key: str, axis: str, default: float = 0.0) -> float:
        values = lengths(el.get(key), style, viewport, axis)
        return values[0] if values else default

    path = skia.Path()
    if tag == "path":
        geometry = _geometry(el.get("d") or "")
        path = _path_from_arrays(geometry.points, geometry.verbs, False)
    elif tag == "rect":
        w, h = one("width", "x"), one("height", "y")
        if w <= 0 or h <= 0:
            return None
        rxs, rys = lengths(el.get("rx"), style, viewport, "x"), lengths(el.get("ry"), style, viewport, "y")
        rxv = rxs[0] if rxs and rxs[0] >= 0 else None
        ryv = rys[0] if rys and rys[0] >= 0 else None
        rxv, ryv = (rxv if rxv is not None else ryv or 0.0), (ryv if ryv is not None else rxv or 0.0)
        rect = skia.Rect.MakeXYWH(one("x", "x"), one("y", "y"), w, h)
        path.addRRect(skia.RRect.MakeRectXY(rect, min(rxv, w / 2), min(ryv, h / 2)))
    elif tag in ("circle", "ellipse"):
        if tag == "circle":
            rx = ry = one("r", "o")
        else:
            rx, ry = one("rx", "x", -1.0), one("ry", "y", -1.0)
            rx, ry = (rx if rx >= 0 else ry), (ry if ry >= 0 else rx)
        cx, cy = one("cx", "x"), one("cy", "y")
        if rx <= 0 or ry <= 0:
            return None
        path.addOval(skia.Rect.MakeLTRB(cx - rx, cy - ry, cx + rx, cy + ry))
    elif tag in ("polygon", "polyline"):
        values = lengths(el.get("points"), {}, viewport) or []
        points = [skia.Point(x, y) for x, y in zip(values[0::2], values[1::2], strict=False)]
        if len(points) < 3:
            return None
        path.addPoly(points, True)
    elif tag == "text":
        for run in layout_text(el, style, find, viewport)[0]:
            path.addPath(run.path)
        return path
    else:
        return None
    rule = style.get("clip-rule", "nonzero").strip().lower()
    path.setFillType(skia.PathFillType.kEvenOdd if rule == "evenodd" else skia.PathFillType.kWinding)
    return path


def clip_region(
    value: str,
    find: Callable[[str], ET.Element | None],
    bbox: tuple[float, float, float, float] | None,
    viewport: tuple[float, float],
    depth: int = 0,
) -> Any:
    """The region (a skia path in the element's user space) the clip path ``value`` lets through.

    None: no clipping (not a reference to a ``<clipPath>``, or ``objectBoundingBox`` units for
    an element whose box is not known here, ``bbox`` None).
    """
    import skia

    ident = server_id(value)
    clip = find(ident) if ident else None
    if clip is None or local_name(clip.tag) != "clipPath" or depth > MAX_NESTING:
        return None
    m = transform_of(clip, computed({}, clip)) or IDENTITY
    if clip.get("clipPathUnits", "").strip() == "objectBoundingBox":
        if bbox is None:
            return None
        x0, y0, x1, y1 = bbox
        m = multiply((x1 - x0, 0.0, 0.0, y1 - y0, x0, y0), m)
    region = skia.Path()
    base = computed({}, clip)
    for child in clip:
        tag = local_name(child.tag)
        if tag is None:
            continue
        style = computed(base, child)
        if style.get("display", "").strip().lower() == "none":
            continue
        if style.get("visibility", "visible").strip().lower() in ("hidden", "collapse"):
            continue
        outline = _outline(child, tag, style, find, viewport)
        own = transform_of(child, style)
        if outline is None or own is None:
            continue
        outline.transform(_matrix(own))
        region = skia.Op(region, outline, skia.PathOp.kUnion_PathOp) or region
    if not all(math.isfinite(v) for v in m):
        return skia.Path()
    region.transform(_matrix(m))
    nested = base.get("clip-path")
    if nested and nested.strip().lower() != "none":
        outer = clip_region(nested, find, bbox, viewport, depth + 1)
        if outer is not None:
            region = skia.Op(region, outer, skia.PathOp.kIntersect_PathOp) or skia.Path()
    return region
