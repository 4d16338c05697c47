"""How far an element is from its terminal drawn at a pose: a symmetric outline distance.

The deviation of an element from a posed shape is the larger of two one-sided distances
(the Hausdorff distance of the outlines): how far the element's samples lie from the shape,
and how far the shape's samples lie from the element.  The side that is looked up is a
polyline through points on each of its cubics, their ends included, so distances are to the
outline (exact at corners, within the sagitta on curves), not to its nearest sample.
Elements that are exact copies (the first side vanishes and the outline lengths agree) skip
the second side.

A copy drawn with the same segments as its shape needs neither side: a cubic is a convex
combination of its control points, so the largest distance between corresponding control
points bounds the outline distance.  Where that bound is negligible (within ``exact``, or a
millionth of the element's size) it is the deviation, found in O(segments) without
polylines: a single path of 10^6 lines, alone with its shape, took 16·10^6 polyline points
and a k-d tree over them (about 2.4 GiB) to confirm what its control points tell.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from lsys_core.instancing.sampling import arc_fractions, sample_elements
from lsys_core.svg.model import Element

__all__ = ["pose_deviations"]

#: Samples of the side that looks; points per cubic of the polyline that is looked up.
_COARSE = 64
_PER_CUBIC = 16
#: A control-point bound this small against the element's size is taken as the deviation.
_NEGLIGIBLE = 1e-6
#: Point-segment distances computed at once, at most.
_BLOCK = 1 << 21
#: Segments compared with their shape's at once, at most.
_SAME_BLOCK = 1 << 16


def _polyline(cubics: np.ndarray, per: int = _PER_CUBIC) -> tuple[np.ndarray, np.ndarray]:
    """Points on every cubic (ends included) and, per point, the next point on the same cubic.

    Segment ends are points of the outline, so corners are exact; the chords of a curve lie
    within its sagitta.
    """
    from lsys_core.instancing.sampling import bezier

    c = np.asarray(cubics, complex).reshape(-1, 4)
    t = np.linspace(0.0, 1.0, per)
    pts = bezier(c[:, None, :].repeat(per, axis=1).reshape(-1, 4), np.tile(t, c.shape[0]))[0]
    nxt = np.arange(pts.size) + 1
    nxt[per - 1 :: per] -= 1  # the last point of a cubic starts no segment
    return pts, nxt


def _to_segments(q: np.ndarray, p0: np.ndarray, p1: np.ndarray) -> np.ndarray:
    """Distance from points ``q`` to segments ``p0 p1`` (broadcast)."""
    d = p1 - p0
    den = np.abs(d) ** 2
    t = np.clip(((q - p0) * np.conj(d)).real / np.where(den > 0, den, 1.0), 0.0, 1.0)
    return np.abs(q - (p0 + t * d))


def _farthest(q: np.ndarray, p0: np.ndarray, p1: np.ndarray) -> float:
    """Largest distance from a point of ``q`` to the segments ``p0 p1`` (in blocks of bounded size)."""
    step = max(1, _BLOCK // max(p0.size, 1))
    worst = 0.0
    for lo in range(0, q.size, step):
        d = _to_segments(q[lo : lo + step, None], p0[None, :], p1[None, :]).min(axis=1)
        worst = max(worst, float(d.max()))
    return worst


def _to_outline(q: np.ndarray, pts: np.ndarray, nxt: np.ndarray) -> np.ndarray:
    """Distance from points ``q`` to the polyline (``pts``, ``nxt``): via the nearest point's segments."""
    prv = np.arange(nxt.size) - 1
    prv[np.r_[0, np.flatnonzero(nxt[:-1] == np.arange(nxt.size - 1)) + 1]] += 1  # first point of a cubic
    k = min(3, pts.size)  # a cubic's end and the next one's start coincide: look at both
    _, nn = cKDTree(np.column_stack([pts.real, pts.imag])).query(np.column_stack([q.real, q.imag]), k=k)
    nn = nn.reshape(q.size, k)
    qq = q[:, None]
    d = np.minimum(_to_segments(qq, pts[nn], pts[nxt[nn]]), _to_segments(qq, pts[prv[nn]], pts[nn]))
    return d.min(axis=1)


def _same_segments(
    elements: tuple[Element, ...] | list[Element],
    shapes: list[Element],
    which: np.ndarray,
    a: np.ndarray,
    b: np.ndarray,
    exact: float,
) -> tuple[np.ndarray, np.ndarray]:
    """Deviations bounded by corresponding control points, and the elements that need sampling.

    Returns the bound where it is negligible (0 elsewhere) and the indices of the other elements.
    The segments are compared in blocks of at most :data:`_SAME_BLOCK` (a path of 10^6 segments
    compared in one pass took about 280 MiB of temporaries), all elements' segments one after
    another (per element in Python, the comparison took 0.6 s for 50,000 leaves).
    """
    n = which.size
    count = np.array([e.cubics.shape[0] for e in elements], np.int64)
    shape_count = np.array([s.cubics.shape[0] for s in shapes], np.int64)
    same = np.flatnonzero((count == shape_count[which]) & (count > 0))
    out = np.zeros(n)
    if same.size == 0:
        return out, np.arange(n)
    a_same, b_same = a[same], b[same]
    counts = count[same]
    ends = np.cumsum(counts)
    starts = ends - counts
    total = int(ends[-1])
    parts = [elements[i].cubics for i in same.tolist()]
    shape_cubics = np.concatenate([_cubics(s) for s in shapes])
    shape_start = (np.cumsum(shape_count) - shape_count)[which[same]]
    gap = np.empty(total)  # per segment of the elements of ``same``, one after another
    size = np.empty(total)
    for lo in range(0, total, _SAME_BLOCK):
        hi = min(lo + _SAME_BLOCK, total)
        seg = np.arange(lo, hi)
        owner = np.searchsorted(ends, seg, side="right")  # index into ``same``
        j0, j1 = int(owner[0]), int(owner[-1])
        own = _block(parts, starts, j0, j1, lo, hi)
        first = own[np.maximum(starts[j0 : j1 + 1] - lo, 0), 0]  # every element's first point
        if starts[j0] < lo:
            first[0] = complex(np.ravel(parts[j0])[0])
        posed = shape_cubics[shape_start[owner] + (seg - starts[owner])]
        gap[lo:hi] = np.abs(a_same[owner, None] * posed + b_same[owner, None] - own).max(axis=1)
        size[lo:hi] = np.abs(own - first[owner - j0, None]).max(axis=1)
    bound = np.maximum.reduceat(gap, starts)  # per element of ``same``: the largest gap, the extent
    extent = np.maximum.reduceat(size, starts)
    ok = bound <= np.maximum(exact, _NEGLIGIBLE * extent)
    out[same[ok]] = bound[ok]
    todo = np.ones(n, bool)
    todo[same[ok]] = False
    return out, np.flatnonzero(todo)


def _block(parts: list, starts: np.ndarray, j0: int, j1: int, lo: int, hi: int) -> np.ndarray:
    """Segments ``lo:hi`` of the cubics ``parts`` (of elements ``j0 … j1``) one after another, ``(hi - lo, 4)``.

    Only the first and last parts are cut (by flat views): the block is one copy, not one
    conversion and slice per element (those took 65 ms of every 50,000-leaf comparison).
    """
    s0 = 4 * int(starts[j0])
    if j0 == j1:
        flat = np.ravel(parts[j0])[4 * lo - s0 : 4 * hi - s0]
    else:
        s1 = 4 * int(starts[j1])
        flat = np.concatenate(
            [np.ravel(parts[j0])[4 * lo - s0 :], *parts[j0 + 1 : j1], np.ravel(parts[j1])[: 4 * hi - s1]],
            axis=None,
        )
    return np.asarray(flat, complex).reshape(-1, 4)


def _cubics(e: Element) -> np.ndarray:
    return np.asarray(e.cubics, complex).reshape(-1, 4)


def pose_deviations(
    elements: tuple[Element, ...] | list[Element],
    shapes: list[Element],
    which: np.ndarray,
    a: np.ndarray,
    b: np.ndarray,
    *,
    exact: float = 0.0,
) -> np.ndarray:
    """Deviation of every element from ``shapes[which[i]]`` drawn at pose ``(a[i], b[i])``.

    Parameters
    ----------
    elements : sequence of Element
        The elements (document coordinates).
    shapes : list of Element
        The shapes, each in its local frame.
    which : ndarray of int
        The shape of every element.
    a, b : ndarray of complex
        Pose of every element's shape: ``z -> a*z + b``.
    exact : float
        Deviations up to this on the first side are taken as exact copies (second side skipped);
        a control-point bound up to this is taken as the deviation.

    Returns
    -------
    ndarray of float
        The symmetric distance, in document units.
    """
    which = np.asarray(which)
    out, todo = _same_segments(elements, shapes, which, a, b, exact)
    if todo.size:
        out[todo] = _sampled([elements[i] for i in todo], shapes, which[todo], a[todo], b[todo], exact)
    return out


def _sampled(
    elements: list[Element],
    shapes: list[Element],
    which: np.ndarray,
    a: np.ndarray,
    b: np.ndarray,
    exact: float,
) -> np.ndarray:
    """:func:`pose_deviations` measured on polylines (see the module docstring)."""
    out = np.zeros(len(elements))
    el = sample_elements(elements, arc_fractions(_COARSE))
    lines = {int(s): _polyline(shapes[int(s)].cubics) for s in np.unique(which)}
    length = np.zeros(len(shapes))
    for s, (pts, nxt) in lines.items():
        idx = np.flatnonzero(which == s)
        local = ((el.points[idx] - b[idx, None]) / a[idx, None]).ravel()
        out[idx] = _to_outline(local, pts, nxt).reshape(idx.size, -1).max(axis=1) * np.abs(a[idx])
        length[s] = float(np.sum(np.abs(pts[nxt] - pts)))
    # an element on a part of the shape is near it everywhere: the outline lengths tell
    same_length = np.abs(el.length - length[which] * np.abs(a)) <= 1e-3 * np.maximum(el.length, 1e-300)
    for i in np.flatnonzero((out > exact) | ~same_length):
        # both sides from every point of both polylines (corners and curve ends included)
        pts, nxt = _polyline(elements[i].cubics)
        spts, snxt = lines[int(which[i])]
        posed = a[i] * spts + b[i]
        there = _farthest(posed, pts, pts[nxt])
        back = _farthest(pts, posed, posed[snxt])
        out[i] = max(out[i], there, back)
    return out
