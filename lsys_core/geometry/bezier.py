"""Evaluating, sampling, transforming and bounding arrays of cubic Bézier segments.

Shapes are ``(k, 4)`` complex arrays of control points (see :mod:`lsys_core.geometry.paths`).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["bezier_points", "cubics_bounds", "sample_cubics", "sample_uniform", "transform_cubics"]


def bezier_points(cubics: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Evaluate every segment at parameters ``t``; return shape ``(k, len(t))``."""
    cubics = np.asarray(cubics, dtype=complex).reshape(-1, 4)
    t = np.asarray(t, dtype=float)[None, :]
    s = 1.0 - t
    p0, c1, c2, p3 = (cubics[:, i : i + 1] for i in range(4))
    return (s * s * s) * p0 + (3.0 * s * s * t) * c1 + (3.0 * s * t * t) * c2 + (t * t * t) * p3


def sample_cubics(cubics: np.ndarray, n_per_segment: int) -> np.ndarray:
    """Sample every segment at ``n_per_segment`` evenly spaced parameters.

    Parameters are ``linspace(0, 1, n)`` per segment, so segment end points are
    included (a joint appears as the last sample of one segment and the first of
    the next).

    Returns
    -------
    ndarray of complex, shape (k * n_per_segment,)
    """
    n = int(n_per_segment)
    if n < 1:
        raise ValueError("n_per_segment must be at least 1")
    t = np.linspace(0.0, 1.0, n) if n > 1 else np.zeros(1)
    return bezier_points(cubics, t).reshape(-1)


def sample_uniform(cubics: np.ndarray, n: int, *, dense: int | None = None) -> np.ndarray:
    """Sample ``n`` points spaced uniformly by arc length along all segments in order.

    The gaps between subpaths (or between segments that do not join) do not count
    as length.  The first and last points are the path's start and end.

    Parameters
    ----------
    cubics : ndarray of complex, shape (k, 4)
    n : int
        Number of points.
    dense : int, optional
        Samples per segment used to measure length (default: enough for ``4 * n``
        samples in all, at least 16 per segment).

    Returns
    -------
    ndarray of complex, shape (n,)
    """
    cubics = np.asarray(cubics, dtype=complex).reshape(-1, 4)
    n = int(n)
    k = len(cubics)
    if n <= 0:
        return np.zeros(0, dtype=complex)
    if k == 0:
        raise ValueError("cannot sample an empty path")
    m = dense if dense is not None else max(16, min(256, math.ceil(4 * n / k)))
    t = np.linspace(0.0, 1.0, m)
    pts = bezier_points(cubics, t)  # (k, m)
    seg = np.abs(np.diff(pts, axis=1))  # (k, m-1)
    local = np.concatenate([np.zeros((k, 1)), np.cumsum(seg, axis=1)], axis=1)  # (k, m)
    offsets = np.concatenate([[0.0], np.cumsum(local[:, -1])[:-1]])
    cum = (local + offsets[:, None]).ravel()
    param = (np.arange(k)[:, None] + t[None, :]).ravel()
    total = cum[-1]
    if total <= 0.0:
        return np.full(n, cubics[0, 0])
    target = np.linspace(0.0, total, n)
    u = np.interp(target, cum, param)
    idx = np.minimum(u.astype(np.intp), k - 1)
    tt = u - idx
    s = 1.0 - tt
    c = cubics[idx]
    return (
        (s * s * s) * c[:, 0] + (3 * s * s * tt) * c[:, 1] + (3 * s * tt * tt) * c[:, 2] + (tt**3) * c[:, 3]
    )


def transform_cubics(cubics: np.ndarray, matrix) -> np.ndarray:
    """Apply an affine ``matrix`` ``(a, b, c, d, e, f)`` (SVG order) to control points."""
    a, b, c, d, e, f = (float(v) for v in matrix)
    x, y = cubics.real, cubics.imag
    return (a * x + c * y + e) + 1j * (b * x + d * y + f)


def cubics_bounds(cubics: np.ndarray) -> tuple[float, float, float, float]:
    """Return ``(xmin, ymin, xmax, ymax)`` of the control points (contains the curve)."""
    c = np.asarray(cubics, dtype=complex)
    return (float(c.real.min()), float(c.imag.min()), float(c.real.max()), float(c.imag.max()))
