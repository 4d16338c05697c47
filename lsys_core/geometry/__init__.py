"""Stage 0, geometry: similarity transforms and poses, path data as arrays of cubic Béziers.

Everything above uses these: points are complex numbers ``x + iy`` (SVG user units, y down), a
pose is ``z -> a*z + b``, a shape is a ``(k, 4)`` complex array of cubic control points.
"""

from __future__ import annotations

from lsys_core.geometry.bezier import (
    bezier_points,
    cubics_bounds,
    sample_cubics,
    sample_uniform,
    transform_cubics,
)
from lsys_core.geometry.paths import MAX_COORD, cubics_from_d, d_from_cubics
from lsys_core.geometry.shapes import shape_arrays
from lsys_core.geometry.transforms import DEG, frames_to_matrices, wrap_deg

__all__ = [
    "DEG",
    "MAX_COORD",
    "bezier_points",
    "cubics_bounds",
    "cubics_from_d",
    "d_from_cubics",
    "frames_to_matrices",
    "sample_cubics",
    "sample_uniform",
    "shape_arrays",
    "transform_cubics",
    "wrap_deg",
]
