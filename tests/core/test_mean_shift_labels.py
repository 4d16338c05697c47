"""Mean shift labels its points per cell only where that gives the KD-tree's answer.

:func:`lsys_core.hierarchy.clustering.mean_shift` labels large point sets by reasoning per
half-bandwidth cell (a cell whose reach holds one mode needs no tree query).  With the
thresholds lowered to 0, every size takes that path; with them raised, every point is queried:
the labels and modes must be the same, including points farther than a bandwidth from every
mode (singleton clusters) and cells between two modes.

Seeds that meet bit for bit are moved by one query (``_distinct_rows``): with that on for every
call and off for every call, the clusters, modes and ranks must be the same bit for bit,
on scenes where many points sit on a few exact places (copies) and seeds merge.  So must they
when the seeds climb in parts on several workers (``_climb_parts``) and all at once on one.
"""

from __future__ import annotations

import numpy as np
import pytest

from lsys_core import parallel
from lsys_core.hierarchy import clustering


def assert_same(got: tuple[np.ndarray, ...], expected: tuple[np.ndarray, ...]) -> None:
    """Every array of two results equal, bit for bit."""
    for a, b in zip(got, expected, strict=True):
        np.testing.assert_array_equal(a, b)


def scene(seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    dim = int(rng.integers(1, 7))
    k = int(rng.integers(1, 60))
    n = int(rng.integers(200, 4000))
    centres = rng.normal(0.0, rng.uniform(0.5, 12.0), (k, dim))
    return centres[rng.integers(0, k, n)] + rng.normal(0.0, rng.uniform(0.05, 2.0), (n, dim))


@pytest.mark.parametrize("seed", range(40))
def test_cell_labels_equal_tree_labels(seed: int, monkeypatch: pytest.MonkeyPatch) -> None:
    pts = scene(seed)
    monkeypatch.setattr(clustering, "_DIRECT", 10**12)
    by_tree = clustering.mean_shift(pts)
    monkeypatch.setattr(clustering, "_DIRECT", 0)
    monkeypatch.setattr(clustering, "_PER_CELL", 0)
    monkeypatch.setattr(clustering, "_BLOCK", 97)  # several blocks, one of them partial
    assert_same(clustering.mean_shift(pts), by_tree)


def copies(seed: int) -> np.ndarray:
    """Points on a few exact places (repeated transforms) with a jittered rest."""
    rng = np.random.default_rng(seed)
    dim = int(rng.integers(2, 7))
    places = rng.normal(0.0, rng.uniform(1.0, 8.0), (int(rng.integers(1, 30)), dim))
    exact = places[rng.integers(0, len(places), int(rng.integers(100, 3000)))]
    near = places[rng.integers(0, len(places), int(rng.integers(0, 3000)))]
    return np.vstack([exact, near + rng.normal(0.0, rng.uniform(0.01, 0.6), near.shape)])


@pytest.mark.parametrize("seed", range(30))
def test_seeds_at_one_place_queried_once(seed: int, monkeypatch: pytest.MonkeyPatch) -> None:
    pts = copies(seed)
    monkeypatch.setattr(clustering, "_DISTINCT", 10**12)
    each = clustering.ranked_mean_shift(pts)
    monkeypatch.setattr(clustering, "_DISTINCT", 0)
    assert_same(clustering.ranked_mean_shift(pts), each)


def test_distinct_rows_groups_equal_rows() -> None:
    rows = np.array([[1.0, 2.0], [3.0, 4.0], [1.0, 2.0], [-0.0, 0.0], [0.0, 0.0], [3.0, 4.0]])
    many = np.repeat(rows, 1000, axis=0)
    first, inverse = clustering._distinct_rows(many)
    np.testing.assert_array_equal(many[first[inverse]], many)
    assert first.size == 4  # -0.0 and 0.0 differ bit for bit: kept apart, never wrongly merged


def one_worker_then_three(
    pts: np.ndarray, monkeypatch: pytest.MonkeyPatch, setting: str, value: int
) -> tuple[tuple[np.ndarray, ...], tuple[np.ndarray, ...]]:
    """``ranked_mean_shift`` of ``pts`` on one worker, then on three with ``clustering.<setting> = value``."""
    parallel.set_jobs(1)
    try:
        whole = clustering.ranked_mean_shift(pts)
        monkeypatch.setattr(clustering, setting, value)
        parallel.set_jobs(3)
        return whole, clustering.ranked_mean_shift(pts)
    finally:
        parallel.set_jobs(None)


@pytest.mark.parametrize("seed", range(10))
def test_ball_queries_in_parts_equal_one_query(seed: int, monkeypatch: pytest.MonkeyPatch) -> None:
    whole, parts = one_worker_then_three(copies(seed), monkeypatch, "_THREADED_FULL", 0)
    assert_same(parts, whole)


@pytest.mark.parametrize("seed", range(12))
def test_seeds_climbing_in_parts_reach_the_same_modes(seed: int, monkeypatch: pytest.MonkeyPatch) -> None:
    pts = copies(seed) if seed % 2 else scene(seed)
    climbs: list[int] = []
    parts = clustering._climb_parts
    monkeypatch.setattr(clustering, "_climb_parts", lambda cent: climbs.append(len(p := parts(cent))) or p)
    whole, in_parts = one_worker_then_three(pts, monkeypatch, "_CLIMB_PART", 1)
    assert climbs[0] == 1 and climbs[1] == 3  # one climb on one worker, three parts on three
    assert_same(in_parts, whole)


def naive_suppress(seeds: np.ndarray, order: np.ndarray) -> np.ndarray:
    kept: list[int] = []
    for i in order.tolist():
        if all(np.linalg.norm(seeds[i] - seeds[k]) > 0.5 for k in kept):
            kept.append(i)
    return np.array(kept, np.int64)


@pytest.mark.parametrize("seed", range(8))
def test_suppress_keeps_the_strongest_seed_of_every_place(seed: int) -> None:
    rng = np.random.default_rng(seed)
    places = rng.uniform(0.0, 6.0, (40, 2))
    seeds = places[rng.integers(0, 40, 5000)]  # many seeds at each place, bit for bit
    seeds[::7] += rng.normal(0.0, 0.3, seeds[::7].shape)
    order = rng.permutation(len(seeds))[: len(seeds) - 300]  # some seeds are too weak to count
    np.testing.assert_array_equal(clustering._suppress(seeds, order), naive_suppress(seeds, order))


@pytest.mark.parametrize("seed", range(6))
def test_crowded_queries_find_the_same_neighbours(seed: int) -> None:
    """Seeds sent straight to the ball query (crowded) get the neighbours the nearest-points query gives."""
    from scipy.spatial import cKDTree

    rng = np.random.default_rng(seed)
    pts = copies(seed)
    tree = cKDTree(pts)
    query = pts[rng.integers(0, len(pts), 3000)] + rng.normal(0.0, 0.2, (3000, pts.shape[1]))
    crowded = rng.random(3000) < 0.5

    def per_owner(pairs: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        by = np.argsort(pairs[0], kind="stable")  # each owner's points keep their order
        return pairs[0][by], pairs[1][by]

    plain = per_owner(clustering._ball_pairs(query, tree))
    routed = per_owner(clustering._ball_pairs(query, tree, crowded=crowded))
    np.testing.assert_array_equal(routed[0], plain[0])
    np.testing.assert_array_equal(routed[1], plain[1])
    assert np.all(np.diff(routed[1])[np.diff(routed[0]) == 0] > 0)  # increasing points per owner
