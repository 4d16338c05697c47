"""Cluster analysis (paper §5.3): the candidate rules of one level.

Pairs of live nodes (:mod:`lsys_core.hierarchy.spaces`) are clustered by mean shift in each
space of a pair of symbols.  Clusters *C* of (nearly) equal transforms give sequences
(chains of pairs, r1/r2) and pairs of different symbols; two clusters of one space that
share their first elements give branchings (full binary trees, r3/r4,
:mod:`lsys_core.hierarchy.branching`); clusters *D* in the (d, s) subspace whose α and β
change by a constant step give sequences with parameters linear in m
(:mod:`lsys_core.hierarchy.linear`).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from lsys_core.hierarchy.branching import branch_candidates
from lsys_core.hierarchy.candidates import (
    Candidate,
    ConstantCluster,
    Context,
    PairCandidate,
    SeqCandidate,
    cluster_means,
    proximity,
    space_key,
)
from lsys_core.hierarchy.chains import link_clusters
from lsys_core.hierarchy.clustering import group_indices, mean_shift, spread
from lsys_core.hierarchy.gain import Ledger, cluster_bounds
from lsys_core.hierarchy.linear import linear_candidates
from lsys_core.hierarchy.spaces import PairSpace
from lsys_core.hierarchy.spacing import spacing_cap
from lsys_core.parallel import submit

__all__ = ["find_candidates"]

#: Pairs up to which the linear sequences are sought beside the constant clusters.  Beyond, the
#: two take turns: each needs memory in proportion to the pairs.  At once, a 50,052-leaf grid
#: (1.21·10^6 pairs, 2 jobs) took 10.6 instead of 12.2 s for 1.23 instead of 1.04 GB resident;
#: a 100,010-leaf grid (2.41·10^6 pairs) needed 2.27 GB and was slower (37.8 against 31.1 s).
BESIDE_PAIRS = 1_500_000
#: Pairs from which the linear sequences are sought beside the constant clusters at all.  Below,
#: both are a few milliseconds of small numpy calls that hold the interpreter: on two workers
#: they waited for each other, and the 76 levels of a published flag (86 elements) took 5 %
#: longer with 2 jobs than with 1 (see :data:`lsys_core.hierarchy.rules.LEDGER_BESIDE`).
BESIDE_MIN_PAIRS = 20_000


def find_candidates(
    ctx: Context, sym: np.ndarray, ps: PairSpace, radius: np.ndarray, ledger: Ledger | None = None
) -> list[Candidate]:
    """Return the candidate rules of one level.

    Parameters
    ----------
    ctx : Context
        Bandwidths, symbol sizes and symbol similarity.
    sym : ndarray of int
        Symbol of every live node.
    ps : PairSpace
        The pairs of this level and their relative transforms.
    radius : ndarray
        Radius of every live node's geometry.
    ledger : Ledger, optional
        The description length of the level: clusters that cannot shorten it, even at best
        (:func:`~lsys_core.hierarchy.gain.cluster_bounds`), are not examined further.
    """
    if len(ps) == 0:
        return []
    tol = ctx.tol
    size = np.maximum(ctx.sizes()[sym[ps.src]], 1e-9)
    key = space_key(sym, ps)
    xy, ang, scale = _bandwidths(tol, size, ps, ledger)
    terminal_sizes = ctx.sizes()[: ctx.n_terminals]
    floor = tol.xy * float(np.median(terminal_sizes)) if terminal_sizes.size else 0.0
    xy = np.minimum(xy, spacing_cap(ps, key, sym[ps.src] >= ctx.n_terminals, sym.size, floor))
    prox = proximity(ps, sym.size, radius)
    # The linear sequences (clusters D) need nothing from the clusters C: found beside them
    # (with one job, at once: before the embedding of the clusters C is made).
    linear = (
        submit(linear_candidates, ctx, sym, ps, prox, size, xy, key, ledger)
        if BESIDE_MIN_PAIRS <= len(ps) <= BESIDE_PAIRS
        else None
    )
    th = np.angle(ps.A)
    emb = np.column_stack(
        [
            ps.B.real / xy,
            ps.B.imag / xy,
            np.cos(th) / ang,
            np.sin(th) / ang,
            np.log(np.abs(ps.A)) / scale,
            key * 1e7,
        ]
    )
    del th
    labels, _ = mean_shift(emb)
    if ledger is not None:
        hopeless = cluster_bounds(ledger, labels, ps.src, ps.dst) <= 0.0
        labels = np.where((labels >= 0) & ~hopeless[np.maximum(labels, 0)], labels, -1)
    n_nodes = sym.size
    out: list[Candidate] = []
    found: list[ConstantCluster] = []
    pending: list[tuple[int, ConstantCluster]] = []
    clusters = [idx for idx in group_indices(labels) if idx.size >= 2]  # a single pair repeats nothing
    costs = spread(emb[:, :5], clusters)
    links = link_clusters(clusters, costs, ps.src, ps.dst, n_nodes)
    means = cluster_means(ps.A, ps.B, prox, [lk.used if len(lk.chains) else lk.used[:0] for lk in links])
    for idx, linked, mean in zip(clusters, links, means, strict=True):
        si, sj = int(sym[ps.src[idx[0]]]), int(sym[ps.dst[idx[0]]])
        chain_list = linked.chains
        if len(chain_list) == 0 or mean is None:
            continue
        cluster = ConstantCluster((si, sj), idx, linked.src, linked.dst)
        found.append(cluster)
        A, B, h = mean  # mean_rel(ps.A[used], ps.B[used]) and np.mean(prox[used]), for all clusters at once
        lengths = chain_list.lengths - 1
        if len(chain_list) < 2 and lengths.max() < 2:
            continue
        phi = ctx.phi(si, sj)
        cand: Candidate
        if si == sj and lengths.max() >= 2:
            cand = SeqCandidate(
                space=(si, sj), groups=chain_list, h=h, phi=phi, l=float(np.mean(lengths)), A=A, B=B
            )
        else:
            pairs = chain_list.head(2)
            cand = PairCandidate(space=(si, sj), groups=pairs, h=h, phi=phi, l=1.0, A=A, B=B)
            if si != sj:
                pending.append((len(out), cluster))
        out.append(cand)
    by_space: dict[tuple[int, int], list[ConstantCluster]] = {}
    for cl in found:
        by_space.setdefault(cl.space, []).append(cl)
    for k, cl in pending:
        out[k] = replace(out[k], l=_alternation_length(cl.succ, by_space.get(cl.space[::-1], [])))
    same = {k: v for k, v in by_space.items() if k[0] == k[1]}
    out += branch_candidates(ps, same, prox, n_nodes)
    out += (
        linear.result()
        if linear is not None
        else linear_candidates(ctx, sym, ps, prox, size, xy, key, ledger)
    )
    return out


#: The widest turn (radians) and log-scale the tolerance floor lets the clustering ignore.
_FLOOR_CAP = np.pi / 8
#: A pair whose nodes already deviate by this share of the tolerance (together) is measured
#: with the whole floor; pairs of copies closer to their terminal with a part of it.
_NOISE = 4.0


def _bandwidths(
    tol, size: np.ndarray, ps: PairSpace, ledger: Ledger | None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Bandwidths of every pair's translation, turn (radians) and log-scale.

    The paper's bandwidths are relative to the size of the shapes (§5.3), but the noise of
    copies drawn by hand is absolute: a dot 6 units wide drawn 10 % larger and 0.2 units off
    its place moves its step by a tenth of its size.  Such copies show it: their outlines
    deviate from their terminal's (the tolerance their node has left, ``slack``, is smaller).
    A pair of symbols whose nodes deviate by ``d1`` and ``d2`` on average is measured with that
    noise: the translation bandwidth is at least ``tol.length·min(eps, 4·(d1 + d2))``
    (:data:`_NOISE`), and turns and scale changes that move the source's outline by as little
    are not told apart either.  The floor is one per pair of symbols, in the source symbol's
    typical frame: within one space every pair is measured in the same units (mean shift
    needs that; a spiral's steps are constant in their own frames).  The relaxed tries of the
    pipeline scale ``tol.length`` with the other bandwidths.  Exact
    copies keep the paper's bandwidths; without a ledger (no precision), so does every pair.
    """
    xy = tol.xy * size
    ang = np.full(size.shape, np.deg2rad(tol.angle))
    scale = np.full(size.shape, float(tol.scale))
    if ledger is None or tol.length <= 0.0:
        return xy, ang, scale
    eps, nodes = ledger.prec.eps, ledger.nodes
    # per symbol (so that one space is measured in one unit): the mean deviation of its nodes'
    # outlines, and their typical scale (the pairs' transforms are in their source's frame)
    noise = np.clip(eps - nodes.slack, 0.0, eps)
    count = np.maximum(np.bincount(nodes.sym), 1)
    noise = np.bincount(nodes.sym, noise) / count
    scale_of = np.exp(np.bincount(nodes.sym, np.log(np.maximum(np.abs(nodes.a), 1e-300))) / count)
    si, sj = nodes.sym[ps.src], nodes.sym[ps.dst]
    floor = tol.length * np.minimum(_NOISE * (noise[si] + noise[sj]), eps) / scale_of[si]
    turn = np.minimum(floor / size, _FLOOR_CAP)
    return np.maximum(xy, floor), np.maximum(ang, turn), np.maximum(scale, turn)


def _alternation_length(succ: dict[int, int], back_clusters: list[ConstantCluster]) -> float:
    """The length of the alternating sequences ``A B A B …`` that pairs ``A → B`` start.

    When a cluster of B→A pairs links each pair's B to the A of the next pair, the pairs
    are the steps of one sequence ``A T B T' A T B …``: merging them first lets the next
    level code it with a single sequence rule.
    """
    best = 1.0
    for back_cl in back_clusters[:4]:
        back = back_cl.succ
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
    return best
