"""The rotation clusters' pivot votes elect what they elected when each cluster drew and voted in turn (hierarchy.pivots)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import cKDTree

from lsys_core.hierarchy import pivots
from lsys_core.hierarchy.clustering import group_indices, mean_shift
from lsys_core.parallel import set_jobs


def _simple(a, b, size, tol_angle, rng) -> complex:
    """``_pivot_for`` as first written: each cluster draws and votes in turn."""
    n = a.size
    k = min(8, n - 1)
    pts = np.column_stack([b.real, b.imag])
    _, idx = cKDTree(pts).query(pts, k=k + 1)
    src = np.repeat(np.arange(n), k + 1)
    dst = np.asarray(idx).ravel()
    ok = (dst != src) & (dst < n)
    src, dst = src[ok], dst[ok]
    A = a[dst] / a[src]
    moving = np.abs(np.angle(A)) > np.deg2rad(tol_angle)
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


def _rows(n_rows: int, per_row: int, step_deg: float, pivot: complex, seed: int):
    """Rows of copies each turned ``step_deg`` more than the last about the local point ``pivot``."""
    rng = np.random.default_rng(seed)
    j = np.tile(np.arange(per_row), n_rows)
    i = np.repeat(np.arange(n_rows), per_row)
    a = np.exp(1j * np.deg2rad(step_deg * j + 40.0 * i)) * (1 + 0.01 * rng.random(j.size))
    place = 10.0 * j + 1j * 14.0 * i
    return a, place - a * pivot


@pytest.mark.parametrize(("n_rows", "per_row", "step"), [(3, 5, 12.0), (40, 25, 9.0), (60, 30, 0.5)])
@pytest.mark.parametrize("jobs", [1, 2])
def test_the_votes_elect_the_same_pivot(n_rows: int, per_row: int, step: float, jobs: int) -> None:
    a, b = _rows(n_rows, per_row, step, 3.0 + 1.0j, n_rows)
    set_jobs(jobs)
    try:
        got = pivots._pivot_for(a, b, 4.0, 1.0, np.random.default_rng(0))
    finally:
        set_jobs(None)
    assert got == _simple(a, b, 4.0, 1.0, np.random.default_rng(0))
