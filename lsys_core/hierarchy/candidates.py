"""Cluster analysis (paper §5.3): candidate rules from the clusters of one level.

Pairs of live nodes (:mod:`lsys_core.hierarchy.spaces`) are clustered by mean shift in each
space of a pair of symbols.  Clusters *C* of (nearly) equal transforms give sequences
(chains of pairs, r1/r2) and pairs of different symbols; two clusters of one space that
share their first elements give branchings (full binary trees, r3/r4); clusters *D* in
the (d, s) subspace whose α and β change by a constant step give sequences with
parameters linear in m.  Each candidate carries the terms of its importance (§5.4).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from lsys_core.geometry.transforms import wrap_deg
from lsys_core.hierarchy.clustering import mean_shift
from lsys_core.hierarchy.spaces import PairSpace

__all__ = ["NEAR_BAND", "Candidate", "find_candidates", "mean_rel"]


@dataclass
class Candidate:
    kind: str  # "seq", "pair", "branch", "lin"
    space: tuple[int, int]
    groups: list  # chains (lists of node indices) or (root, depth) trees
    T: tuple  # transform(s)
    n: float = 0.0
    h: float = 0.0
    phi: float = 0.0
    l: float = 0.0
    covered: int = 0
    score: float = 0.0
    extra: dict = field(default_factory=dict)


def mean_rel(A: np.ndarray, B: np.ndarray) -> tuple[complex, complex]:
    """Average relative frames: geometric mean of ``A`` (log space), arithmetic mean of ``B``."""
    la = np.log(A)
    ang = np.angle(np.mean(np.exp(1j * la.imag)))
    return complex(np.exp(np.mean(la.real) + 1j * ang)), complex(np.mean(B))


def _space_key(sym: np.ndarray, ps: PairSpace) -> np.ndarray:
    return sym[ps.src] * (int(sym.max()) + 1) + sym[ps.dst]


def _size_of(bld, sym: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    sizes = np.array([s.size for s in bld.syms])
    return np.maximum(sizes[sym[nodes]], 1e-9)


def _proximity(ps: PairSpace, n_nodes: int, radius: np.ndarray) -> np.ndarray:
    """Per-pair proximity in (0, 1]: 1 for a node's nearest neighbour, lower for farther pairs.

    Distances are between the centres of the nodes' geometry, relative to the nearest
    neighbour of either node; neighbours up to :data:`NEAR_BAND` times farther than the
    nearest count as equally near (spacings that differ a little look alike).
    """
    nn = np.full(n_nodes, np.inf)
    np.minimum.at(nn, ps.src, ps.dist)
    eps = 0.1 * float(np.median(radius)) + 1e-12
    near = np.minimum(nn[ps.src], nn[ps.dst])
    return np.minimum(NEAR_BAND * (near + eps) / (ps.dist + eps), 1.0)


def find_candidates(bld, sym, a, b, ps: PairSpace, radius: np.ndarray) -> list[Candidate]:
    """Return the candidate rules of one level, with their importance terms ``n, h, φ, l``.

    Parameters
    ----------
    bld
        The rule builder (bandwidths ``bld.tol``, symbol sizes, shape similarity ``bld.phi``).
    sym, a, b
        Symbol and frame of every live node.
    ps : PairSpace
        The pairs of this level and their relative transforms.
    radius : ndarray
        Radius of every live node's geometry.
    """
    if len(ps) == 0:
        return []
    tol = bld.tol
    size = _size_of(bld, sym, ps.src)
    key = _space_key(sym, ps)
    th = np.angle(ps.A)
    ang = np.deg2rad(tol.angle)
    emb = np.column_stack(
        [
            ps.B.real / (tol.xy * size),
            ps.B.imag / (tol.xy * size),
            np.cos(th) / ang,
            np.sin(th) / ang,
            np.log(np.abs(ps.A)) / tol.scale,
            key * 1e7,
        ]
    )
    labels, _ = mean_shift(emb)
    prox = _proximity(ps, a.size, radius)
    out: list[Candidate] = []
    clusters = _group_indices(labels)
    seq_by_space: dict[tuple[int, int], list[tuple[np.ndarray, dict]]] = {}
    for idx in clusters:
        if idx.size < 2:
            continue  # a single pair repeats nothing
        si, sj = int(sym[ps.src[idx[0]]]), int(sym[ps.dst[idx[0]]])
        cost = np.linalg.norm(emb[idx, :5] - emb[idx, :5].mean(0), axis=1)
        src, dst = ps.src[idx], ps.dst[idx]
        chains, succ = _chains(src, dst, cost, a.size)
        if not chains:
            continue
        used = _chain_pairs(chains, src, dst, idx)
        A, B = mean_rel(ps.A[used], ps.B[used])
        lengths = [len(c) - 1 for c in chains]
        rep = len(chains) >= 2 or max(lengths) >= 2
        seq_by_space.setdefault((si, sj), []).append((idx, succ))
        if not rep:
            continue
        kind = "seq" if si == sj and max(lengths) >= 2 else "pair"
        if kind == "pair":
            chains = [c[:2] for c in chains]
            lengths = [1] * len(chains)
        cand = Candidate(kind, (si, sj), chains, (A, B))
        cand.covered = sum(len(c) for c in chains)
        cand.h = float(np.mean(prox[used]))
        cand.phi = bld.phi(si, sj)
        cand.l = float(np.mean(lengths))
        if kind == "pair" and si != sj:
            cand.extra["succ"] = succ
        out.append(cand)
    _alternation_lengths(out, seq_by_space)
    out += _branch_candidates(bld, ps, {k: v for k, v in seq_by_space.items() if k[0] == k[1]}, prox, a.size)
    out += _linear_candidates(bld, sym, ps, prox, size, key)
    return out


def _alternation_lengths(cands: list[Candidate], clusters: dict) -> None:
    """Give pair candidates A→B the length of the alternating sequences A B A B … they start.

    When a cluster of B→A pairs links each pair's B to the A of the next pair, the pairs
    are the steps of one sequence ``A T B T' A T B …``: merging them first lets the next
    level code it with a single sequence rule.
    """
    for c in cands:
        succ = c.extra.get("succ")
        if succ is None:
            continue
        si, sj = c.space
        best = 1.0
        for _, back in clusters.get((sj, si), [])[:4]:
            targets = set(back.values())
            lengths = []
            for x in (x for x in succ if x not in targets):
                n, cur, seen = 0, x, set()
                while cur in succ and cur not in seen:
                    seen.add(cur)
                    n += 1
                    cur = back.get(succ[cur], -1)
                lengths.append(n)
            if lengths:
                best = max(best, float(np.mean(lengths)))
        c.l = best


def _group_indices(labels: np.ndarray) -> list[np.ndarray]:
    order = np.argsort(labels, kind="stable")
    lab = labels[order]
    cuts = np.flatnonzero(np.diff(lab)) + 1
    return [g for g in np.split(order, cuts) if g.size and labels[g[0]] >= 0]


def _chains(src, dst, cost, n_nodes) -> tuple[list[list[int]], dict[int, int]]:
    """Link pairs into sequences: greedy best pairs, each node with ≤ 1 successor and predecessor."""
    order = np.argsort(cost, kind="stable")
    succ: dict[int, int] = {}
    pred: dict[int, int] = {}
    for e in order:
        i, j = int(src[e]), int(dst[e])
        if i == j or i in succ or j in pred:
            continue
        succ[i] = j
        pred[j] = i
    paths, loops = _follow(succ, sorted(i for i in succ if i not in pred))
    # Rings keep all their nodes; the pair closing the ring is dropped.
    return paths + loops, succ


def _follow(succ: dict[int, int], starts) -> tuple[list[list[int]], list[list[int]]]:
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


def _chain_pairs(chains, src, dst, idx) -> np.ndarray:
    look = {(int(s), int(d)): int(k) for s, d, k in zip(src, dst, idx, strict=True)}
    return np.array([look[(c[t], c[t + 1])] for c in chains for t in range(len(c) - 1)], int)


def _branch_candidates(bld, ps, seq_by_space, prox, n_nodes) -> list[Candidate]:
    """Full binary trees from two clusters of one symbol space sharing their first elements (r3/r4)."""
    out = []
    for (si, sj), clusters in seq_by_space.items():
        big = [c for c in clusters if len(c[1]) >= 2][:8]
        for x in range(len(big)):
            for y in range(x + 1, len(big)):
                (i1, s1), (i2, s2) = big[x], big[y]
                both = set(s1) & set(s2)
                if len(both) < 1:
                    continue
                c1 = np.full(n_nodes, -1)
                c2 = np.full(n_nodes, -1)
                for k, v in s1.items():
                    c1[k] = v
                for k, v in s2.items():
                    c2[k] = v
                depth = np.zeros(n_nodes, int)
                has = (c1 >= 0) & (c2 >= 0)
                for _ in range(64):
                    new = np.where(has, 1 + np.minimum(depth[np.maximum(c1, 0)], depth[np.maximum(c2, 0)]), 0)
                    if np.array_equal(new, depth):
                        break
                    depth = new
                trees, covered = [], np.zeros(n_nodes, bool)
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
                    trees.append((int(r), dep, nodes))
                if not trees or (len(trees) < 2 and trees[0][1] < 2):
                    continue
                used1 = np.array([k for k in i1 if covered[ps.src[k]] and c1[ps.src[k]] == ps.dst[k]])
                used2 = np.array([k for k in i2 if covered[ps.src[k]] and c2[ps.src[k]] == ps.dst[k]])
                if used1.size == 0 or used2.size == 0:
                    continue
                T1 = mean_rel(ps.A[used1], ps.B[used1])
                T2 = mean_rel(ps.A[used2], ps.B[used2])
                cand = Candidate("branch", (si, sj), trees, (T1, T2), extra={"c1": c1, "c2": c2})
                cand.covered = int(covered.sum())
                cand.h = float(max(np.mean(prox[used1]), np.mean(prox[used2])))
                cand.phi = 1.0
                cand.l = float(np.mean([t[1] for t in trees])) * 2.0
                out.append(cand)
    return out


def _tree_nodes(root: int, depth: int, c1: np.ndarray, c2: np.ndarray) -> np.ndarray | None:
    """Nodes of the full binary tree of ``depth`` under ``root``, or None if they are not distinct."""
    level = np.array([root])
    nodes = [level]
    for _ in range(depth):
        level = np.concatenate([c1[level], c2[level]])
        nodes.append(level)
    out = np.concatenate(nodes)
    return out if np.unique(out).size == out.size and (out >= 0).all() else None


#: Pairs up to this factor farther apart than a node's nearest neighbour have proximity 1.
NEAR_BAND = 1.25
#: Step clusters (Δα, Δβ) examined per (d, s) cluster, largest first: smaller ones cannot win.
_STEP_CLUSTERS = 12


def _linear_candidates(bld, sym, ps, prox, size, key) -> list[Candidate]:
    """Sequences whose α and β change by a constant step (clusters D in the (d, s) subspace)."""
    tol = bld.tol
    ok = (ps.d / size > 0.1) & (sym[ps.src] == sym[ps.dst])
    if ok.sum() < 2:
        return []
    sel = np.flatnonzero(ok)
    emb = np.column_stack([ps.d[sel] / (size[sel] * tol.xy), np.log(ps.s[sel]) / tol.scale, key[sel] * 1e7])
    labels, _ = mean_shift(emb)
    out = []
    ang = np.deg2rad(tol.angle)
    for g in _group_indices(labels):
        if g.size < 2:
            continue
        idx = sel[g]
        e1a, e2a = _successor_pairs(ps.src, ps.dst, idx)
        if e1a.size < 1:
            continue
        da = np.deg2rad(wrap_deg(ps.alpha[e2a] - ps.alpha[e1a]))
        db = np.deg2rad(wrap_deg(ps.beta[e2a] - ps.beta[e1a]))
        emb2 = np.column_stack([np.cos(da), np.sin(da), np.cos(db), np.sin(db)]) / ang
        lab2, _ = mean_shift(emb2)
        for g2 in _group_indices(lab2)[:_STEP_CLUSTERS]:
            if g2.size < 2:
                continue  # a single consecutive pair is no sequence
            dA = float(np.rad2deg(np.arctan2(emb2[g2, 1].mean(), emb2[g2, 0].mean())))
            dB = float(np.rad2deg(np.arctan2(emb2[g2, 3].mean(), emb2[g2, 2].mean())))
            if abs(dA) < tol.angle and abs(dB) < tol.angle:
                continue  # constant transform: a cluster C already covers it
            cand = _linear_chains(bld, sym, ps, e1a[g2], e2a[g2], dA, dB, prox)
            if cand is not None:
                out.append(cand)
    return out


def _successor_pairs(src: np.ndarray, dst: np.ndarray, idx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
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


def _edge_chains(e1: np.ndarray, e2: np.ndarray) -> list[list[int]]:
    """Follow links ``e1 → e2`` (each pair with at most one successor and predecessor) into chains."""
    _, first = np.unique(e1, return_index=True)
    e1, e2 = e1[np.sort(first)], e2[np.sort(first)]
    _, first = np.unique(e2, return_index=True)
    e1, e2 = e1[np.sort(first)], e2[np.sort(first)]
    keep = e1 != e2
    nxt = dict(zip(e1[keep].tolist(), e2[keep].tolist(), strict=True))
    has_prev = set(nxt.values())
    paths, loops = _follow(nxt, [s0 for s0 in nxt if s0 not in has_prev])
    # Closed loops (a ring of dots): cut each before its smallest pair and drop the closing one.
    return paths + [loop[:-1] for loop in loops if len(loop) > 2]


def _linear_chains(bld, sym, ps, e1, e2, dA, dB, prox) -> Candidate | None:
    chains_e = _edge_chains(e1, e2)
    # Node-disjoint chains only (greedy, longest first).
    chains_e.sort(key=len, reverse=True)
    taken: set[int] = set()
    groups: dict[tuple, list] = {}
    for ch in chains_e:
        nodes = [int(ps.src[ch[0]])] + [int(ps.dst[e]) for e in ch]
        if taken.intersection(nodes) or len(set(nodes)) != len(nodes):
            continue
        taken.update(nodes)
        k = len(ch)
        al0 = float(ps.alpha[ch[0]])
        be0 = float(ps.beta[ch[0]])
        kq = (k, round(al0 / max(bld.tol.angle, 1e-6)), round(be0 / max(bld.tol.angle, 1e-6)))
        groups.setdefault(kq, []).append((nodes, ch))
    if not groups:
        return None
    # One candidate: the most populated (length, start) group; others follow in later levels.
    _, best = max(groups.items(), key=lambda kv: (len(kv[1]) * kv[0][0], kv[0][0]))
    if len(best) < 2 and len(best[0][1]) < 2:
        return None
    edges = np.array([e for _, ch in best for e in ch])
    step = np.array([t for _, ch in best for t in range(len(ch))])
    al = np.array([float(ps.alpha[ch[0]]) for _, ch in best])
    be = np.array([float(ps.beta[ch[0]]) for _, ch in best])
    k = len(best[0][1])
    # Least-squares fit of α0, β0 given the steps (angles unwrapped around the first chain).
    al_fit = float(np.mean(wrap_deg(ps.alpha[edges] - step * dA - al[0]))) + al[0]
    be_fit = float(np.mean(wrap_deg(ps.beta[edges] - step * dB - be[0]))) + be[0]
    d = float(np.mean(ps.d[edges]))
    s = float(np.exp(np.mean(np.log(ps.s[edges]))))
    si = int(sym[ps.src[edges[0]]])
    cand = Candidate("lin", (si, si), [nodes for nodes, _ in best], (al_fit, d, s, be_fit, dA, dB, k))
    cand.covered = sum(len(n) for n, _ in best)
    cand.h = float(np.mean(prox[edges]))
    cand.phi = 1.0
    cand.l = float(k)
    return cand
