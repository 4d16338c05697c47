"""Stage 5, output: a :class:`~lsys_core.derive.Drawing` as SVG text or as pixels (skia)."""

from __future__ import annotations

from lsys_core.render.raster import Renderer, encode_png, render, render_png
from lsys_core.render.structured import drawing_to_structured_svg
from lsys_core.render.svg import drawing_bounds, drawing_to_svg, export_svg

__all__ = [
    "Renderer",
    "drawing_bounds",
    "drawing_to_structured_svg",
    "drawing_to_svg",
    "encode_png",
    "export_svg",
    "render",
    "render_png",
]
