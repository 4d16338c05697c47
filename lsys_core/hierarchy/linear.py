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
from lsys_core.hierarchy.clustering import group_indices, mean_shift
from lsys_core.hierarchy.flat import Groups, greedy_disjoint, sorted_unique
from lsys_core.hierarchy.gain import Ledger, cluster_bounds
from lsys_core.hierarchy.spaces import PairSpace

__all__ = ["linear_candidates"]

#: Step clusters (Δα, Δβ) examined per (d, s) cluster, largest first: smaller ones cannot win.
_STEP_CLUSTERS = 12
#: Consecutive pairs from which the chains of the step clusters are solved in several runs.
_SPLIT = 200_000
#: Consecutive pairs solved in one run at most (unless one step cluster has more): a run's
#: arrays take about 100 bytes per pair, and two runs at a time held 0.9 GiB at 100,000 elements.
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
    # Consecutive pairs i→j→k inside each (d, s) cluster, for all clusters at once.
    n = sym.size
    idx, lab = sel[keep], labels[keep].astype(np.int64)
    e1, e2 = successor_pairs(lab * n + ps.src[idx], lab * n + ps.dst[idx], np.arange(idx.size))
    if e1.size < 2:
        return []
    cluster = lab[e1]
    e1, e2 = idx[e1], idx[e2]
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
    emb2[:, 4] = cluster * 1e7
    lab2, _ = mean_shift(emb2)
    if ledger is not None:
        lab2 = _promising(ledger, lab2, e1, e2, ps)
    problems: list[tuple[np.ndarray, np.ndarray, float, float]] = []
    taken: dict[int, int] = {}
    for g2 in group_indices(lab2):
        if g2.size < 2:
            continue  # a single consecutive pair is no sequence
        c = int(cluster[g2[0]])
        taken[c] = taken.get(c, 0) + 1
        if taken[c] > _STEP_CLUSTERS:
            continue
        dA = float(np.rad2deg(np.arctan2(emb2[g2, 1].mean(), emb2[g2, 0].mean())))
        dB = float(np.rad2deg(np.arctan2(emb2[g2, 3].mean(), emb2[g2, 2].mean())))
        if abs(dA) < tol.angle and abs(dB) < tol.angle:
            continue  # constant transform: a cluster C already covers it
        problems.append((e1[g2], e2[g2], dA, dB))
    del emb2, lab2, e1, e2, cluster  # millions of consecutive pairs at 50,000 elements
    batches = _batches([p[0].size for p in problems], parallel.jobs())
    solved = parallel.pmap(lambda b: _linear_chains(ctx, sym, ps, problems[b[0] : b[1]], prox), batches)
    return [c for part in solved for c in part]


def _batches(sizes: list[int], workers: int) -> list[tuple[int, int]]:
    """Split problems of these sizes into runs, in order, each of ≤ a worker's share and ≤ :data:`_BATCH` pairs.

    The problems are independent (:func:`_linear_chains` solves each on its own keys), so the
    runs can be solved on separate threads and their candidates concatenated in order: the
    result does not depend on the number of workers or runs.  Runs are at most
    :data:`_BATCH` pairs (a larger problem is a run of its own), so memory stays bounded
    whatever the scene's size; small inputs stay in one run.
    """
    total = sum(sizes)
    if total < _SPLIT or len(sizes) < 2:
        return [(0, len(sizes))]
    cap = min(_BATCH, -(-total // max(workers, 1)))
    runs, lo, acc = [], 0, 0
    for i, size in enumerate(sizes):
        if acc and acc + size > cap:
            runs.append((lo, i))
            lo, acc = i, 0
        acc += size
    runs.append((lo, len(sizes)))
    return runs


def _promising(
    ledger: Ledger, labels: np.ndarray, e1: np.ndarray, e2: np.ndarray, ps: PairSpace
) -> np.ndarray:
    """``labels`` with the step clusters that cannot shorten the description set to -1.

    A step cluster links pairs ``e1 → e2``; its chains use its distinct pairs and nodes, so
    they number at least ``nodes - pairs``.
    """
    n_lab = int(labels.max()) + 1 if labels.size else 0
    ok = labels >= 0
    lab = labels[ok]
    m = len(ps)
    pairs = sorted_unique(np.concatenate([lab * m + e1[ok], lab * m + e2[ok]])) // m
    n = len(ledger.nodes)
    nodes = (
        sorted_unique(
            np.concatenate([lab * n + ps.src[e1[ok]], lab * n + ps.dst[e1[ok]], lab * n + ps.dst[e2[ok]]])
        )
        // n
    )
    n_pairs = np.bincount(pairs, minlength=n_lab)
    n_nodes = np.bincount(nodes, minlength=n_lab)
    fam = np.zeros(n_lab, int)
    fam[lab] = ledger.family[ps.src[e1[ok]]]
    bound = ledger.bound(fam, n_nodes, np.full(n_lab, -1), np.zeros(n_lab), np.maximum(n_nodes - n_pairs, 1))
    return np.where(ok & (bound[np.maximum(labels, 0)] > 0.0), labels, -1)


def _linear_chains(ctx, sym, ps, problems, prox) -> list[LinearCandidate]:
    """One candidate per step cluster: its longest node-disjoint chains of one length and start.

    Every step cluster (links ``e1 → e2`` between consecutive pairs, steps ``dA``, ``dB``) is
    an independent problem; all are solved at once on keys offset by the problem's index.
    """
    if not problems:
        return []
    n_pairs, n_nodes = np.int64(len(ps)), np.int64(sym.size)
    pid = np.repeat(np.arange(len(problems), dtype=np.int64), [p[0].size for p in problems])
    e1 = pid * n_pairs + np.concatenate([p[0] for p in problems])
    e2 = pid * n_pairs + np.concatenate([p[1] for p in problems])
    chains_e = edge_groups(e1, e2)
    chains_e = chains_e.take(np.argsort(chains_e.firsts // n_pairs, kind="stable"))  # by problem
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
    order = np.argsort(prob * (int(k_e.max()) + 1) - k_e, kind="stable")
    taken = greedy_disjoint(node_chains, order, int(n_nodes) * len(problems))
    acc = order[taken[order]]
    if acc.size == 0:
        return []
    step_tol = max(ctx.tol.angle, 1e-6)
    first_e = edges[chains_e.offsets[:-1][acc]]
    key = np.column_stack(
        [prob[acc], k_e[acc], np.round(ps.alpha[first_e] / step_tol), np.round(ps.beta[first_e] / step_tol)]
    )
    _, first, inv, counts = np.unique(key, axis=0, return_index=True, return_inverse=True, return_counts=True)
    inv = inv.ravel()
    # Per problem, the most populated (length, start) group (the first such group on ties).
    kq, pq = k_e[acc][first], prob[acc][first]
    rank = np.lexsort((first, -kq, -counts * kq, pq))
    win = rank[np.r_[True, pq[rank][1:] != pq[rank][:-1]]]
    winning = np.zeros(first.size, bool)
    winning[win] = True
    best = acc[winning[inv]]  # the winners' chains, per problem in greedy order
    cuts = np.searchsorted(prob[best], np.arange(len(problems) + 1))
    out = []
    for p, (_, _, dA, dB) in enumerate(problems):
        chosen = best[cuts[p] : cuts[p + 1]]
        if chosen.size == 0 or (chosen.size < 2 and k_e[chosen[0]] < 2):
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
