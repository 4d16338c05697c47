"""Gradient paint servers as skia shaders: ``fill="url(#g)"`` on content the own renderer draws.

:func:`gradient_shader` turns a ``<linearGradient>`` or ``<radialGradient>`` (attributes and
stops inherited through ``href`` chains, ``gradientUnits``, ``gradientTransform``,
``spreadMethod``, focal points and radius ``fr``) into a skia shader for a shape with a given
bounding box.  Patterns and other servers are not drawn here (callers use the paint's
fallback colour).  skia is imported inside the functions.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Callable
from functools import lru_cache
from typing import Any

from lsys_core.render.paths import _number, _rgba, parse_style
from lsys_core.svg.tree import href_of, local_name
from lsys_core.svg.values import IDENTITY, Viewport, multiply, parse_length, parse_transform, to_user

__all__ = ["NONE", "defs_index", "gradient_shader", "parse_fragment", "server_id"]

#: What :func:`gradient_shader` returns for a gradient that paints nothing (no stops).
NONE = "none"
#: Longest ``href`` chain followed between gradients.
MAX_CHAIN = 16
_GRADIENTS = ("linearGradient", "radialGradient")
_INHERITED = (
    "x1", "y1", "x2", "y2", "cx", "cy", "r", "fx", "fy", "fr", "gradientUnits", "gradientTransform", "spreadMethod",
)  # fmt: skip
_DEFAULTS = {
    "x1": "0%",
    "y1": "0%",
    "x2": "100%",
    "y2": "0%",
    "cx": "50%",
    "cy": "50%",
    "r": "50%",
    "fr": "0%",
}
_AXIS = {"x1": "x", "x2": "x", "cx": "x", "fx": "x", "y1": "y", "y2": "y", "cy": "y", "fy": "y"}


def parse_fragment(markup: str) -> ET.Element | None:
    """Parse SVG markup (one or more elements) inside a wrapper; None if it is not well-formed.

    No DTD can occur inside the wrapper, so no entity is expanded.
    """
    if not markup.strip():
        return None
    try:
        return ET.fromstring(f"<g>{markup}</g>")
    except ET.ParseError:
        return None


@lru_cache(maxsize=4)
def defs_index(defs: str) -> dict[str, ET.Element]:
    """The elements of a drawing's definitions (markup) by id."""
    root = parse_fragment(defs)
    out: dict[str, ET.Element] = {}
    for el in root.iter() if root is not None else ():
        if el.get("id"):
            out.setdefault(el.get("id", ""), el)
    return out


def server_id(value: str) -> str | None:
    """The id in a ``url(#id)`` paint value (None: not a local reference)."""
    v = value.strip()
    if not v.lower().startswith("url("):
        return None
    close = v.find(")")
    ref = v[4:close].strip().strip("'\"").strip() if close > 0 else ""
    return ref[1:] if ref.startswith("#") and len(ref) > 1 else None


def _chain(el: ET.Element, find: Callable[[str], ET.Element | None]) -> list[ET.Element]:
    """The gradient and those it refers to by ``href``, nearest first (no cycles)."""
    out = [el]
    while len(out) < MAX_CHAIN:
        href = href_of(out[-1])
        nxt = find(href[1:]) if href and href.startswith("#") else None
        if nxt is None or local_name(nxt.tag) not in _GRADIENTS or any(nxt is e for e in out):
            break
        out.append(nxt)
    return out


def _stops(chain: list[ET.Element]) -> list[tuple[float, int]]:
    """The (offset, ARGB colour) stops of the first gradient of the chain that has any."""
    for el in chain:
        stops = [c for c in el if local_name(c.tag) == "stop"]
        if not stops:
            continue
        out: list[tuple[float, int]] = []
        for stop in stops:
            decls = {k: v for k, v in stop.attrib.items() if k in ("offset", "stop-color", "stop-opacity")}
            decls.update(parse_style(stop.get("style", "")))
            offset = _number(decls.get("offset"), 0.0)
            offset = max(0.0, min(1.0, offset))
            if out:
                offset = max(offset, out[-1][0])
            opacity = max(0.0, min(1.0, _number(decls.get("stop-opacity"), 1.0)))
            rgba = _rgba(decls.get("stop-color", "black"), opacity) or (0, 0, 0, 0)
            r, g, b, a = rgba
            out.append((offset, (a << 24) | (r << 16) | (g << 8) | b))
        return out
    return []


def gradient_shader(
    value: str,
    find: Callable[[str], ET.Element | None],
    bbox: tuple[float, float, float, float],
    viewport: tuple[float, float],
) -> Any:
    """The shader of the gradient ``value`` (``url(#id)``) for a shape whose box is ``bbox``.

    Returns a skia shader, :data:`NONE` when the gradient paints nothing (no stops), or None
    when ``value`` is not a gradient drawn here or its ``objectBoundingBox`` units meet a box
    without area (the caller uses the fallback colour).
    """
    import skia

    ident = server_id(value)
    el = find(ident) if ident else None
    if el is None or local_name(el.tag) not in _GRADIENTS:
        return None
    chain = _chain(el, find)
    attrs: dict[str, str] = {}
    for k in _INHERITED:
        for e in chain:
            if e.get(k) is not None:
                attrs[k] = e.get(k, "")
                break
    stops = _stops(chain)
    if not stops:
        return NONE
    positions, colors = [s[0] for s in stops], [s[1] for s in stops]
    if len(stops) == 1:
        positions, colors = [0.0, 1.0], colors * 2
    bounding = attrs.get("gradientUnits", "objectBoundingBox").strip() != "userSpaceOnUse"
    x0, y0, x1, y1 = bbox
    m = parse_transform(attrs.get("gradientTransform")) or IDENTITY
    if bounding:
        if x1 - x0 <= 0 or y1 - y0 <= 0:  # as renderers do: the fallback colour, if any
            return None
        m = multiply((x1 - x0, 0.0, 0.0, y1 - y0, x0, y0), m)
    vp = Viewport(1.0, 1.0, 16.0, 16.0) if bounding else Viewport(viewport[0], viewport[1])

    def coord(key: str, default: str | None = None) -> float:
        length = parse_length(attrs.get(key, default if default is not None else _DEFAULTS[key]))
        if length is None:
            length = parse_length(_DEFAULTS.get(key, "0"))
        assert length is not None
        if bounding and length.unit == "%":
            return length.value / 100.0
        return to_user(length, vp, _AXIS.get(key, "o"))

    local = skia.Matrix.MakeAll(m[0], m[2], m[4], m[1], m[3], m[5], 0, 0, 1)
    mode = {"reflect": skia.TileMode.kMirror, "repeat": skia.TileMode.kRepeat}.get(
        attrs.get("spreadMethod", "pad").strip(), skia.TileMode.kClamp
    )
    if local_name(el.tag) == "linearGradient":
        p1 = skia.Point(coord("x1"), coord("y1"))
        p2 = skia.Point(coord("x2"), coord("y2"))
        if p1 == p2:  # no direction: the last stop's colour
            return skia.Shaders.Color(colors[-1])
        return skia.GradientShader.MakeLinear([p1, p2], colors, positions, mode, 0, local)
    cx, cy, r = coord("cx"), coord("cy"), coord("r")
    fx, fy, fr = coord("fx", attrs.get("cx", "50%")), coord("fy", attrs.get("cy", "50%")), coord("fr")
    if r <= 0:
        return skia.Shaders.Color(colors[-1])
    if (fx, fy, fr) == (cx, cy, 0.0):
        return skia.GradientShader.MakeRadial(skia.Point(cx, cy), r, colors, positions, mode, 0, local)
    shader = skia.GradientShader.MakeTwoPointConical(
        skia.Point(fx, fy), max(fr, 0.0), skia.Point(cx, cy), r, colors, positions, mode, 0, local
    )
    return shader if shader is not None else skia.Shaders.Color(colors[-1])
