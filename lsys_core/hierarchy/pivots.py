"""Choose each terminal's local origin so that rotating sequences become regular.

A terminal's local frame is first put at its representative's centroid.  When elements
of a row each turn a little more than the previous one about some point of the shape
(a leaf about its base), the transform between neighbours expressed at the centroid
is not constant in (d, s) and the sequence is missed.  Expressed at the pivot ``o``
(local coordinates), consecutive pivots differ by one constant world displacement ``D``:

    Δb + Δa · o = D        (Δb, Δa: differences of the two poses)

Every two pairs of one rotation cluster give an estimate of ``o``; the estimates are
clustered by mean shift and a well-supported mode with ``|D|`` comparable to the
spacing moves the terminal's origin there.

When *all* instances of a terminal are turned about one common point (``D = 0``: the
petals of one flower, the rays of one sun, copies rotated by ``rotate(θ cx cy)``), the
origin moves to that point: every instance then sits at the same place and differs only by
its turn, so a ring is written as a pure turn ``P(m) -> A +(360/n) P(m-1)`` and random turns
are seen for what they are (the same place, nothing to repeat).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy.spatial import cKDTree

from lsys_core.hierarchy.clustering import group_indices, mean_shift
from lsys_core.instancing.model import Instancing
from lsys_core.parallel import jobs

__all__ = ["estimate_pivots", "recenter"]

#: Points from which neighbours are looked up on all workers (for fewer, starting threads costs more).
_THREADED = 4096


def _pivot_for(a: np.ndarray, b: np.ndarray, size: float, tol_angle: float, rng) -> complex:
    n = a.size
    k = min(8, n - 1)
    pts = np.column_stack([b.real, b.imag])
    # the same neighbours for any number of workers (threads only pay off for many points)
    _, idx = cKDTree(pts).query(pts, k=k + 1, workers=jobs() if n >= _THREADED else 1)
    src = np.repeat(np.arange(n), k + 1)
    dst = np.asarray(idx).ravel()
    ok = (dst != src) & (dst < n)
    src, dst = src[ok], dst[ok]
    A = a[dst] / a[src]
    rot = np.angle(A)
    moving = np.abs(rot) > np.deg2rad(tol_angle)
    if moving.sum() < 4:
        return 0j
    src, dst, A = src[moving], dst[moving], A[moving]
    ang = np.deg2rad(tol_angle)
    lab, _ = mean_shift(
        np.column_stack([np.cos(np.angle(A)) / ang, np.sin(np.angle(A)) / ang, np.log(np.abs(A)) / 0.01])
    )
    spacing = float(np.median(np.abs(b[dst] - b[src])))
    groups = [g for g in group_indices(lab) if g.size >= 4]
    draws = []  # drawn in the groups' order, as the votes were when they ran one after another
    for g in groups:
        m = min(4000, g.size * (g.size - 1) // 2)
        draws.append((rng.integers(0, g.size, m), rng.integers(0, g.size, m)))

    def vote(task: tuple[np.ndarray, tuple[np.ndarray, np.ndarray]]) -> tuple[complex, int, complex] | None:
        """The pivot one rotation cluster votes for, its support and displacement (or None)."""
        g, (e1, e2) = task
        db = b[dst[g]] - b[src[g]]
        da = a[dst[g]] - a[src[g]]
        den = da[e1] - da[e2]
        good = np.abs(den) > 1e-9 * (np.abs(da[e1]) + 1e-300)
        if good.sum() < 3:
            return None
        o = (db[e2[good]] - db[e1[good]]) / den[good]
        o = o[np.isfinite(o) & (np.abs(o) < 20 * size)]
        if o.size < 3:
            return None
        _, modes = mean_shift(np.column_stack([o.real, o.imag]) / (0.02 * size))
        if modes.shape[0] == 0:
            return None
        cand = complex(*(modes[0] * 0.02 * size))
        D = db + da * cand
        lab2, dmodes = mean_shift(np.column_stack([D.real, D.imag]) / (0.02 * max(spacing, size)))
        return cand, int(np.sum(lab2 == 0)), complex(*(dmodes[0] * 0.02 * max(spacing, size)))

    # One after another on the calling thread: a vote is hundreds of small numpy calls that hold
    # the interpreter, so on two workers they wait for each other.  The 982 rotation clusters of
    # a published wind-vector chart (4,817 arrows) voted in 1.95-2.04 s of wall and 2.8-2.9 s of
    # CPU on two workers, 1.09-1.13 s on one (only its 134 clusters of 1,000 draws or more on the
    # workers: 1.26-1.30 s); the four of a 50,052-leaf grid in 0.13-0.14 s against 0.15 s.
    votes = [vote(task) for task in zip(groups, draws, strict=True)]
    best, best_support = 0j, 0
    for g, found in zip(groups, votes, strict=True):
        if found is None:
            continue
        cand, support, Dm = found
        if support >= max(3, g.size // 3) and abs(Dm) > 0.5 * spacing and support > best_support:
            best, best_support = cand, support
    return best if abs(best) > 0.05 * size else 0j


def _common_pivot(a: np.ndarray, b: np.ndarray, size: float, tolerance: float) -> complex:
    """The local point all poses ``(a, b)`` map to one place (within ``tolerance``), or 0.

    Solves ``b_i + a_i·o = P`` for ``o`` and ``P`` in the least-squares sense; the poses must
    turn (or scale) enough for ``o`` to be determined, and ``o`` must be near the shape.
    """
    if a.size < 3 or tolerance <= 0:
        return 0j
    spread = float(np.sqrt(np.mean(np.abs(a - a.mean()) ** 2)))
    if spread < 0.05 * float(np.mean(np.abs(a))):
        return 0j
    m = np.column_stack([a, -np.ones(a.size, complex)])
    sol = np.linalg.lstsq(m, -b, rcond=None)[0]
    o, p = complex(sol[0]), complex(sol[1])
    if not np.isfinite(o) or np.max(np.abs(b + a * o - p)) > tolerance:
        return 0j
    apart = np.max(np.abs(b - b.mean())) > tolerance  # the instances do not share a place yet
    return o if apart and abs(o) <= 20 * size else 0j


def estimate_pivots(
    inst: Instancing,
    sizes: np.ndarray,
    *,
    tol_angle: float = 1.0,
    tolerance: float = 0.0,
    seed: int = 0,
) -> np.ndarray:
    """Return, per terminal, the local offset of its pivot (0 where the centroid is kept).

    Parameters
    ----------
    inst : Instancing
        Similarity groups and poses.
    sizes : ndarray
        Radius of each terminal's shape in its local frame.
    tol_angle : float
        Rotations below this (degrees) do not count as turning.
    tolerance : float
        Largest distance (document units) between the places a common pivot maps to; 0
        looks for no common pivot.
    seed : int
        Seed of the vote sampling (results are deterministic).
    """
    rng = np.random.default_rng(seed)
    out = np.zeros(len(inst.terminals), complex)
    for g in range(len(inst.terminals)):
        if inst.symmetry[g] == 0:
            continue  # a round shape turns about its centre unseen: moving its origin would show turns
        sel = np.flatnonzero(inst.group == g)
        out[g] = _common_pivot(inst.a[sel], inst.b[sel], float(sizes[g]), tolerance)
        if out[g] == 0 and sel.size >= 5:
            out[g] = _pivot_for(inst.a[sel], inst.b[sel], float(sizes[g]), tol_angle, rng)
    return out


def recenter(inst: Instancing, offsets: np.ndarray) -> Instancing:
    """Move terminal origins by ``offsets`` (local coordinates): shapes shift, poses follow."""
    if not np.any(offsets):
        return inst
    from lsys_core.geometry.paths import d_from_cubics
    from lsys_core.geometry.shapes import shape_arrays

    terminals = list(inst.terminals)
    for g, o in enumerate(offsets):
        if o == 0:
            continue
        cubics, subpaths, closed = shape_arrays(terminals[g].path)
        terminals[g] = replace(terminals[g], path=d_from_cubics(cubics - o, subpaths, closed))
    b = inst.b + inst.a * offsets[inst.group]
    return replace(inst, b=b, terminals=tuple(terminals))
