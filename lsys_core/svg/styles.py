"""Drawing styles of svgelements shapes as CSS declaration strings."""

from __future__ import annotations

import math

__all__ = ["own_opacity", "style_of", "unit_float"]


def own_opacity(node) -> float:
    """Return the ``opacity`` set on the element itself (not inherited), clamped to [0, 1]."""
    attrs = node.values.get("attributes")
    raw = attrs.get("opacity") if isinstance(attrs, dict) else None
    v = unit_float(raw, 1.0)
    return 1.0 if v is None else v


def unit_float(raw, default: float | None) -> float | None:
    """Parse an opacity-like value (number or percentage) clamped to [0, 1]."""
    if raw is None:
        return default
    text = str(raw).strip()
    try:
        v = float(text[:-1]) / 100.0 if text.endswith("%") else float(text)
    except ValueError:
        return default
    if not math.isfinite(v):
        return default
    return min(1.0, max(0.0, v))


def _num(v: float) -> str:
    """Format a style number compactly."""
    return f"{v:.6g}"


def style_of(shape, vp_scale: float, opacity: float) -> str | None:
    """Return the resolved drawing style of a shape as CSS declarations (None if unusable)."""
    values = shape.values
    parts: list[str] = []
    fill = shape.fill
    if fill is None or fill.value is None:
        parts.append("fill:none")
    else:
        parts.append(f"fill:{fill.hexrgb}")
        fo = unit_float(values.get("fill-opacity"), None) if "fill-opacity" in values else None
        fo = fill.opacity if fo is None else fo
        if fo < 1.0:
            parts.append(f"fill-opacity:{_num(fo)}")
        rule = str(values.get("fill-rule", "")).strip().lower()
        if rule == "evenodd":
            parts.append("fill-rule:evenodd")
    stroke = shape.stroke
    if stroke is None or stroke.value is None:
        parts.append("stroke:none")
    else:
        parts.append(f"stroke:{stroke.hexrgb}")
        width = shape.implicit_stroke_width
        width = 1.0 if width is None else float(width) / vp_scale
        if not math.isfinite(width):
            return None
        parts.append(f"stroke-width:{_num(max(width, 0.0))}")
        so = unit_float(values.get("stroke-opacity"), None) if "stroke-opacity" in values else None
        so = stroke.opacity if so is None else so
        if so < 1.0:
            parts.append(f"stroke-opacity:{_num(so)}")
        cap = str(values.get("stroke-linecap", "")).strip().lower()
        if cap in ("round", "square"):
            parts.append(f"stroke-linecap:{cap}")
        join = str(values.get("stroke-linejoin", "")).strip().lower()
        if join in ("round", "bevel", "miter-clip", "arcs"):
            parts.append(f"stroke-linejoin:{join}")
    if opacity < 1.0:
        parts.append(f"opacity:{_num(opacity)}")
    return ";".join(parts)
