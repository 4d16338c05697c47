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
from lsys_core.hierarchy.spaces import PairSpace

__all__ = ["linear_candidates"]

#: Step clusters (Δα, Δβ) examined per (d, s) cluster, largest first: smaller ones cannot win.
_STEP_CLUSTERS = 12


def linear_candidates(
    ctx: Context, sym: np.ndarray, ps: PairSpace, prox: np.ndarray, size: np.ndarray, key: np.ndarray
) -> list[LinearCandidate]:
    """Sequences whose α and β change by a constant step (clusters D in the (d, s) subspace)."""
    tol = ctx.tol
    ok = (ps.d / size > 0.1) & (sym[ps.src] == sym[ps.dst])
    if ok.sum() < 2:
        return []
    sel = np.flatnonzero(ok)
    emb = np.column_stack([ps.d[sel] / (size[sel] * tol.xy), np.log(ps.s[sel]) / tol.scale, key[sel] * 1e7])
    labels, _ = mean_shift(emb)
    out = []
    ang = np.deg2rad(tol.angle)
    for g in group_indices(labels):
        if g.size < 2:
            continue
        idx = sel[g]
        e1a, e2a = successor_pairs(ps.src, ps.dst, idx)
        if e1a.size < 1:
            continue
        da = np.deg2rad(wrap_deg(ps.alpha[e2a] - ps.alpha[e1a]))
        db = np.deg2rad(wrap_deg(ps.beta[e2a] - ps.beta[e1a]))
        emb2 = np.column_stack([np.cos(da), np.sin(da), np.cos(db), np.sin(db)]) / ang
        lab2, _ = mean_shift(emb2)
        for g2 in group_indices(lab2)[:_STEP_CLUSTERS]:
            if g2.size < 2:
                continue  # a single consecutive pair is no sequence
            dA = float(np.rad2deg(np.arctan2(emb2[g2, 1].mean(), emb2[g2, 0].mean())))
            dB = float(np.rad2deg(np.arctan2(emb2[g2, 3].mean(), emb2[g2, 2].mean())))
            if abs(dA) < tol.angle and abs(dB) < tol.angle:
                continue  # constant transform: a cluster C already covers it
            cand = _linear_chains(ctx, sym, ps, e1a[g2], e2a[g2], dA, dB, prox)
            if cand is not None:
                out.append(cand)
    return out


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
