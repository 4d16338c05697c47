"""Pair spaces with the pairs found by a sparse union are those of the sorted pair codes, bit for bit (hierarchy.spaces)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import cKDTree

from lsys_core.geometry.transforms import t4_from_rel
from lsys_core.hierarchy import spaces
from lsys_core.parallel import set_jobs
from lsys_core.sorting import sorted_unique


def _simple(a, b, center, radius, k):
    """The pair space as first written: every array at once, on the calling thread."""
    n = a.size
    kk = min(k, n - 1)
    _, idx = cKDTree(np.column_stack([center.real, center.imag])).query(
        np.column_stack([center.real, center.imag]), k=kk + 1
    )
    src = np.repeat(np.arange(n), kk + 1)
    dst = np.atleast_2d(idx).ravel()
    keep = (dst != src) & (dst < n)
    src, dst = src[keep], dst[keep]
    both = sorted_unique(np.concatenate([src * n + dst, dst * n + src]))
    src, dst = both // n, both % n
    A = a[dst] / a[src]
    B = (b[dst] - b[src]) / a[src]
    alpha, d, s, beta = t4_from_rel(A, B)
    dist = np.abs(center[dst] - center[src])
    gap = np.maximum(dist - radius[src] - radius[dst], 0.0)
    return src, dst, A, B, alpha, d, s, beta, dist, gap


@pytest.mark.parametrize("jobs", [1, 2, 3])
def test_the_sparse_union_gives_the_same_bits(jobs: int) -> None:
    rng = np.random.default_rng(jobs)
    n = 3000
    # a turning grid with exact ties of distance, and scattered nodes at other scales
    grid = (np.arange(n) % 50) * 3.0 + 1j * (np.arange(n) // 50) * 3.0
    center = np.where(np.arange(n) < 2000, grid, rng.normal(size=n) * 100 + 1j * rng.normal(size=n) * 100)
    a = rng.uniform(0.2, 3.0, n) * np.exp(
        1j * np.where(np.arange(n) < 1000, np.arange(n) * 0.1, rng.uniform(-4, 4, n))
    )
    a[::97] = 1.0  # unturned nodes: the angles' edge cases
    center[2500:2600] = center[2400:2500]  # coincident nodes: a node is not always its own nearest
    b = center + rng.normal(size=n) + 1j * rng.normal(size=n)
    radius = rng.uniform(0.0, 2.0, n)
    set_jobs(jobs)
    try:
        ps = spaces.pair_space(a, b, center, radius, k=12)
    finally:
        set_jobs(None)
    got = (ps.src, ps.dst, ps.A, ps.B, ps.alpha, ps.d, ps.s, ps.beta, ps.dist, ps.gap)
    for x, y in zip(got, _simple(a, b, center, radius, 12), strict=True):
        assert x.dtype == y.dtype and x.tobytes() == y.tobytes()


@pytest.mark.parametrize("n", [2, 3, 13, 14])
def test_few_nodes_give_the_same_pairs(n: int) -> None:
    rng = np.random.default_rng(n)
    center = rng.normal(size=n) + 1j * rng.normal(size=n)
    center[-1] = center[0]
    a = np.exp(1j * rng.uniform(-3, 3, n))
    radius = np.ones(n)
    ps = spaces.pair_space(a, center, center, radius, k=12)
    got = (ps.src, ps.dst, ps.A, ps.B, ps.alpha, ps.d, ps.s, ps.beta, ps.dist, ps.gap)
    for x, y in zip(got, _simple(a, center, center, radius, 12), strict=True):
        assert x.dtype == y.dtype and x.tobytes() == y.tobytes()
