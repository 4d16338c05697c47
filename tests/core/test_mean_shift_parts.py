"""Parts of the mean shift against their plain definitions: ball pairs and greedy suppression."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import cKDTree

from lsys_core.hierarchy import clustering


def _points(seed: int) -> np.ndarray:
    """Isolated points, dense clumps (more than ``_NEAR`` within a bandwidth) and exact duplicates."""
    rng = np.random.default_rng(seed)
    dim = int(rng.integers(1, 5))
    lone = rng.uniform(0, 60, (int(rng.integers(0, 200)), dim))
    clumps = rng.uniform(0, 60, (int(rng.integers(1, 6)), dim))
    dense = np.repeat(clumps, 3 * clustering._NEAR, axis=0) + rng.normal(
        0, 0.2, (len(clumps) * 3 * clustering._NEAR, dim)
    )
    dup = np.repeat(rng.uniform(0, 60, (3, dim)), 4, axis=0)
    return np.concatenate([lone, dense, dup])


@pytest.mark.parametrize("seed", range(8))
def test_ball_pairs_are_every_point_within_the_radius(seed: int) -> None:
    pts = _points(seed)
    tree = cKDTree(pts)
    query = pts[::2] + 0.1
    i, j = clustering._ball_pairs(query, tree)
    ref = cKDTree(query).sparse_distance_matrix(tree, 1.0, output_type="ndarray")
    got = sorted(zip(i.tolist(), j.tolist(), strict=True))
    assert got == sorted(zip(ref["i"].tolist(), ref["j"].tolist(), strict=True))


@pytest.mark.parametrize("seed", range(8))
def test_suppression_keeps_what_the_greedy_loop_keeps(seed: int) -> None:
    seeds = _points(seed)
    order = np.random.default_rng(seed).permutation(len(seeds))[: len(seeds) - 3]
    suppressed = np.zeros(len(seeds), bool)
    expected = []
    for i, near in zip(order.tolist(), cKDTree(seeds).query_ball_point(seeds[order], r=0.5), strict=True):
        if not suppressed[i]:
            expected.append(i)
            suppressed[near] = True
    assert clustering._suppress(seeds, order).tolist() == expected


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_support_of_seeds_that_stopped_is_that_of_a_new_query(seed: int) -> None:
    rng = np.random.default_rng(seed)
    lone = rng.uniform(0, 400, (300, 3))  # far apart: they stop where they start
    crowd = rng.normal(0, 0.4, (200, 3)) + 500.0  # they move, then stop near each other
    points = np.vstack([lone, crowd])
    weights = rng.integers(1, 5, len(points)).astype(float)
    tree = cKDTree(points)
    seeds = points.copy()
    seeds[300:] = points[300:].mean(axis=0)  # moved seeds: queried again
    owner, flat = clustering._ball_pairs(seeds[:300], tree)
    kept = clustering._support(seeds, tree, weights, [owner], [flat])
    owner, flat = clustering._ball_pairs(seeds, tree)
    fresh = np.bincount(owner, weights=weights[flat], minlength=len(seeds))
    assert kept.tobytes() == fresh.tobytes()
    assert (fresh[300:] > 100).all() and (fresh[:300] >= 1).all()
