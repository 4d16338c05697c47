"""Linking pairs of nodes into sequences (§5.3, step 3a), shared by all kinds of candidates.

A cluster of pairs ``i → j`` with one transform links into chains when the second node of a
pair is the first of another.  Each node gets at most one successor and one predecessor;
closed loops (a ring) keep all their nodes and drop the pair that closes them.
"""

from __future__ import annotations

import numpy as np

__all__ = ["chain_pairs", "chains", "edge_chains", "follow", "successor_pairs"]


def chains(src: np.ndarray, dst: np.ndarray, cost: np.ndarray) -> tuple[list[list[int]], dict[int, int]]:
    """Link pairs into sequences: greedy, cheapest pairs first, each node with ≤ 1 successor and predecessor.

    Returns the chains (open paths, then rings cut before their smallest node) and the
    successor map they were followed from.
    """
    order = np.argsort(cost, kind="stable")
    succ: dict[int, int] = {}
    pred: dict[int, int] = {}
    for e in order.tolist():
        i, j = int(src[e]), int(dst[e])
        if i == j or i in succ or j in pred:
            continue
        succ[i] = j
        pred[j] = i
    paths, loops = follow(succ, sorted(i for i in succ if i not in pred))
    return paths + loops, succ


def follow(succ: dict[int, int], starts) -> tuple[list[list[int]], list[list[int]]]:
    """Follow a successor map (≤ 1 successor and predecessor each) from ``starts`` into paths.

    Returns the paths and the closed loops left over, each loop listed from its smallest item.
    """
    paths: list[list[int]] = []
    seen: set[int] = set()
    for s0 in starts:
        path = [s0]
        while path[-1] in succ:
            path.append(succ[path[-1]])
        seen.update(path)
        paths.append(path)
    loops: list[list[int]] = []
    for s0 in sorted(succ):
        if s0 in seen:
            continue
        loop = [s0]
        while succ[loop[-1]] != s0:
            loop.append(succ[loop[-1]])
        seen.update(loop)
        loops.append(loop)
    return paths, loops


def chain_pairs(chain_list: list[list[int]], src: np.ndarray, dst: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """Return the pair indices (from ``idx``, with ends ``src``/``dst``) that link consecutive chain nodes."""
    look = {(int(s), int(d)): int(k) for s, d, k in zip(src, dst, idx, strict=True)}
    return np.array([look[(c[t], c[t + 1])] for c in chain_list for t in range(len(c) - 1)], int)


def successor_pairs(src: np.ndarray, dst: np.ndarray, idx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """All pairs of pairs ``(i→j, j→k)`` with ``k != i`` among the pair indices ``idx``."""
    order = np.argsort(src[idx], kind="stable")
    s_sorted = src[idx][order]
    lo = np.searchsorted(s_sorted, dst[idx], "left")
    cnt = np.searchsorted(s_sorted, dst[idx], "right") - lo
    e1 = np.repeat(idx, cnt)
    offs = np.arange(int(cnt.sum())) - np.repeat(np.cumsum(cnt) - cnt, cnt)
    e2 = idx[order][np.repeat(lo, cnt) + offs]
    keep = dst[e2] != src[e1]
    return e1[keep], e2[keep]


def edge_chains(e1: np.ndarray, e2: np.ndarray) -> list[list[int]]:
    """Follow links ``e1 → e2`` (each pair with at most one successor and predecessor) into chains."""
    _, first = np.unique(e1, return_index=True)
    e1, e2 = e1[np.sort(first)], e2[np.sort(first)]
    _, first = np.unique(e2, return_index=True)
    e1, e2 = e1[np.sort(first)], e2[np.sort(first)]
    keep = e1 != e2
    nxt = dict(zip(e1[keep].tolist(), e2[keep].tolist(), strict=True))
    has_prev = set(nxt.values())
    paths, loops = follow(nxt, [s0 for s0 in nxt if s0 not in has_prev])
    # Closed loops (a ring of dots): cut each before its smallest pair and drop the closing one.
    return paths + [loop[:-1] for loop in loops if len(loop) > 2]
