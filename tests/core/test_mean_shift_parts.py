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


def _separated_parts(seed: int) -> list[np.ndarray]:
    """Point sets far apart along a last coordinate (as the consecutive pairs of several (d, s) clusters).

    Each has lone points, dense clumps (more than ``_NEAR`` neighbours) and duplicates; one
    part is a single point.
    """
    rng = np.random.default_rng(seed)
    dim = int(rng.integers(1, 5))
    parts = []
    for k in range(int(rng.integers(2, 7))):
        lone = rng.uniform(0, 30, (int(rng.integers(0, 60)), dim))
        clumps = rng.uniform(0, 30, (int(rng.integers(1, 4)), dim))
        dense = np.repeat(clumps, 3 * clustering._NEAR, axis=0)
        dense += rng.normal(0, 0.3, dense.shape)
        dup = np.repeat(rng.uniform(0, 30, (2, dim)), 3, axis=0)
        pts = np.concatenate([lone, dense, dup])[rng.permutation(len(lone) + len(dense) + len(dup))]
        if k == 3:
            pts = pts[:1]
        parts.append(np.column_stack([pts, np.full(len(pts), k * 1e7)]))
    return parts


@pytest.mark.parametrize("seed", range(10))
def test_mean_shift_in_parts_is_the_mean_shift_of_the_whole(seed: int) -> None:
    parts = _separated_parts(seed)
    # the parts' points interleaved in the whole, each part keeping its order
    owner = np.random.default_rng(seed).permutation(np.repeat(np.arange(len(parts)), [len(p) for p in parts]))
    whole = np.empty((owner.size, parts[0].shape[1]))
    for k, pts in enumerate(parts):
        whole[owner == k] = pts
    labels, modes, rank = clustering.ranked_mean_shift(whole)
    assert clustering.rank_order(rank).tolist() == list(range(len(rank)))
    assert labels.tolist() == clustering.mean_shift(whole)[0].tolist()
    found = [clustering.ranked_mean_shift(pts) for pts in parts]
    merged = clustering.rank_order(np.concatenate([r for _, _, r in found]))
    # cluster k of the merged order is cluster k of the whole: same members, same mode, bit for bit
    offsets = np.cumsum([0] + [len(r) for _, _, r in found])
    part_modes = np.concatenate([m for _, m, _ in found])
    lone, lone_whole = [], []
    for k, g in enumerate(merged.tolist()):
        p = int(np.searchsorted(offsets, g, side="right")) - 1
        members = np.flatnonzero(owner == p)[found[p][0] == g - offsets[p]].tolist()
        if rank["support"][k] < 0:  # a point alone: numbered by its index in its own part
            lone += members
            lone_whole += np.flatnonzero(labels == k).tolist()
            continue
        assert members == np.flatnonzero(labels == k).tolist()
        assert part_modes[g].tobytes() == modes[k].tobytes()
    assert sorted(lone) == sorted(lone_whole)


@pytest.mark.parametrize("seed", range(4))
def test_spread_is_each_groups_distance_from_its_mean_bit_for_bit(seed: int) -> None:
    rng = np.random.default_rng(seed)
    pts = rng.normal(size=(30_000, 6)) * rng.uniform(0.1, 1e4, 6)  # magnitudes where order matters
    sizes = [2, 9, 17, 3_000, *rng.integers(2, 60, 200).tolist()]
    members = np.sort(rng.choice(len(pts), sum(sizes), replace=False))
    groups = np.split(members, np.cumsum(sizes)[:-1])
    want = np.concatenate([np.linalg.norm(pts[g, :5] - pts[g, :5].mean(0), axis=1) for g in groups])
    got = clustering.spread(pts[:, :5], groups)
    assert got.tobytes() == want.tobytes()
    assert clustering.spread(pts, []).size == 0
