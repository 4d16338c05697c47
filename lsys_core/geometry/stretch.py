"""Stretching a shape along its local y axis: a cut along ``y = 0`` and its halves pulled apart.

A terminal drawn with stretch ``t`` (the turtle command ``~(t)``) is its path with every point
of ``y > 0`` moved by ``+t/2`` along y and every point of ``y < 0`` by ``-t/2`` (points on the
cut stay).  It is a piecewise translation, a nine-slice along one axis, not a scale: rounded
corners, arcs and stroke widths keep their size, and a bar of height ``h`` drawn with stretch
``t`` is the same bar with height ``h + t``.  Applied to control points it is exact for every
segment that does not cross the cut, and for straight segments that do (their inner control
points are put back at a third and two thirds of the moved chord, so they stay lines); a curve
crossing the cut is deformed, which is why the inference checks every stretched instance
against its element.
"""

from __future__ import annotations

import numpy as np

from lsys_core.geometry.paths import collinear_thirds

__all__ = ["stretch_cubics", "stretch_path"]

#: A cubic whose inner control points lie within this share of its chord from a third and two
#: thirds of it is a straight segment (as path data writes ``L``).
_STRAIGHT = 1e-9


def stretch_cubics(cubics: np.ndarray, t: float) -> np.ndarray:
    """Return cubic segments ``(k, 4)`` (complex, local frame) stretched by ``t`` along y."""
    c = np.asarray(cubics, dtype=complex).reshape(-1, 4)
    if t == 0 or c.size == 0:
        return c.copy()
    extent = float(np.max(np.abs(c))) if c.size else 0.0
    y = c.imag
    side = np.where(np.abs(y) <= 1e-12 * max(extent, 1e-300), 0.0, np.sign(y))
    out = c + 1j * (0.5 * float(t)) * side
    chord = np.abs(c[:, 3] - c[:, 0])
    straight = (chord > 0) & collinear_thirds(c, _STRAIGHT * np.maximum(chord, 1e-300))
    q0, q3 = out[straight, 0], out[straight, 3]
    out[straight, 1] = (2 * q0 + q3) / 3
    out[straight, 2] = (q0 + 2 * q3) / 3
    return out


def stretch_path(d: str, t: float) -> str:
    """Return SVG path data ``d`` (a terminal's, in its local frame) stretched by ``t`` along y."""
    from lsys_core.geometry.paths import d_from_cubics
    from lsys_core.geometry.shapes import shape_arrays

    if t == 0:
        return d
    cubics, subpaths, closed = shape_arrays(d)
    return d_from_cubics(stretch_cubics(cubics, t), subpaths, closed)
