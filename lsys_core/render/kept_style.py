"""Styles of kept content for the own renderer: cascade down a kept fragment, paints, transforms.

A kept fragment (:class:`~lsys_core.grammar.model.Verbatim`) has its cascaded declarations
baked into ``style`` attributes by the reader, so computing an element's style here is only
inheritance: the parent's inherited properties, then the element's presentation attributes,
then its ``style`` declarations (``inherit`` takes the parent's value).  ``font-size`` is
resolved to user units on the way down, so ``em`` and ``%`` sizes of nested ``<tspan>``
elements refer to their parent's size.  skia is imported inside the functions.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Callable, Mapping
from typing import Any

from lsys_core.render.paint_servers import NONE
from lsys_core.render.paths import _number, _Paints, _rgba, _skia_paint, parse_style
from lsys_core.svg.style import INHERITED, PROPERTIES, font_size_px
from lsys_core.svg.values import IDENTITY, Matrix, Viewport, parse_length, parse_transform, to_user

__all__ = ["computed", "dash_effect", "font_px", "group_opacity", "lengths", "shape_paints", "transform_of"]

#: The initial font size in user units (librsvg's; CSS's ``medium`` would be 16).
INITIAL_FONT_SIZE = 12.0
#: Presentation attributes read from a kept element (``transform`` is read by :func:`transform_of`).
_ATTRIBUTES = PROPERTIES - {"transform", "font"}


def computed(parent: Mapping[str, str], el: ET.Element) -> dict[str, str]:
    """Return an element's computed declarations given its parent's (``font-size`` as a number)."""
    own = {k: v for k, v in el.attrib.items() if k in _ATTRIBUTES}
    own.update(parse_style(el.get("style", "")))
    out = {k: v for k, v in parent.items() if k in INHERITED}
    parent_px = font_px(parent)
    for k, v in own.items():
        if v.strip().lower() == "inherit":
            if k in parent:
                out[k] = parent[k]
            else:
                out.pop(k, None)
        else:
            out[k] = v
    if "font-size" in own:
        size = font_size_px(out.get("font-size", ""), parent_px, INITIAL_FONT_SIZE)
        out["font-size"] = repr(size if math.isfinite(size) and size >= 0 else parent_px)
    return out


def font_px(style: Mapping[str, str]) -> float:
    """The font size of a computed style in user units."""
    return _number(style.get("font-size"), INITIAL_FONT_SIZE)


def lengths(
    text: str | None, style: Mapping[str, str], viewport: tuple[float, float], axis: str = "o"
) -> list[float] | None:
    """Read a list of lengths in user units (font-relative ones of ``style``, percentages of the
    ``viewport`` size along ``axis``); None when absent, empty or unreadable."""
    if text is None:
        return None
    vp = Viewport(viewport[0], viewport[1], font_px(style), INITIAL_FONT_SIZE)
    out = []
    for part in text.replace(",", " ").split():
        length = parse_length(part)
        if length is None:
            return None
        out.append(to_user(length, vp, axis))
    return out or None


def transform_of(el: ET.Element, style: Mapping[str, str]) -> Matrix | None:
    """Return an element's own transform (the CSS property wins over the attribute); None if unreadable."""
    if "transform" in style:
        return parse_transform(style["transform"], css=True)
    if el.get("transform") is not None:
        return parse_transform(el.get("transform"))
    return IDENTITY


def group_opacity(style: Mapping[str, str]) -> float:
    """The element's ``opacity`` (a group effect, not inherited), clamped to [0, 1]."""
    return max(0.0, min(1.0, _number(style.get("opacity"), 1.0)))


#: A paint server lookup: ``(paint value) -> shader``, :data:`~.paint_servers.NONE` or None.
Servers = Callable[[str], Any]


def _colour(style: Mapping[str, str], key: str, default: str, opacity: float):
    value = style.get(key, default).strip()
    if value.lower().startswith("url("):  # a paint server not drawn here: its fallback colour, if any
        close = value.find(")")
        value = value[close + 1 :].strip() if close >= 0 else ""
        if not value:
            return None
    if value.lower() == "currentcolor":
        value = style.get("color", "black")
    rgba = _rgba(value, opacity)
    return rgba if rgba is not None and rgba[3] > 0 else None


def _dash_lengths(style: Mapping[str, str], viewport: tuple[float, float]) -> list[float]:
    text = style.get("stroke-dasharray", "none").strip()
    values = (lengths(text, style, viewport) if text.lower() != "none" else None) or []
    return values * 2 if len(values) % 2 else values


def dash_effect(style: Mapping[str, str], viewport: tuple[float, float]) -> Any:
    """The skia dash effect of ``stroke-dasharray``/``stroke-dashoffset`` (None: a solid stroke).

    As SVG says: an odd count of values is repeated, a negative value or a sum of zero draws
    solid (as does a pattern without gaps); percentages are of the viewport's diagonal.
    """
    import skia

    values = _dash_lengths(style, viewport)
    if not values or min(values) < 0 or not math.isfinite(sum(values)) or sum(values) <= 0:
        return None
    if not any(values[1::2]):  # no gaps: a solid stroke (skia would cut its joins)
        return None
    offset = lengths(style.get("stroke-dashoffset"), style, viewport)
    phase = offset[0] % sum(values) if offset and math.isfinite(offset[0]) else 0.0
    return skia.DashPathEffect.Make(values, phase)


def shape_paints(
    style: Mapping[str, str],
    antialias: bool = True,
    servers: Servers | None = None,
    viewport: tuple[float, float] = (0.0, 0.0),
) -> list:
    """Return the skia paints of a shape with this style, in its paint order (fill, stroke).

    ``servers`` gives the shaders of ``url(#id)`` paints (gradients); without one, or where it
    has none, the paint's fallback colour is used (none if not given).  Strokes are dashed
    (:func:`dash_effect`; percentages of the ``viewport``).
    """
    width = max(0.0, _number(style.get("stroke-width"), 1.0))
    stroke_geometry = _Paints(
        fill=None,
        stroke=None,
        width=width,
        cap=style.get("stroke-linecap", "butt").lower(),
        join=style.get("stroke-linejoin", "miter").lower(),
        miter=max(1.0, _number(style.get("stroke-miterlimit"), 4.0)),
        evenodd=False,
    )
    out = []
    for key, default in (("fill", "black"), ("stroke", "none")):
        if key == "stroke" and (width == 0.0 or not math.isfinite(width)):
            continue
        opacity = max(0.0, min(1.0, _number(style.get(key + "-opacity"), 1.0)))
        value = style.get(key, default).strip()
        shader = servers(value) if servers is not None and value.lower().startswith("url(") else None
        if shader is NONE:
            continue
        rgba = (
            (0, 0, 0, round(opacity * 255)) if shader is not None else _colour(style, key, default, opacity)
        )
        if rgba is None or rgba[3] == 0:
            continue
        paint = (
            _skia_paint(rgba, antialias, stroke_geometry, width)
            if key == "stroke"
            else _skia_paint(rgba, antialias)
        )
        if shader is not None:
            paint.setShader(shader)
        dashes = dash_effect(style, viewport) if key == "stroke" else None
        if dashes is not None:
            if stroke_geometry.cap == "butt" and not any(_dash_lengths(style, viewport)[0::2]):
                continue  # dashes of length zero with butt caps draw nothing
            paint.setPathEffect(dashes)
        out.append(paint)
    order = style.get("paint-order", "normal").split()
    stroke_first = order[:1] == ["stroke"] or order[:2] == ["markers", "stroke"]
    if stroke_first and len(out) == 2:
        out.reverse()
    return out
