"""Branching candidates (§5.2 r3/r4, §5.3 step 3b): full binary trees from two clusters.

When the second node of a pair is the first node of two pairs from two different clusters of
one symbol space, the nodes branch: ``R -> [A] [T1 R] T2 R``.  Every node gets the depth of
the full binary tree below it; trees are taken deepest first, node-disjoint.
"""

from __future__ import annotations

import numpy as np

from lsys_core.hierarchy.candidates import BranchCandidate, ConstantCluster, mean_rel
from lsys_core.hierarchy.flat import Groups, isin
from lsys_core.hierarchy.spaces import PairSpace

__all__ = ["branch_candidates"]

#: Clusters per symbol space tried as the two branches of a tree (largest first).
_BRANCH_CLUSTERS = 8


def branch_candidates(
    ps: PairSpace, clusters: dict[tuple[int, int], list[ConstantCluster]], prox: np.ndarray, n_nodes: int
) -> list[BranchCandidate]:
    """Return full binary trees made of two clusters of one symbol space sharing their first elements."""
    out = []
    for space, cls in clusters.items():
        big = [c for c in cls if c.src.size >= 2][:_BRANCH_CLUSTERS]
        for x in range(len(big)):
            for y in range(x + 1, len(big)):
                cand = _trees(ps, space, big[x], big[y], prox, n_nodes)
                if cand is not None:
                    out.append(cand)
    return out


def _successors(cl: ConstantCluster, n_nodes: int) -> np.ndarray:
    c = np.full(n_nodes, -1)
    c[cl.src] = cl.dst
    return c


def _trees(ps, space, one: ConstantCluster, two: ConstantCluster, prox, n_nodes) -> BranchCandidate | None:
    if not isin(one.src, two.src).any():
        return None
    c1 = _successors(one, n_nodes)
    c2 = _successors(two, n_nodes)
    depth = np.zeros(n_nodes, int)
    has = (c1 >= 0) & (c2 >= 0)
    for _ in range(64):
        new = np.where(has, 1 + np.minimum(depth[np.maximum(c1, 0)], depth[np.maximum(c2, 0)]), 0)
        if np.array_equal(new, depth):
            break
        depth = new
    trees = _greedy_trees(depth, int(np.log2(n_nodes + 1)) - 1, c1, c2)
    if not trees or (len(trees) < 2 and trees[0][0] < 2):
        return None
    covered = np.zeros(n_nodes, bool)
    for _, nodes in trees:
        covered[nodes] = True
    s1, s2 = ps.src[one.pairs], ps.src[two.pairs]
    used1 = one.pairs[covered[s1] & (c1[s1] == ps.dst[one.pairs])]
    used2 = two.pairs[covered[s2] & (c2[s2] == ps.dst[two.pairs])]
    if used1.size == 0 or used2.size == 0:
        return None
    return BranchCandidate(
        space=space,
        groups=Groups.of(nodes for _, nodes in trees),
        h=float(max(np.mean(prox[used1]), np.mean(prox[used2]))),
        phi=1.0,
        l=float(np.mean([d for d, _ in trees])) * 2.0,
        first=mean_rel(ps.A[used1], ps.B[used1]),
        second=mean_rel(ps.A[used2], ps.B[used2]),
        depths=tuple(d for d, _ in trees),
    )


def _greedy_trees(
    depth: np.ndarray, cap: int, c1: np.ndarray, c2: np.ndarray
) -> list[tuple[int, np.ndarray]]:
    """Disjoint full binary trees, deepest roots first, each as deep as it stays valid (≤ ``cap``).

    A tree of depth ``d`` under a root is valid when its ``2^(d+1) - 1`` nodes exist, are
    distinct and not yet covered; validity at ``d`` implies it at every smaller depth, so each
    tree grows level by level until the next level would break it (root first, then each
    level's left children, then its right children).
    """
    order = np.argsort(-depth, kind="stable")
    roots = order[depth[order] >= 1].tolist()
    most = np.minimum(depth, cap).tolist()
    left, right = c1.tolist(), c2.tolist()
    covered = bytearray(depth.size)
    trees = []
    for r in roots:
        if covered[r]:
            continue
        levels = [[r]]
        seen = {r}
        for _ in range(most[r]):
            last = levels[-1]
            nxt = [left[v] for v in last] + [right[v] for v in last]
            if any(v < 0 or covered[v] or v in seen for v in nxt) or len(set(nxt)) != len(nxt):
                break
            seen.update(nxt)
            levels.append(nxt)
        if len(levels) < 2:
            continue
        nodes = [v for lev in levels for v in lev]
        for v in nodes:
            covered[v] = 1
        trees.append((len(levels) - 1, np.array(nodes)))
    return trees
