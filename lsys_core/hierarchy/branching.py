"""Branching candidates (§5.2 r3/r4, §5.3 step 3b): full binary trees from two clusters.

When the second node of a pair is the first node of two pairs from two different clusters of
one symbol space, the nodes branch: ``R -> [A] [T1 R] T2 R``.  Every node gets the depth of
the full binary tree below it; trees are taken deepest first, node-disjoint.
"""

from __future__ import annotations

import numpy as np

from lsys_core.hierarchy.candidates import BranchCandidate, ConstantCluster, mean_rel
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
        big = [c for c in cls if len(c.succ) >= 2][:_BRANCH_CLUSTERS]
        for x in range(len(big)):
            for y in range(x + 1, len(big)):
                cand = _trees(ps, space, big[x], big[y], prox, n_nodes)
                if cand is not None:
                    out.append(cand)
    return out


def _successors(succ: dict[int, int], n_nodes: int) -> np.ndarray:
    c = np.full(n_nodes, -1)
    if succ:
        c[np.fromiter(succ.keys(), int)] = np.fromiter(succ.values(), int)
    return c


def _trees(ps, space, one: ConstantCluster, two: ConstantCluster, prox, n_nodes) -> BranchCandidate | None:
    if not set(one.succ) & set(two.succ):
        return None
    c1 = _successors(one.succ, n_nodes)
    c2 = _successors(two.succ, n_nodes)
    depth = np.zeros(n_nodes, int)
    has = (c1 >= 0) & (c2 >= 0)
    for _ in range(64):
        new = np.where(has, 1 + np.minimum(depth[np.maximum(c1, 0)], depth[np.maximum(c2, 0)]), 0)
        if np.array_equal(new, depth):
            break
        depth = new
    trees: list[tuple[int, np.ndarray]] = []
    covered = np.zeros(n_nodes, bool)
    for r in np.argsort(-depth, kind="stable"):
        if depth[r] < 1 or covered[r]:
            continue
        dep = min(int(depth[r]), int(np.log2(n_nodes + 1)) - 1)
        nodes = _tree_nodes(int(r), dep, c1, c2)
        while dep >= 1 and (nodes is None or covered[nodes].any()):
            dep -= 1
            nodes = _tree_nodes(int(r), dep, c1, c2)
        if dep < 1 or nodes is None:
            continue
        covered[nodes] = True
        trees.append((dep, nodes))
    if not trees or (len(trees) < 2 and trees[0][0] < 2):
        return None
    used1 = np.array([k for k in one.pairs if covered[ps.src[k]] and c1[ps.src[k]] == ps.dst[k]])
    used2 = np.array([k for k in two.pairs if covered[ps.src[k]] and c2[ps.src[k]] == ps.dst[k]])
    if used1.size == 0 or used2.size == 0:
        return None
    return BranchCandidate(
        space=space,
        groups=tuple(nodes for _, nodes in trees),
        h=float(max(np.mean(prox[used1]), np.mean(prox[used2]))),
        phi=1.0,
        l=float(np.mean([d for d, _ in trees])) * 2.0,
        first=mean_rel(ps.A[used1], ps.B[used1]),
        second=mean_rel(ps.A[used2], ps.B[used2]),
        depths=tuple(d for d, _ in trees),
    )


def _tree_nodes(root: int, depth: int, c1: np.ndarray, c2: np.ndarray) -> np.ndarray | None:
    """Nodes of the full binary tree of ``depth`` under ``root`` (root first), or None if not distinct."""
    level = np.array([root])
    nodes = [level]
    for _ in range(depth):
        level = np.concatenate([c1[level], c2[level]])
        nodes.append(level)
    out = np.concatenate(nodes)
    return out if np.unique(out).size == out.size and (out >= 0).all() else None
