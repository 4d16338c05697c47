"""Instances the fast passes cannot draw (gradients, clip paths, dashes, stroke under fill), drawn one by one.

A paint server's coordinates are the canvas's (``userSpaceOnUse``) or the painted shape's box
there (``objectBoundingBox``), as the SVG export writes such instances baked into canvas
coordinates.  So each one is drawn as its outline mapped by its pose into the canvas, with
the gradient's shader (:mod:`.paint_servers`) over that outline's box, its stroke width in
canvas units (times the scale for a ``scaled`` terminal) and dashed likewise, its
``paint-order``, its ``opacity`` as a group and its clip path (:mod:`.clipping`).
The fast passes of :mod:`.raster` leave these instances out; :class:`~.kept.Kept` places
them in the paint order.  Patterns and servers that cannot be found use the fallback colour.
skia is imported inside the functions.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import lru_cache
from typing import Any

import numpy as np

from lsys_core.derive.model import Drawing
from lsys_core.grammar.model import Terminal
from lsys_core.render.clipping import clip_region
from lsys_core.render.kept_style import group_opacity, lengths, shape_paints
from lsys_core.render.paint_servers import defs_index, gradient_shader, server_id
from lsys_core.render.paths import parse_style

__all__ = ["draw_served", "served_instances"]


def _served_style(style: str) -> bool:
    """Whether the fast passes cannot draw this style: paint servers, clips, dashes, stroke first."""
    decls = parse_style(style)
    if any("url(" in decls.get(k, "").lower() for k in ("fill", "stroke", "clip-path")):
        return True
    if decls.get("stroke-dasharray", "none").strip().lower() != "none":
        return True
    return decls.get("paint-order", "normal").split()[:1] == ["stroke"]


def served_instances(drawing: Drawing) -> np.ndarray:
    """Return the indices of the instances whose fill, stroke or clip path is a ``url(#id)``, whose
    stroke is dashed, or whose ``paint-order`` puts the stroke first."""
    n = len(drawing)
    if n == 0:
        return np.zeros(0, np.intp)
    styles, style = drawing.instance_styles()
    served = np.array([_served_style(s) for s in styles] + [False])
    if not served.any():
        return np.zeros(0, np.intp)
    index = np.asarray(style, np.intp).reshape(n)
    index = np.where((index >= 0) & (index < len(styles)), index, len(styles))
    return np.flatnonzero(served[index])


@lru_cache(maxsize=256)
def _clip(
    value: str, defs: str, viewport: tuple[float, float], bbox: tuple[float, float, float, float] | None
):
    """A clip path's region (cached: instances share their clip paths, redraws repeat them)."""
    return clip_region(value, defs_index(defs).get, bbox, viewport)


@lru_cache(maxsize=1024)
def _plain(css: str, scale: float, viewport: tuple[float, float]) -> tuple[dict[str, str], tuple]:
    """A style's declarations (lengths times ``scale``) and, without paint servers, its paints."""
    decls = parse_style(css)
    if scale != 1.0:  # a scaled terminal: its stroke scales with the instance
        for key in ("stroke-width", "stroke-dasharray", "stroke-dashoffset"):
            values = lengths(decls.get(key), decls, viewport)
            if values:
                decls[key] = " ".join(repr(v * scale) for v in values)
    served = any("url(" in decls.get(k, "") for k in ("fill", "stroke"))
    return decls, () if served else tuple(shape_paints(decls, True, None, viewport))


def draw_served(
    canvas,
    term: Terminal,
    css: str,
    a: complex,
    b: complex,
    terminal: Callable[[str, str], Any],
    defs: str,
    viewport: tuple[float, float],
    view: tuple[float, float, float],
) -> None:
    """Draw an instance of ``term`` in style ``css`` at pose ``(a, b)`` under the view ``(scale, tx, ty)``.

    ``terminal(path, style)`` gives the renderer's cached skia objects of a terminal; ``defs``
    is the drawing's definitions markup.  Paints without paint servers are cached per style.
    """
    import skia

    if not (np.isfinite(a) and np.isfinite(b)):
        return
    find = defs_index(defs).get
    path = skia.Path(terminal(term.path, css).path)
    path.transform(skia.Matrix.MakeAll(a.real, -a.imag, b.real, a.imag, a.real, b.imag, 0, 0, 1))
    decls, paints = _plain(css, abs(a) if term.scaled else 1.0, viewport)
    bbox = (0.0, 0.0, 0.0, 0.0)
    if "url(" in css:  # paint servers and clip paths may need the box
        box = path.computeTightBounds()
        bbox = (box.left(), box.top(), box.right(), box.bottom())
    if any("url(" in decls.get(k, "") for k in ("fill", "stroke")):

        def servers(value: str) -> Any:
            return gradient_shader(value, find, bbox, viewport)

        paints = tuple(shape_paints(decls, True, servers, viewport))
    alpha = group_opacity(decls)
    if not paints or alpha <= 0.0:
        return
    s, tx, ty = view
    canvas.save()
    canvas.setMatrix(skia.Matrix.MakeAll(s, 0, tx, 0, s, ty, 0, 0, 1))
    if "url(" in decls.get("clip-path", ""):
        clip = find(server_id(decls["clip-path"]) or "")
        boxed = clip is not None and clip.get("clipPathUnits", "").strip() == "objectBoundingBox"
        region = _clip(decls["clip-path"], defs, viewport, bbox if boxed else None)
        if region is not None:
            canvas.clipPath(region, skia.ClipOp.kIntersect, True)
    if alpha < 1.0:
        canvas.saveLayerAlpha(None, round(alpha * 255))
    for paint in paints:
        canvas.drawPath(path, paint)
    if alpha < 1.0:
        canvas.restore()
    canvas.restore()
