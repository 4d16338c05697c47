"""Where a drawing goes in an image: the view fitted into it, and the size of a PNG of it.

The view is the drawing's viewBox, else its bounds with a margin (:func:`default_view`);
:func:`fit_view` centres it in an image, aspect kept.  :func:`png_size` chooses a PNG's size
from the requested one or the document's own size in its units.
"""

from __future__ import annotations

import math

from lsys_core.derive.model import Drawing
from lsys_core.render.units import CSS_DPI, length_px

__all__ = ["default_view", "fit_view", "png_size"]


def fit_view(view: tuple[float, float, float, float], width: int, height: int) -> tuple[float, float, float]:
    """Return ``(scale, tx, ty)`` mapping ``view`` (x, y, w, h) centred into a width×height image."""
    x, y, w, h = (float(v) for v in view)
    w = w if w > 0 and math.isfinite(w) else 1.0
    h = h if h > 0 and math.isfinite(h) else 1.0
    s = min(width / w, height / h)
    tx = (width - s * w) / 2.0 - s * x
    ty = (height - s * h) / 2.0 - s * y
    return s, tx, ty


def default_view(drawing: Drawing) -> tuple[float, float, float, float]:
    """Return the drawing's viewBox, or its bounds with a small margin, or a unit square."""
    if drawing.viewbox is not None:
        return drawing.viewbox
    from lsys_core.render.svg import MARGIN, drawing_bounds

    bounds = drawing_bounds(drawing)
    if bounds is None:
        return (0.0, 0.0, 1.0, 1.0)
    x0, y0, x1, y1 = bounds
    m = MARGIN * max(x1 - x0, y1 - y0) or 1.0
    return (x0 - m, y0 - m, x1 - x0 + 2 * m, y1 - y0 + 2 * m)


def png_size(
    drawing: Drawing,
    width: int | None,
    height: int | None,
    dpi: float,
    max_side: int,
    max_pixels: int,
) -> tuple[int, int]:
    """Choose the PNG size: as given, else the document's size in its units at ``dpi``, aspect kept.

    Without ``width`` and ``height`` the size is the drawing's ``width``/``height`` converted
    from their units (``cm``, ``in``, ``pt``, … at 96 CSS px per inch) to pixels at ``dpi``;
    a missing or relative (``%``) size falls back to the viewBox size in user units.  Sides are
    capped at ``max_side`` and the image at ``max_pixels`` pixels (scaled down, aspect kept).
    """
    _, _, vw, vh = default_view(drawing)
    aspect = vw / vh if vw > 0 and vh > 0 else 1.0
    if width is not None and height is not None:
        w, h = int(width), int(height)
    elif height is not None:
        h = int(height)
        w = max(1, round(h * aspect))
    elif width is not None:
        w = int(width)
        h = max(1, round(w / aspect))
    else:
        size = drawing.size
        given_w = length_px(size[0]) if size else None
        given_h = length_px(size[1]) if size else None
        if given_w is not None:
            fw, fh = given_w, given_h if given_h is not None else given_w / aspect
        elif given_h is not None:
            fw, fh = given_h * aspect, given_h
        else:
            fw, fh = vw, vh
        scale = dpi / CSS_DPI
        w, h = max(1, round(fw * scale)), max(1, round(fh * scale))
    w, h = min(w, max_side), min(h, max_side)
    if w * h > max_pixels:
        shrink = math.sqrt(max_pixels / (w * h))
        w, h = max(1, int(w * shrink)), max(1, int(h * shrink))
    return w, h
