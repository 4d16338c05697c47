"""SVG input and output: safe parsing into a Scene, path data as cubic arrays, export of a Drawing."""

from __future__ import annotations

from .export import drawing_bounds, drawing_to_svg, export_svg
from .parse import load_svg, parse_svg
from .pathdata import cubics_from_d, cubics_from_path, d_from_cubics, sample_cubics, sample_uniform

__all__ = [
    "cubics_from_d",
    "cubics_from_path",
    "d_from_cubics",
    "drawing_bounds",
    "drawing_to_svg",
    "export_svg",
    "load_svg",
    "parse_svg",
    "sample_cubics",
    "sample_uniform",
]
