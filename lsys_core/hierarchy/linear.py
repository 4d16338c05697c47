"""Sequences with parameters linear in m (§5.1 eq. 4, §5.3 clusters *D*).

Pairs whose transforms share ``(d, s)`` but whose turns ``α``, ``β`` change by a constant
step along a chain are the steps of ``P(m) -> A +(α0 + Δα·(k-m)) f(d) *(s) +(β0 + Δβ·(k-m)) P(m-1)``:
a row of leaves each turned a little more than the last.  They are found by clustering the
pairs in the (d, s) subspace, then the differences of consecutive pairs' turns.
"""

from __future__ import annotations

import numpy as np

from lsys_core.geometry.transforms import wrap_deg
from lsys_core.hierarchy.candidates import Context, LinearCandidate
from lsys_core.hierarchy.chains import edge_chains, successor_pairs
from lsys_core.hierarchy.clustering import group_indices, mean_shift
from lsys_core.hierarchy.gain import Ledger, cluster_bounds
from lsys_core.hierarchy.spaces import PairSpace

__all__ = ["linear_candidates"]

#: Step clusters (Δα, Δβ) examined per (d, s) cluster, largest first: smaller ones cannot win.
_STEP_CLUSTERS = 12


def linear_candidates(
    ctx: Context,
    sym: np.ndarray,
    ps: PairSpace,
    prox: np.ndarray,
    size: np.ndarray,
    key: np.ndarray,
    ledger: Ledger | None = None,
) -> list[LinearCandidate]:
    """Sequences whose α and β change by a constant step (clusters D in the (d, s) subspace).

    With a ``ledger``, clusters that cannot shorten the description are skipped.
    """
    tol = ctx.tol
    ok = (ps.d / size > 0.1) & (sym[ps.src] == sym[ps.dst])
    if ok.sum() < 2:
        return []
    sel = np.flatnonzero(ok)
    emb = np.column_stack([ps.d[sel] / (size[sel] * tol.xy), np.log(ps.s[sel]) / tol.scale, key[sel] * 1e7])
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
    da = np.deg2rad(wrap_deg(ps.alpha[e2] - ps.alpha[e1]))
    db = np.deg2rad(wrap_deg(ps.beta[e2] - ps.beta[e1]))
    emb2 = np.column_stack(
        [np.cos(da) / ang, np.sin(da) / ang, np.cos(db) / ang, np.sin(db) / ang, cluster * 1e7]
    )
    lab2, _ = mean_shift(emb2)
    if ledger is not None:
        lab2 = _promising(ledger, lab2, e1, e2, ps)
    out = []
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
        cand = _linear_chains(ctx, sym, ps, e1[g2], e2[g2], dA, dB, prox)
        if cand is not None:
            out.append(cand)
    return out


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
    pairs = np.unique(np.concatenate([lab * m + e1[ok], lab * m + e2[ok]])) // m
    n = len(ledger.nodes)
    nodes = (
        np.unique(
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


def _linear_chains(ctx, sym, ps, e1, e2, dA, dB, prox) -> LinearCandidate | None:
    chains_e = edge_chains(e1, e2)
    # Node-disjoint chains only (greedy, longest first).
    chains_e.sort(key=len, reverse=True)
    taken: set[int] = set()
    groups: dict[tuple, list] = {}
    step_tol = max(ctx.tol.angle, 1e-6)
    for ch in chains_e:
        nodes = [int(ps.src[ch[0]])] + [int(ps.dst[e]) for e in ch]
        if taken.intersection(nodes) or len(set(nodes)) != len(nodes):
            continue
        taken.update(nodes)
        k = len(ch)
        kq = (k, round(float(ps.alpha[ch[0]]) / step_tol), round(float(ps.beta[ch[0]]) / step_tol))
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
    # Least-squares fit of α0, β0 given the steps (angles unwrapped around the first chain).
    al_fit = float(np.mean(wrap_deg(ps.alpha[edges] - step * dA - al[0]))) + al[0]
    be_fit = float(np.mean(wrap_deg(ps.beta[edges] - step * dB - be[0]))) + be[0]
    si = int(sym[ps.src[edges[0]]])
    return LinearCandidate(
        space=(si, si),
        groups=tuple(np.array(nodes) for nodes, _ in best),
        h=float(np.mean(prox[edges])),
        phi=1.0,
        l=float(len(best[0][1])),
        alpha0=al_fit,
        d=float(np.mean(ps.d[edges])),
        s=float(np.exp(np.mean(np.log(ps.s[edges])))),
        beta0=be_fit,
        d_alpha=dA,
        d_beta=dB,
        steps=len(best[0][1]),
    )
