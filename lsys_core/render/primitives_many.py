"""Basic shapes of many terminals at once: cheap vectorised rejections, the full test on the rest.

:func:`~lsys_core.render.primitives.primitive` costs about 0.3 ms per parsed path, nearly all
of it numpy's fixed cost per call on arrays of a few points (a conic fit by SVD, least-squares
radii, straightness tests): a drawing of 10,000 distinct small leaves spent 2.6 s of its export
in it (14 s of 15 under the profiler).  :func:`primitives` gives the same answers for a list of
paths: it parses the new ones in passes of many (:func:`~lsys_core.geometry.shapes.shapes_arrays`)
and rejects, with array operations over all paths at once, those that certainly are no circle,
ellipse, rectangle or line; only the others go through the full test one by one.  The same
10,000 leaves take 0.12 s so (0.33 s with their parsing).

A rejection is made only where it is beyond doubt: every quantity compared with a threshold
is computed here in bulk, in an order of operations that can round differently from the full
test's, so a path is rejected only when it misses the threshold by far more than rounding
(:data:`_MARGIN`); an SVD whose smallest singular vector is ill-determined rejects nothing.
A test (``tests/core/test_primitives_many.py``) checks the answers against the full test's
on random near-circles, near-ellipses, near-rectangles, lines and leaves.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from lsys_core.geometry.shapes import ptp_at, shapes_arrays
from lsys_core.render.primitives import TOLERANCE, chord_frame, primitive_of

__all__ = ["Shape", "primitives"]

#: Relative distance from a threshold below which a bulk-computed quantity decides nothing.
_MARGIN = 1e-7
#: Samples per segment (as the full test's ellipse fit).
_SAMPLES = 8
#: Segments tested at once (bounds the temporaries, some 200 bytes a segment).
_BLOCK = 1 << 14
#: Smallest gap between the two smallest singular values of a conic fit, relative to the
#: largest, for the fit to be trusted to reject.
_GAP = 1e-6

#: A basic element: its tag and attributes.
Shape = tuple[str, dict[str, str]]


def primitives(ds: Sequence[str]) -> list[Shape | None]:
    """Return :func:`~lsys_core.render.primitives.primitive` of every path data text.

    Parameters
    ----------
    ds : sequence of str
        SVG path data texts (terminals' paths, in their local frames).

    Returns
    -------
    list
        Per text, ``(tag, attributes)`` or None, exactly as ``primitive(d)`` returns it.
    """
    arrays = shapes_arrays(ds)
    out: list[Shape | None] = [None] * len(ds)
    cand: list[int] = []  # the paths of one subpath (the others are none of the shapes)
    parts: list[np.ndarray] = []
    flags: list[bool] = []
    for i, found in enumerate(arrays):
        if found is not None and found[0].shape[0] > 0 and len(found[2]) == 1:
            cand.append(i)
            parts.append(found[0])
            flags.append(found[2][0])
    if not cand:
        return out
    counts = np.fromiter((c.shape[0] for c in parts), np.intp, len(parts))
    cubics = np.concatenate(parts)
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    closed = np.array(flags, dtype=bool)
    finite = np.logical_and.reduceat(np.isfinite(cubics).all(axis=1), starts)
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        size = ptp_at(cubics.real, starts) + ptp_at(cubics.imag, starts)
        tol = TOLERANCE * size
        keep = finite & (size > 0)
        seg_tol = np.repeat(tol, counts)
        tests = [
            _straight_bounds(cubics[lo : lo + _BLOCK], seg_tol[lo : lo + _BLOCK])
            for lo in range(0, len(cubics), _BLOCK)
        ]
        straight, unsure = (np.concatenate(t) for t in zip(*tests, strict=True))
        n_straight = np.add.reduceat(straight.astype(np.intp), starts)
        n_unsure = np.add.reduceat(unsure.astype(np.intp), starts)
    sure = n_unsure == 0
    # a line: one open segment, straight; a rectangle: four or more straight sides (a rounded
    # one: four straight sides and curved corners); otherwise an ellipse: no straight side
    keep &= np.where(
        closed, ~sure | (n_straight >= 4) | (n_straight == 0), (counts == 1) & ~(sure & (n_straight == 0))
    )
    oval = np.flatnonzero(keep & closed & sure & (n_straight == 0))
    with np.errstate(invalid="ignore", over="ignore", divide="ignore", under="ignore"):
        keep[oval] = ~_surely_no_ellipse(cubics, starts[oval], counts[oval], tol[oval])
    for j in np.flatnonzero(keep).tolist():
        a = arrays[cand[j]]
        assert a is not None
        out[cand[j]] = primitive_of(a[0], a[2])
    return out


def _straight_bounds(
    cubics: np.ndarray, tol: np.ndarray, max_angle: float = 1e-3
) -> tuple[np.ndarray, np.ndarray]:
    """The straightness test of :func:`~lsys_core.render.primitives._straight` with its doubt.

    Returns ``(straight, unsure)``: what the test says, and where a condition is so close to
    its threshold that the full test might say otherwise.
    """
    length, safe, rel, off, start, end = chord_frame(cubics)
    # every condition as slack >= 0 (or > 0) and the scale of its rounding
    slack = [(tol - off, tol + off)]
    slack += [(r.real + tol, np.abs(r.real) + tol) for r in rel]
    slack += [(1 + tol - r.real, 1 + tol + np.abs(r.real)) for r in rel]
    slack += [(max_angle - np.abs(np.angle(t / safe)), np.full(t.shape, max_angle)) for t in (start, end)]
    straight = length > 0
    unsure = np.zeros(length.shape, bool)
    for s, scale in slack:
        straight &= s > 0
        unsure |= np.abs(s) <= _MARGIN * scale
    unsure &= length > 0
    return straight, unsure


def _surely_no_ellipse(
    cubics: np.ndarray, starts: np.ndarray, counts: np.ndarray, tol: np.ndarray
) -> np.ndarray:
    """Whether each path (all segments curved, one closed subpath) is certainly no ellipse.

    The full test's conic fit and radii, for the paths of each segment count at once; a path
    is rejected when the fitted conic is certainly no ellipse or some sample lies certainly
    farther from the fitted ellipse than the tolerance.
    """
    out = np.zeros(starts.size, bool)
    t = np.linspace(0.0, 1.0, _SAMPLES)[None, None, :]
    s = 1.0 - t
    weights = [s * s * s, 3.0 * s * s * t, 3.0 * s * t * t, t * t * t]
    for k in np.unique(counts).tolist():
        group = np.flatnonzero(counts == k)
        step = max(1, _BLOCK // (_SAMPLES * k))
        for lo in range(0, group.size, step):
            sel = group[lo : lo + step]
            out[sel] = _no_ellipse_rows(cubics, starts[sel], k, tol[sel], weights)
    return out


def _no_ellipse_rows(
    cubics: np.ndarray, starts: np.ndarray, k: int, tol: np.ndarray, weights: list[np.ndarray]
) -> np.ndarray:
    """:func:`_surely_no_ellipse` of paths of ``k`` segments each, sampled as the full test samples."""
    out = np.zeros(starts.size, bool)
    c = cubics[(starts[:, None] + np.arange(k)[None, :]).reshape(-1)].reshape(starts.size, k, 4)
    pts = weights[0] * c[:, :, 0:1]
    for j in (1, 2, 3):
        pts = pts + weights[j] * c[:, :, j : j + 1]
    pts = pts.reshape(starts.size, -1)
    span = np.maximum(np.ptp(pts.real, axis=1), np.ptp(pts.imag, axis=1))
    ok = np.isfinite(pts).all(axis=1) & (span > 0)  # the others are left to the full test
    out[ok] = _no_ellipse(pts[ok], tol[ok])
    return out


def _no_ellipse(pts: np.ndarray, tol: np.ndarray) -> np.ndarray:
    """:func:`_surely_no_ellipse` of paths sampled as the rows of ``pts``."""
    x, y = pts.real, pts.imag
    mx, my = x.mean(axis=1, keepdims=True), y.mean(axis=1, keepdims=True)
    scale = np.maximum(np.ptp(x, axis=1), np.ptp(y, axis=1))[:, None]
    u, v = (x - mx) / scale, (y - my) / scale
    design = np.stack([u * u, u * v, v * v, u, v, np.ones_like(u)], axis=-1)
    _, sv, vt = np.linalg.svd(design, full_matrices=False)
    trusted = (sv[:, -2] - sv[:, -1]) > _GAP * sv[:, 0]
    A, B, C, D, E = (vt[:, -1, j] for j in range(5))
    det = 4 * A * C - B * B  # the coefficients have norm 1
    no = trusted & (det < -_MARGIN)
    fit = trusted & (det > _MARGIN)
    det = np.where(fit, det, 1.0)
    uc = ((B * E - 2 * C * D) / det)[:, None]
    vc = ((B * D - 2 * A * E) / det)[:, None]
    theta = 0.5 * np.arctan2(B, A - C)
    ct, st = np.cos(theta)[:, None], np.sin(theta)[:, None]
    pu = (u - uc) * ct + (v - vc) * st
    pv = -(u - uc) * st + (v - vc) * ct
    # least-squares radii by the normal equations of pu²/ru² + pv²/rv² = 1
    a2, b2 = pu * pu, pv * pv
    g11, g12, g22 = (a2 * a2).sum(1), (a2 * b2).sum(1), (b2 * b2).sum(1)
    r1, r2 = a2.sum(1), b2.sum(1)
    gdet = g11 * g22 - g12 * g12
    fit &= gdet > 1e-8 * np.maximum(g11 * g22, 1e-300)
    gdet = np.where(fit, gdet, 1.0)
    iu, iv = (g22 * r1 - g12 * r2) / gdet, (g11 * r2 - g12 * r1) / gdet
    fit &= (iu > 0) & (iv > 0)
    ru, rv = 1.0 / np.sqrt(np.where(fit, iu, 1.0)), 1.0 / np.sqrt(np.where(fit, iv, 1.0))
    radial = np.hypot(pu / ru[:, None], pv / rv[:, None])
    error = np.abs(radial - 1.0).max(axis=1) * np.maximum(ru, rv) * scale[:, 0]
    no |= fit & (error > 1.5 * tol)
    return no
