"""Sequences with parameters linear in m (§5.1 eq. 4, §5.3 clusters *D*).

Pairs whose transforms share ``(d, s)`` but whose turns ``α``, ``β`` change by a constant
step along a chain are the steps of ``P(m) -> A +(α0 + Δα·(k-m)) f(d) *(s) +(β0 + Δβ·(k-m)) P(m-1)``:
a row of leaves each turned a little more than the last.  They are found by clustering the
pairs in the (d, s) subspace, then the differences of consecutive pairs' turns.
"""

from __future__ import annotations

import numpy as np

from lsys_core import parallel
from lsys_core.geometry.transforms import wrap_deg
from lsys_core.hierarchy.candidates import Context, LinearCandidate
from lsys_core.hierarchy.chains import edge_groups, successor_pairs
from lsys_core.hierarchy.clustering import RANK, mean_shift, rank_order, ranked_mean_shift
from lsys_core.hierarchy.flat import Groups, greedy_disjoint
from lsys_core.hierarchy.gain import Ledger, cluster_bounds
from lsys_core.hierarchy.spaces import PairSpace
from lsys_core.sorting import (
    dense_fits,
    distinct_counts,
    row_groups,
    sorted_unique,
    stable_argsort,
)

__all__ = ["linear_candidates"]

#: Step clusters (Δα, Δβ) examined per (d, s) cluster, largest first: smaller ones cannot win.
_STEP_CLUSTERS = 12
#: (d, s) clusters are examined in parts of up to this many pairs (a larger cluster is a part of
#: its own): a part's consecutive pairs (about 7 per pair in a grid) are all its memory.
_PART = 100_000
#: Consecutive pairs from which the chains of a part's step clusters are solved in several runs.
_SPLIT = 200_000
#: Consecutive pairs solved in one run at most (unless one step cluster has more): a run's
#: arrays take about 100 bytes per pair.
_BATCH = 500_000


def linear_candidates(
    ctx: Context,
    sym: np.ndarray,
    ps: PairSpace,
    prox: np.ndarray,
    size: np.ndarray,
    xy: np.ndarray,
    key: np.ndarray,
    ledger: Ledger | None = None,
) -> list[LinearCandidate]:
    """Sequences whose α and β change by a constant step (clusters D in the (d, s) subspace).

    ``size`` is every pair's source size and ``xy`` its translation bandwidth.  With a
    ``ledger``, clusters that cannot shorten the description are skipped.

    Consecutive pairs never leave their (d, s) cluster, so the clusters are examined in parts
    (:data:`_PART`) on :func:`lsys_core.parallel.jobs` threads, each part holding only its
    own consecutive pairs (10^7 at 100,000 elements); the step clusters of all parts are then
    put in the order of one mean shift of all of them (:func:`ranked_mean_shift`): the result
    does not depend on the parts or the number of workers.
    """
    tol = ctx.tol
    ok = (ps.d / size > 0.1) & (sym[ps.src] == sym[ps.dst])
    if ok.sum() < 2:
        return []
    sel = np.flatnonzero(ok)
    emb = np.column_stack([ps.d[sel] / xy[sel], np.log(ps.s[sel]) / tol.scale, key[sel] * 1e7])
    labels, _ = mean_shift(emb)
    if ledger is not None:
        hopeless = cluster_bounds(ledger, labels, ps.src[sel], ps.dst[sel]) <= 0.0
        labels = np.where((labels >= 0) & ~hopeless[np.maximum(labels, 0)], labels, -1)
    keep = labels >= 0
    if keep.sum() < 2:
        return []
    idx, lab = sel[keep], labels[keep].astype(np.int64)
    by_cluster = stable_argsort(lab)
    bounds = np.concatenate([[0], np.cumsum(np.bincount(lab))])

    def solve(part: tuple[int, int]) -> tuple[list[LinearCandidate], np.ndarray]:
        take = np.sort(by_cluster[bounds[part[0]] : bounds[part[1]]])  # in the order of the pairs
        return _part_candidates(ctx, sym, ps, prox, idx[take], lab[take], ledger)

    solved = parallel.pmap(solve, parallel.runs(np.diff(bounds).tolist(), _PART))
    found = [c for part, _ in solved for c in part]
    rank = np.concatenate([r for _, r in solved])
    return [found[k] for k in rank_order(rank)]


def _part_candidates(
    ctx: Context,
    sym: np.ndarray,
    ps: PairSpace,
    prox: np.ndarray,
    idx: np.ndarray,
    lab: np.ndarray,
    ledger: Ledger | None,
) -> tuple[list[LinearCandidate], np.ndarray]:
    """The candidates of the (d, s) clusters ``lab`` of pairs ``idx``, and their step clusters' ranks."""
    tol = ctx.tol
    # Consecutive pairs i→j→k inside each (d, s) cluster, for all the part's clusters at once
    # (pair indices and clusters in 32 bits: the part's largest arrays).
    n = sym.size
    e1, e2 = successor_pairs(lab * n + ps.src[idx], lab * n + ps.dst[idx], np.arange(idx.size))
    if e1.size < 2:
        return [], np.zeros(0, RANK)
    cluster = lab.astype(np.int32)[e1]
    narrow = idx.astype(np.int32) if len(ps) < 2**31 else idx
    e1, e2 = narrow[e1], narrow[e2]
    ang = np.deg2rad(tol.angle)
    # The steps of α and β as (cos, sin) / ang, and the cluster: filled in place, column by
    # column (stacking five temporaries doubled this array's 77 MiB at 20,000 elements).
    emb2 = np.empty((e1.size, 5))
    for col, angles in ((0, ps.alpha), (2, ps.beta)):
        step = np.deg2rad(wrap_deg(angles[e2] - angles[e1]))
        np.cos(step, out=emb2[:, col])
        np.sin(step, out=emb2[:, col + 1])
    del step
    emb2[:, :4] /= ang
    np.multiply(cluster, 1e7, out=emb2[:, 4])
    lab2, _, rank = ranked_mean_shift(emb2)
    # The step clusters' members, label after label (increasing within each).
    order = stable_argsort(lab2)
    starts = np.searchsorted(lab2[order], np.arange(rank.size + 1))
    wanted = np.diff(starts) >= 2  # a single consecutive pair is no sequence
    if ledger is not None:
        wanted &= _promising(ledger, order, starts, e1, e2, ps)
    problems: list[tuple[np.ndarray, np.ndarray, float, float]] = []
    ranks: list[int] = []
    taken: dict[int, int] = {}
    for label in np.flatnonzero(wanted).tolist():
        g2 = order[starts[label] : starts[label + 1]]
        c = int(cluster[g2[0]])
        taken[c] = taken.get(c, 0) + 1
        if taken[c] > _STEP_CLUSTERS:
            continue
        dA = float(np.rad2deg(np.arctan2(emb2[g2, 1].mean(), emb2[g2, 0].mean())))
        dB = float(np.rad2deg(np.arctan2(emb2[g2, 3].mean(), emb2[g2, 2].mean())))
        if abs(dA) < tol.angle and abs(dB) < tol.angle:
            continue  # constant transform: a cluster C already covers it
        problems.append((e1[g2], e2[g2], dA, dB))
        ranks.append(label)
    del emb2, lab2, order, e1, e2, cluster  # millions of consecutive pairs at 50,000 elements
    sizes = [p[0].size for p in problems]
    runs = parallel.runs(sizes, _BATCH) if sum(sizes) >= _SPLIT else [(0, len(problems))]
    solved = [
        c
        for part in parallel.pmap(
            lambda run: _linear_chains(ctx, sym, ps, problems[run[0] : run[1]], prox), runs
        )
        for c in part
    ]
    found = [k for k, c in enumerate(solved) if c is not None]
    return [c for c in solved if c is not None], rank[np.asarray(ranks, np.int64)[found]]


def _promising(
    ledger: Ledger, order: np.ndarray, starts: np.ndarray, e1: np.ndarray, e2: np.ndarray, ps: PairSpace
) -> np.ndarray:
    """Per step cluster (members ``order[starts[k]:starts[k + 1]]``), whether it may shorten the description.

    A step cluster links pairs ``e1 → e2``; its chains use its distinct pairs and nodes, so
    they number at least ``nodes - pairs``.  The clusters are counted in blocks of about
    :data:`_BATCH` consecutive pairs (their temporaries are five times their size).
    """
    n_lab = starts.size - 1
    m, n = np.int64(len(ps)), np.int64(len(ledger.nodes))

    def count(run: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
        lo, hi = run
        members = order[starts[lo] : starts[hi]]
        lab = np.repeat(np.arange(lo, hi, dtype=np.int64), np.diff(starts[lo : hi + 1]))
        a, b = e1[members], e2[members]
        if dense_fits(hi - lo, int(m), 2 * a.size):
            # few cells: count distinct pairs and nodes by marking them (the same counts)
            lab2 = np.concatenate([lab, lab]) - lo
            ends = np.concatenate([ps.src[a], ps.src[b], ps.dst[a], ps.dst[b]])
            return (
                distinct_counts(lab2, np.concatenate([a, b]), hi - lo, int(m)),
                distinct_counts(np.concatenate([lab2, lab2]), ends, hi - lo, int(n)),
            )
        keys = sorted_unique(np.concatenate([lab * m + a, lab * m + b]))
        lab, pair = np.divmod(keys, m)
        n_pairs = np.bincount(lab - lo, minlength=hi - lo)
        # the nodes of its pairs (i→j→k: the j of one is the source of the next)
        nodes = sorted_unique(np.concatenate([lab * n + ps.src[pair], lab * n + ps.dst[pair]]))
        return n_pairs, np.bincount(nodes // n - lo, minlength=hi - lo)

    counted = parallel.pmap(count, parallel.runs(np.diff(starts).tolist(), _BATCH))
    n_pairs = np.concatenate([c[0] for c in counted]) if counted else np.zeros(0, np.int64)
    n_nodes = np.concatenate([c[1] for c in counted]) if counted else np.zeros(0, np.int64)
    fam = ledger.family[ps.src[e1[order[starts[1:] - 1]]]]  # the last member's, as one assignment gives
    bound = ledger.bound(fam, n_nodes, np.full(n_lab, -1), np.zeros(n_lab), np.maximum(n_nodes - n_pairs, 1))
    return bound > 0.0


def _linear_chains(ctx, sym, ps, problems, prox) -> list[LinearCandidate | None]:
    """One candidate per step cluster: its longest node-disjoint chains of one length and start.

    Every step cluster (links ``e1 → e2`` between consecutive pairs, steps ``dA``, ``dB``) is
    an independent problem; all are solved at once on keys offset by the problem's index.
    Returns one entry per problem (None: no sequence).
    """
    if not problems:
        return []
    n_pairs, n_nodes = np.int64(len(ps)), np.int64(sym.size)
    pid = np.repeat(np.arange(len(problems), dtype=np.int64), [p[0].size for p in problems])
    e1 = pid * n_pairs + np.concatenate([p[0] for p in problems])
    e2 = pid * n_pairs + np.concatenate([p[1] for p in problems])
    chains_e = edge_groups(e1, e2)
    chains_e = chains_e.take(stable_argsort(chains_e.firsts // n_pairs))  # by problem
    prob = chains_e.firsts // n_pairs
    edges = chains_e.nodes % n_pairs
    k_e = chains_e.lengths
    # Node chains: the first pair's source, then every pair's destination (offset by problem).
    offsets = chains_e.offsets + np.arange(len(chains_e) + 1)
    nodes = np.empty(int(offsets[-1]), np.int64)
    head = np.zeros(nodes.size, bool)
    head[offsets[:-1]] = True
    base = np.repeat(prob, k_e)
    nodes[head] = ps.src[edges[chains_e.offsets[:-1]]] + prob * n_nodes
    nodes[~head] = ps.dst[edges] + base * n_nodes
    node_chains = Groups(nodes, offsets)
    # Node-disjoint chains only (greedy, longest first, per problem).
    order = stable_argsort(prob * (int(k_e.max()) + 1) - k_e)
    taken = greedy_disjoint(node_chains, order, int(n_nodes) * len(problems))
    acc = order[taken[order]]
    if acc.size == 0:
        return [None] * len(problems)
    step_tol = max(ctx.tol.angle, 1e-6)
    first_e = edges[chains_e.offsets[:-1][acc]]
    first, inv, counts = row_groups(
        [prob[acc], k_e[acc], np.round(ps.alpha[first_e] / step_tol), np.round(ps.beta[first_e] / step_tol)]
    )
    # Per problem, the most populated (length, start) group (the first such group on ties).
    kq, pq = k_e[acc][first], prob[acc][first]
    rank = np.lexsort((first, -kq, -counts * kq, pq))
    win = rank[np.r_[True, pq[rank][1:] != pq[rank][:-1]]]
    winning = np.zeros(first.size, bool)
    winning[win] = True
    best = acc[winning[inv]]  # the winners' chains, per problem in greedy order
    cuts = np.searchsorted(prob[best], np.arange(len(problems) + 1))
    out: list[LinearCandidate | None] = []
    for p, (_, _, dA, dB) in enumerate(problems):
        chosen = best[cuts[p] : cuts[p + 1]]
        if chosen.size == 0 or (chosen.size < 2 and k_e[chosen[0]] < 2):
            out.append(None)
            continue
        cand = _candidate(
            sym, ps, prox, chains_e.take(chosen), node_chains.take(chosen), n_pairs, n_nodes, dA, dB
        )
        out.append(cand)
    return out


def _candidate(sym, ps, prox, chains_e, node_chains, n_pairs, n_nodes, dA, dB) -> LinearCandidate:
    edges = chains_e.nodes % n_pairs
    steps = int(chains_e.lengths[0])
    step = chains_e.positions()
    al = ps.alpha[chains_e.firsts % n_pairs]
    be = ps.beta[chains_e.firsts % n_pairs]
    # Least-squares fit of α0, β0 given the steps (angles unwrapped around the first chain).
    al_fit = float(np.mean(wrap_deg(ps.alpha[edges] - step * dA - al[0]))) + al[0]
    be_fit = float(np.mean(wrap_deg(ps.beta[edges] - step * dB - be[0]))) + be[0]
    si = int(sym[ps.src[edges[0]]])
    return LinearCandidate(
        space=(si, si),
        groups=Groups(node_chains.nodes % n_nodes, node_chains.offsets),
        h=float(np.mean(prox[edges])),
        phi=1.0,
        l=float(steps),
        alpha0=al_fit,
        d=float(np.mean(ps.d[edges])),
        s=float(np.exp(np.mean(np.log(ps.s[edges])))),
        beta0=be_fit,
        d_alpha=dA,
        d_beta=dB,
        steps=steps,
    )
