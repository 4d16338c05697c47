"""The flat chain primitives agree with the plain sequential algorithms they replace."""

from __future__ import annotations

import numpy as np
import pytest

from lsys_core.hierarchy.flat import (
    Groups,
    follow_links,
    greedy_disjoint,
    greedy_links,
    greedy_sets,
    isin,
    sorted_unique,
)


def _follow_reference(succ: dict[int, int], starts: list[int]) -> tuple[list[list[int]], list[list[int]]]:
    paths, seen = [], set()
    for s0 in starts:
        path = [s0]
        while path[-1] in succ:
            path.append(succ[path[-1]])
        seen.update(path)
        paths.append(path)
    loops = []
    for s0 in sorted(succ):
        if s0 in seen:
            continue
        loop = [s0]
        while succ[loop[-1]] != s0:
            loop.append(succ[loop[-1]])
        seen.update(loop)
        loops.append(loop)
    return paths, loops


def _greedy_reference(sets: list[list[int]], order: list[int]) -> list[bool]:
    used: set[int] = set()
    out = [False] * len(sets)
    for c in order:
        if used.isdisjoint(sets[c]):
            out[c] = True
            used.update(sets[c])
    return out


@pytest.mark.parametrize("seed", range(40))
def test_follow_links_matches_walking_the_map(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 80))
    src = rng.permutation(3 * n)[:n]
    dst = rng.permutation(3 * n)[:n]
    keep = src != dst
    succ = dict(zip(src[keep].tolist(), dst[keep].tolist(), strict=True))
    has_prev = set(succ.values())
    starts = [s for s in succ if s not in has_prev]
    rng.shuffle(starts)
    paths, loops = follow_links(np.array(list(succ)), np.array(list(succ.values())), np.array(starts, int))
    assert (paths.tolist(), loops.tolist()) == _follow_reference(succ, starts)


def test_follow_links_cuts_rings_before_their_smallest_node() -> None:
    paths, loops = follow_links(np.array([5, 9, 7, 1]), np.array([9, 7, 5, 2]), np.array([1]))
    assert paths.tolist() == [[1, 2]] and loops.tolist() == [[5, 9, 7]]


@pytest.mark.parametrize("seed", range(40))
def test_greedy_sets_matches_the_sequential_pass(seed: int) -> None:
    rng = np.random.default_rng(seed)
    count = int(rng.integers(1, 300))
    universe = int(rng.integers(4, 200))
    sets = [rng.choice(universe, size=int(rng.integers(1, 5)), replace=False).tolist() for _ in range(count)]
    order = rng.permutation(count)[: int(rng.integers(0, count + 1))]
    offsets = np.concatenate([[0], np.cumsum([len(s) for s in sets])])
    got = greedy_sets(offsets, np.concatenate([np.array(s) for s in sets]), order)
    assert got.tolist() == _greedy_reference(sets, order.tolist())


def test_greedy_sets_resolves_long_cascades_exactly() -> None:
    # set k shares an item with set k + 1: taken, skipped, taken, ... along a chain of 2,000
    sets = [[k, k + 1] for k in range(2000)]
    offsets = np.arange(2001) * 2
    got = greedy_sets(offsets, np.array(sets).ravel(), np.arange(2000))
    assert got.tolist() == [k % 2 == 0 for k in range(2000)]


def test_greedy_links_keeps_one_successor_and_predecessor_per_node() -> None:
    src = np.array([0, 0, 1, 2, 1])
    dst = np.array([1, 2, 2, 3, 3])
    order = np.array([1, 0, 2, 3, 4])  # 0→2 first: 0→1 then loses its source, 1→2 its target
    taken = greedy_links([src, dst], order, 4)
    assert taken.tolist() == [False, True, False, True, False]


def test_greedy_disjoint_never_takes_a_chain_repeating_a_node() -> None:
    chains = Groups.of([[0, 1, 0], [1, 2], [3, 4]])
    assert greedy_disjoint(chains, np.arange(3), 5).tolist() == [False, True, True]


def test_chains_slicing_and_helpers() -> None:
    c = Groups.of([[4, 5, 6], [7], [8, 9]])
    assert len(c) == 3 and c[2].tolist() == [8, 9] and c[-1].tolist() == [8, 9]
    assert c.take(np.array([2, 0])).nodes.tolist() == [8, 9, 4, 5, 6]
    assert c.head(2).tolist() == [[4, 5], [7], [8, 9]]
    assert c.firsts.tolist() == [4, 7, 8] and c.lengths.tolist() == [3, 1, 2]
    assert [a.tolist() for a in c] == [[4, 5, 6], [7], [8, 9]]
    assert Groups.singletons(2).tolist() == [[0], [1]]
    lo, hi = c.links()
    assert c.nodes[lo].tolist() == [4, 5, 8] and c.nodes[hi].tolist() == [5, 6, 9]
    assert sorted_unique(np.array([3, 1, 3, 2])).tolist() == [1, 2, 3]
    assert isin(np.array([1, 5, 2]), np.array([2, 1, 1])).tolist() == [True, False, True]


@pytest.mark.parametrize("seed", range(40))
def test_greedy_disjoint_matches_the_sequential_pass_without_repeating_chains(seed: int) -> None:
    rng = np.random.default_rng(seed)
    count = int(rng.integers(1, 300))
    universe = int(rng.integers(4, 120))
    chains = [rng.integers(0, universe, size=int(rng.integers(1, 6))).tolist() for _ in range(count)]
    order = rng.permutation(count)[: int(rng.integers(0, count + 1))]
    distinct = [c for c in order.tolist() if len(set(chains[c])) == len(chains[c])]
    got = greedy_disjoint(Groups.of(chains), order, universe)
    assert got.tolist() == _greedy_reference(chains, distinct)
