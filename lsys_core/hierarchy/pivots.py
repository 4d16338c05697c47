"""Choose each terminal's local origin so that rotating sequences become regular.

A terminal's local frame is first put at its representative's centroid.  When elements
of a row each turn a little more than the previous one about some point of the shape
(a leaf about its base), the transform between neighbours expressed at the centroid
is not constant in (d, s) and the sequence is missed.  Expressed at the pivot ``o``
(local coordinates), consecutive pivots differ by one constant world displacement ``D``:

    Δb + Δa · o = D        (Δb, Δa: differences of the two poses)

Every two pairs of one rotation cluster give an estimate of ``o``; the estimates are
clustered by mean shift and a well-supported mode with ``|D|`` comparable to the
spacing moves the terminal's origin there.  Rings and spirals (``D = 0`` at their
centre) are left alone: their transforms are constant at any origin.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy.spatial import cKDTree

from lsys_core.hierarchy.clustering import group_indices, mean_shift
from lsys_core.instancing.model import Instancing

__all__ = ["estimate_pivots", "recenter"]


def _pivot_for(a: np.ndarray, b: np.ndarray, size: float, tol_angle: float, rng) -> complex:
    n = a.size
    k = min(8, n - 1)
    pts = np.column_stack([b.real, b.imag])
    _, idx = cKDTree(pts).query(pts, k=k + 1)
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
    best, best_support = 0j, 0
    spacing = float(np.median(np.abs(b[dst] - b[src])))
    for g in group_indices(lab):
        if g.size < 4:
            continue
        db = b[dst[g]] - b[src[g]]
        da = a[dst[g]] - a[src[g]]
        m = min(4000, g.size * (g.size - 1) // 2)
        e1 = rng.integers(0, g.size, m)
        e2 = rng.integers(0, g.size, m)
        den = da[e1] - da[e2]
        good = np.abs(den) > 1e-9 * (np.abs(da[e1]) + 1e-300)
        if good.sum() < 3:
            continue
        o = (db[e2[good]] - db[e1[good]]) / den[good]
        o = o[np.isfinite(o) & (np.abs(o) < 20 * size)]
        if o.size < 3:
            continue
        _, modes = mean_shift(np.column_stack([o.real, o.imag]) / (0.02 * size))
        if modes.shape[0] == 0:
            continue
        cand = complex(*(modes[0] * 0.02 * size))
        D = db + da * cand
        lab2, dmodes = mean_shift(np.column_stack([D.real, D.imag]) / (0.02 * max(spacing, size)))
        support = int(np.sum(lab2 == 0))
        Dm = complex(*(dmodes[0] * 0.02 * max(spacing, size)))
        if support >= max(3, g.size // 3) and abs(Dm) > 0.5 * spacing and support > best_support:
            best, best_support = cand, support
    return best if abs(best) > 0.05 * size else 0j


def estimate_pivots(
    inst: Instancing, sizes: np.ndarray, *, tol_angle: float = 1.0, seed: int = 0
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
    seed : int
        Seed of the vote sampling (results are deterministic).
    """
    rng = np.random.default_rng(seed)
    out = np.zeros(len(inst.terminals), complex)
    for g in range(len(inst.terminals)):
        sel = np.flatnonzero(inst.group == g)
        if sel.size >= 5:
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
