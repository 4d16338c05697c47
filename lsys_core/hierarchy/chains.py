"""Linking pairs of nodes into sequences (§5.3, step 3a), shared by all kinds of candidates.

A cluster of pairs ``i → j`` with one transform links into chains when the second node of a
pair is the first of another.  Each node gets at most one successor and one predecessor;
closed loops (a ring) keep all their nodes and drop the pair that closes them.  All clusters
of a level are linked at once with the flat primitives of :mod:`lsys_core.hierarchy.flat`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lsys_core import parallel
from lsys_core.hierarchy.flat import Groups, follow_links, greedy_links, isin
from lsys_core.sorting import first_occurrences, sorted_unique, stable_argsort

__all__ = ["Linked", "chains", "edge_chains", "edge_groups", "follow", "link_clusters", "successor_pairs"]


@dataclass(frozen=True, eq=False)
class Linked:
    """One cluster's pairs linked into chains.

    Attributes
    ----------
    chains : Groups
        Open paths (from their first nodes, in node order), then rings (from their smallest node).
    used : ndarray of int
        The pair linking every two consecutive nodes of the chains, chain by chain.
    src, dst : ndarray of int
        The links taken: the successor map the chains were followed from.
    """

    chains: Groups
    used: np.ndarray
    src: np.ndarray
    dst: np.ndarray


def link_clusters(
    clusters: list[np.ndarray], costs: np.ndarray, src: np.ndarray, dst: np.ndarray, n_nodes: int
) -> list[Linked]:
    """Link every cluster's pairs into sequences, all clusters at once.

    Per cluster, pairs are taken greedily from the cheapest (ties in pair order), each node
    keeping ≤ 1 successor and ≤ 1 predecessor, and the links are followed into chains.
    Clusters are linked on their own, so from :data:`_SPLIT` pairs up they are linked in runs
    of about equal pairs on the :func:`~lsys_core.parallel.jobs` workers (numpy's sorts release
    the interpreter): the same chains.  A 50,052-leaf grid's 1.2·10^6 pairs took 3.2 s of the
    main thread's 6 s of clustering with 2 jobs, one core idle once the linear sequences beside
    it had ended; in parts the whole inference took 8.52 -> 8.25 s (3 pairs).

    Parameters
    ----------
    clusters : list of ndarray of int
        The pair indices of every cluster, increasing.
    costs : ndarray of float
        The cost of every pair, cluster after cluster (as ``np.concatenate(clusters)``).
    src, dst : ndarray of int
        First and second node of every pair.
    n_nodes : int
        Number of nodes.
    """
    count = len(clusters)
    if count == 0:
        return []
    sizes = np.fromiter((c.size for c in clusters), np.int64, count)
    parts = _parts(sizes, parallel.jobs())
    if len(parts) > 1:
        ends = np.concatenate([[0], np.cumsum(sizes)])
        return [
            linked
            for part in parallel.pmap(
                lambda p: _link(clusters[p[0] : p[1]], costs[ends[p[0]] : ends[p[1]]], src, dst, n_nodes),
                parts,
            )
            for linked in part
        ]
    return _link(clusters, costs, src, dst, n_nodes)


#: Pairs from which the clusters of a level are linked in parts, one per worker.
_SPLIT = 200_000


def _parts(sizes: np.ndarray, workers: int) -> list[tuple[int, int]]:
    """Consecutive runs of clusters of about equal pairs, one per worker (one run below :data:`_SPLIT` pairs)."""
    total = int(sizes.sum())
    if workers < 2 or total < _SPLIT or sizes.size < 2:
        return [(0, int(sizes.size))]
    cuts = np.searchsorted(np.cumsum(sizes), total * np.arange(1, workers) / workers, side="right")
    bounds = sorted_unique(np.concatenate([[0], np.minimum(cuts, sizes.size - 1), [sizes.size]]))
    return list(zip(bounds[:-1].tolist(), bounds[1:].tolist(), strict=True))


def _link(
    clusters: list[np.ndarray], costs: np.ndarray, src: np.ndarray, dst: np.ndarray, n_nodes: int
) -> list[Linked]:
    """:func:`link_clusters` of some clusters, in one pass."""
    count = len(clusters)
    n = np.int64(max(n_nodes, 1))
    items = np.concatenate(clusters)
    cid = np.repeat(np.arange(count, dtype=np.int64), [c.size for c in clusters])
    order = np.lexsort((costs, cid))  # per cluster by cost; ties in pair order
    s_key = cid * n + src[items]
    d_key = cid * n + dst[items]
    order = order[(s_key != d_key)[order]]  # a pair within one node links nothing
    # The pairs' two ends as numbers 0, 1, ... (what greedy_links needs), the arrays that made
    # them freed before it runs: they were a fifth of the level's peak memory.
    k = np.concatenate([s_key, d_key])
    uniq = sorted_unique(k)
    k = np.searchsorted(uniq, k)
    size = uniq.size
    del uniq
    acc = np.flatnonzero(greedy_links([k[: items.size], k[items.size :]], order, size))
    del k, order
    a_src, a_dst = s_key[acc], d_key[acc]
    starts = sorted_unique(a_src[~isin(a_src, a_dst)])  # per cluster, in node order
    paths, loops = follow_links(a_src, a_dst, starts)
    allc = paths.concat(loops)
    allc = allc.take(stable_argsort(allc.firsts // n))  # per cluster: paths, then rings
    # The pair along every link of the chains: the taken pair leaving the link's first node.
    srt = np.argsort(a_src)
    lo, _ = allc.links()
    used = items[acc[srt[np.searchsorted(a_src[srt], allc.nodes[lo])]]]
    cuts_c = np.searchsorted(allc.firsts // n, np.arange(count + 1))
    cuts_u = np.searchsorted(allc.nodes[lo] // n, np.arange(count + 1))
    cuts_a = np.searchsorted(cid[acc], np.arange(count + 1))
    out = []
    for c in range(count):
        c0, c1 = cuts_c[c], cuts_c[c + 1]
        base = c * n
        sub = Groups(
            allc.nodes[allc.offsets[c0] : allc.offsets[c1]] - base,
            allc.offsets[c0 : c1 + 1] - allc.offsets[c0],
        )
        a0, a1 = cuts_a[c], cuts_a[c + 1]
        out.append(Linked(sub, used[cuts_u[c] : cuts_u[c + 1]], a_src[a0:a1] - base, a_dst[a0:a1] - base))
    return out


def chains(src: np.ndarray, dst: np.ndarray, cost: np.ndarray) -> tuple[list[list[int]], dict[int, int]]:
    """Link pairs into sequences: greedy, cheapest pairs first, each node with ≤ 1 successor and predecessor.

    Returns the chains (open paths, then rings cut before their smallest node) and the
    successor map they were followed from.
    """
    src, dst = np.asarray(src, np.int64), np.asarray(dst, np.int64)
    if src.size == 0:
        return [], {}
    n = int(max(src.max(), dst.max())) + 1
    (linked,) = link_clusters([np.arange(src.size)], np.asarray(cost, float), src, dst, n)
    return linked.chains.tolist(), dict(zip(linked.src.tolist(), linked.dst.tolist(), strict=True))


def follow(succ: dict[int, int], starts) -> tuple[list[list[int]], list[list[int]]]:
    """Follow a successor map (≤ 1 successor and predecessor each) from ``starts`` into paths.

    Returns the paths and the closed loops left over, each loop listed from its smallest item.
    """
    src = np.fromiter(succ.keys(), np.int64, len(succ))
    dst = np.fromiter(succ.values(), np.int64, len(succ))
    paths, loops = follow_links(src, dst, np.asarray(list(starts), np.int64))
    return paths.tolist(), loops.tolist()


def successor_pairs(src: np.ndarray, dst: np.ndarray, idx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """All pairs of pairs ``(i→j, j→k)`` with ``k != i`` among the pair indices ``idx``."""
    order = stable_argsort(src[idx])
    s_sorted = src[idx][order]
    lo = np.searchsorted(s_sorted, dst[idx], "left")
    cnt = np.searchsorted(s_sorted, dst[idx], "right") - lo
    e1 = np.repeat(idx, cnt)
    offs = np.arange(int(cnt.sum())) - np.repeat(np.cumsum(cnt) - cnt, cnt)
    e2 = idx[order][np.repeat(lo, cnt) + offs]
    keep = dst[e2] != src[e1]
    return e1[keep], e2[keep]


def edge_groups(e1: np.ndarray, e2: np.ndarray) -> Groups:
    """Follow links ``e1 → e2`` (each pair keeps its first successor and predecessor) into chains.

    Paths come in the order of their first links; closed loops (a ring of dots) are cut
    before their smallest pair and lose the closing one.
    """
    first = first_occurrences(e1)
    e1, e2 = e1[first], e2[first]
    first = first_occurrences(e2)
    e1, e2 = e1[first], e2[first]
    keep = e1 != e2
    s, d = e1[keep], e2[keep]
    paths, loops = follow_links(s, d, s[~isin(s, d)])
    loops = loops.take(np.flatnonzero(loops.lengths > 2))
    return paths.concat(loops.take_prefix(loops.lengths - 1))


def edge_chains(e1: np.ndarray, e2: np.ndarray) -> list[list[int]]:
    """:func:`edge_groups` as lists."""
    return edge_groups(e1, e2).tolist()
