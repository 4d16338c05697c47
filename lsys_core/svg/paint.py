"""What a shape draws with: its computed style turned into the output declarations of an element.

Fill and stroke become ``#rrggbb`` colours (a colour's alpha is folded into ``fill-opacity`` /
``stroke-opacity``) or ``url(#id)`` references to paint servers rewritten in document
coordinates (:mod:`lsys_core.svg.resources`).  Lengths (stroke width, dashes, dash offset) are
resolved against the viewport and font size and scaled into document units by the element's
transform, so the element's geometry, which is in document units too, draws the same.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from lsys_core.svg.colors import hex_of, parse_color
from lsys_core.svg.values import Matrix, Viewport, parse_length, parse_number, to_user

__all__ = ["Paint", "parse_paint", "scale_of", "stroke_declarations", "unit_value"]

#: A resolved paint: None (nothing drawn), ``("color", "#rrggbb", alpha)`` or ``("url", "#id", 1.0)``.
Paint = tuple[str, str, float] | None


def unit_value(text: str | None, default: float) -> float:
    """Read an opacity-like value (number or percentage), clamped to [0, 1]."""
    if text is None:
        return default
    t = text.strip()
    length = parse_length(t)
    if length is None or length.unit not in ("", "%"):
        return default
    v = length.value / 100.0 if length.unit == "%" else length.value
    return min(1.0, max(0.0, v)) if math.isfinite(v) else default


def scale_of(m: Matrix) -> float:
    """The length scale of a transform (square root of its determinant's magnitude)."""
    return math.sqrt(abs(m[0] * m[3] - m[1] * m[2]))


def anisotropy(m: Matrix) -> float:
    """Ratio of the largest to the smallest stretch of a transform (1 for similarities)."""
    a, b, c, d = m[0], m[1], m[2], m[3]
    s1 = math.hypot(a + d, b - c) / 2
    s2 = math.hypot(a - d, b + c) / 2
    big, small = s1 + s2, abs(s1 - s2)
    return math.inf if small == 0 else big / small


def split_url(value: str) -> tuple[str | None, str]:
    """Split ``url(#id) fallback`` into the reference (``#id``, quotes removed) and the fallback."""
    v = value.strip()
    if not v.lower().startswith("url("):
        return None, v
    close = v.find(")")
    inner = v[4:close].strip().strip("'\"").strip()
    return inner, v[close + 1 :].strip()


def parse_paint(
    value: str | None,
    style: dict[str, str],
    server: Callable[[str], Paint | str],
    context: dict[str, Paint] | None = None,
) -> Paint:
    """Resolve a ``fill`` or ``stroke`` value.

    ``server(ref)`` turns a reference into a paint, or returns ``"missing"`` when nothing usable
    is there (then the fallback applies, or no paint).  ``context`` holds the paints of the
    element a marker is drawn on (``context-fill``, ``context-stroke``).
    """
    if value is None:
        return None
    low = value.strip().lower()
    if low == "none":
        return None
    if low in ("context-fill", "context-stroke"):
        return (context or {}).get(low[8:])
    if low.startswith("url("):
        ref, fallback = split_url(value)
        got = server(ref or "")
        if got != "missing":
            return got  # type: ignore[return-value]
        return parse_paint(fallback, style, server, context) if fallback else None
    current = parse_color(style.get("color", "black")) if low == "currentcolor" else None
    rgba = parse_color(value, current)
    if rgba is None:
        return None
    return ("color", hex_of(rgba), rgba[3])


def length(text: str | None, vp: Viewport, default: float, axis: str = "o") -> float:
    """Resolve a length property to user units (``default`` if absent or unreadable)."""
    if text is None:
        return default
    got = parse_length(text)
    return default if got is None else to_user(got, vp, axis)


def _num(v: float) -> str:
    return f"{v:.6g}"


def stroke_declarations(style: dict[str, str], vp: Viewport, scale: float) -> dict[str, str] | None:
    """Return the stroke geometry declarations (width, caps, joins, dashes), or None for zero width.

    Lengths are multiplied by ``scale`` (document units per user unit of the element).
    """
    width = length(style.get("stroke-width"), vp, 1.0)
    if not math.isfinite(width) or width <= 0:
        return None
    out = {"stroke-width": _num(width * scale)}
    cap = style.get("stroke-linecap", "butt").lower()
    if cap in ("round", "square"):
        out["stroke-linecap"] = cap
    join = style.get("stroke-linejoin", "miter").lower()
    if join != "miter":
        out["stroke-linejoin"] = join
    lim = parse_number(style.get("stroke-miterlimit")) or 4.0  # the cascade dropped values below 1
    if lim >= 1.0 and lim != 4.0:
        out["stroke-miterlimit"] = _num(lim)
    dashes = _dashes(style.get("stroke-dasharray"), vp)
    if dashes:
        out["stroke-dasharray"] = ",".join(_num(d * scale) for d in dashes)
        offset = length(style.get("stroke-dashoffset"), vp, 0.0)
        if offset:
            out["stroke-dashoffset"] = _num(offset * scale)
    return out


def _dashes(value: str | None, vp: Viewport) -> list[float] | None:
    """Resolve a dash array: None for solid (``none``, negative or all-zero values)."""
    if value is None or value.strip().lower() == "none":
        return None
    out = []
    for part in value.replace(",", " ").split():
        got = parse_length(part)
        if got is None:
            return None
        v = to_user(got, vp)
        if not math.isfinite(v) or v < 0:
            return None
        out.append(v)
    if not out or sum(out) <= 0:
        return None
    if len(out) % 2:
        out = out * 2
    return out


def paint_declarations(kind: str, paint: Paint, opacity: float) -> dict[str, str]:
    """Declarations of a fill or stroke: colour or reference, and its opacity below 1."""
    if paint is None:
        return {kind: "none"}
    what, value, alpha = paint
    out = {kind: value if what == "color" else f"url({value})"}
    op = opacity * alpha
    if op < 1.0:
        out[f"{kind}-opacity"] = _num(op)
    return out
