"""Match a batch of candidate elements against one representative (§4.1, steps 2–7).

Helpers of :mod:`lsys_core.instancing.similarity`, on shapes in their normalised frames
(:mod:`lsys_core.instancing.reference`).

1. Vote (:mod:`lsys_core.instancing.vote`): sample pairs of similar radius and curvature
   each imply a rotation and a residual translation; the peaks of the smoothed vote grid
   are the candidate transforms.
2. Refine: batched ICP from up to three distinct peaks on a third of the samples (trimmed
   point-to-line least squares over the complex similarity, closed form), then on all
   samples against foot points on the representative's curves, which makes the pose of a
   clean copy exact however it was drawn.  Open paths also pin their ends by arc length.
3. Score: ``φ`` is the share of the candidate's samples that the transform puts on the
   representative (within ``_INLIER`` RMS radii, normals within ~37°), or the share of the
   representative covered by them if smaller.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lsys_core.instancing.reference import Batch, Reference
from lsys_core.instancing.sampling import bezier
from lsys_core.instancing.vote import VoteSpace

__all__ = ["PERFECT", "MatchResult", "match_batch"]

#: A fit gap (RMS point-to-line distance, in RMS radii) below which a match is taken as exact.
PERFECT = 2e-3

_INLIER = 0.04
_NORMAL_COS = 0.8
_P2P_WEIGHT = 0.1
_FAR = 1.0
_COARSE_STRIDE = 3
_COARSE_ITERS = 6
_FINE_ITERS = 5
_COARSE_MARGIN = 0.2
_ARC_AGREE = 0.1
_CONVERGED = 1e-9


@dataclass(frozen=True, eq=False)
class MatchResult:
    """Per candidate: similarity ``phi``, fit ``gap`` and the map ``rep ≈ c * cand + d`` (normalised)."""

    phi: np.ndarray
    gap: np.ndarray
    c: np.ndarray
    d: np.ndarray


def _nearest(ref: Reference, x: np.ndarray, exact: bool = False):
    """Return the nearest points of the representative to points ``x``.

    Returns distance, dense sample index, whether found (within ``_FAR``), and the nearest
    point and unit normal there: the dense sample's, or with ``exact`` the foot point on
    the curve itself, found by Newton steps from the dense sample (point-to-line residuals
    at foot points vanish for an exact copy, however it was sampled).
    """
    pts = np.column_stack([x.real.ravel(), x.imag.ravel()])
    dist, nn = ref.tree.query(pts, distance_upper_bound=_FAR, workers=-1 if pts.shape[0] > 20000 else 1)
    found = np.isfinite(dist).reshape(x.shape)
    nn = np.minimum(nn, ref.dense.size - 1).reshape(x.shape)
    dist = dist.reshape(x.shape)
    if not exact:
        return dist, nn, found, ref.dense[nn], ref.dense_normals[nn]
    c = ref.cubics[ref.dense_seg[nn]]
    t = ref.dense_t[nn]
    for _ in range(2):
        pos, d1, d2 = bezier(c, t)
        diff = pos - x
        g = (diff * np.conj(d1)).real
        h = np.abs(d1) ** 2 + (diff * np.conj(d2)).real
        h = np.where(h > 1e-12, h, np.maximum(np.abs(d1) ** 2, 1e-12))
        t = np.clip(t - g / h, 0.0, 1.0)
    foot, d1, _ = bezier(c, t)
    speed = np.abs(d1)
    normal = np.where(speed > 1e-9, 1j * d1 / np.maximum(speed, 1e-300), ref.dense_normals[nn])
    return np.where(found, np.abs(x - foot), dist), nn, found, foot, normal


def _arc_targets(ref: Reference, nn: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Return point-to-point targets that follow arc length instead of nearest points.

    Nearest points slide along an open outline with the candidate, so they cannot pin
    down the poses that only the ends of an arc or a line determine.  Arc length can: on
    a single open path the candidate sample at fraction ``u`` corresponds to fraction
    ``u`` (or ``1 - u`` when drawn the other way) of the representative.  The direction is
    the one most nearest points agree with; samples far from their arc-length partner
    (another shape, another subpath layout) keep their nearest point.
    """
    v = ref.dense_frac[nn]
    fwd = np.abs(v - u) <= _ARC_AGREE
    bwd = np.abs(v - (1.0 - u)) <= _ARC_AGREE
    forward = fwd.sum(axis=1) >= bwd.sum(axis=1)
    w = np.where(forward[:, None], u, 1.0 - u)
    agree = np.where(forward[:, None], fwd, bwd)
    m = ref.dense.size
    pos = (w - ref.dense_frac[0]) * m
    k0 = np.floor(pos).astype(np.int64)
    t = pos - k0
    lo, hi = np.clip(k0, 0, m - 1), np.clip(k0 + 1, 0, m - 1)
    interp = ref.dense[lo] * (1 - t) + ref.dense[hi] * t
    return np.where(agree, interp, ref.dense[nn])


def _icp(ref: Reference, q, qn, c, d, iters: int, u=None, exact: bool = False):
    """Refine ``rep ≈ c * q + d`` for every candidate by trimmed point-to-line ICP.

    Each step solves the 4-unknown linear least squares of the point-to-line distances
    (plus a small point-to-point term that keeps it well posed on circles and lines) in
    closed form for all candidates at once.  With the candidates' arc-length fractions
    ``u`` the point-to-point term follows arc length (:func:`_arc_targets`), which pins
    down open arcs and lines exactly; ``exact`` uses foot points on the curve.

    Returns
    -------
    c, d : ndarray of complex
        The refined maps.
    near : tuple of ndarray, shape (b, s) each
        ``(dist, nn, found, foot, normal)`` of :func:`_nearest` under the refined maps.
    """
    b, s = q.shape
    active = np.ones(b, bool)
    near = (
        np.zeros((b, s)),
        np.zeros((b, s), np.int64),
        np.zeros((b, s), bool),
        np.zeros((b, s), complex),
        np.ones((b, s), complex),
    )
    # foot points slide with the candidate, so a point-to-point pull towards them has the
    # wrong Jacobian and slows convergence: keep it faint unless it follows arc length
    lam = _P2P_WEIGHT if (u is not None or not exact) else 0.1 * _P2P_WEIGHT
    for _ in range(iters):
        idx = np.flatnonzero(active)
        if idx.size == 0:
            break
        qa, na = q[idx], qn[idx]
        res = _nearest(ref, c[idx, None] * qa + d[idx, None], exact)
        for full, part in zip(near, res, strict=True):
            full[idx] = part
        di, ni, fi, r, n = res
        rp = r if u is None else _arc_targets(ref, ni, u)
        rot = c[idx] / np.maximum(np.abs(c[idx]), 1e-300)
        compat = np.abs((rot[:, None] * na * np.conj(n)).real) > _NORMAL_COS
        tau = np.maximum(3.0 * np.median(np.where(fi, di, _FAR), axis=1), _INLIER)
        w = fi & (di < tau[:, None]) & compat
        w = np.where(w.sum(axis=1, keepdims=True) >= 4, w, fi).astype(float)
        qn_ = qa * np.conj(n)
        one, zero = np.ones_like(qa.real), np.zeros_like(qa.real)
        jac = np.concatenate(
            [
                np.stack([qn_.real, -qn_.imag, n.real, n.imag], axis=-1),
                lam * np.stack([qa.real, -qa.imag, one, zero], axis=-1),
                lam * np.stack([qa.imag, qa.real, zero, one], axis=-1),
            ],
            axis=1,
        )
        tgt = np.concatenate([(r * np.conj(n)).real, lam * rp.real, lam * rp.imag], axis=1)
        wj = (jac * np.tile(w, 3)[..., None]).transpose(0, 2, 1)
        a_mat = wj @ jac + np.eye(4) * 1e-12
        with np.errstate(all="ignore"):
            sol = np.linalg.solve(a_mat, wj @ tgt[..., None])[..., 0]
        c_new = sol[:, 0] + 1j * sol[:, 1]
        d_new = sol[:, 2] + 1j * sol[:, 3]
        ok = np.isfinite(sol).all(axis=1) & (np.abs(c_new) > 1e-6)
        change = np.abs(c_new - c[idx]) + np.abs(d_new - d[idx])
        c[idx] = np.where(ok, c_new, c[idx])
        d[idx] = np.where(ok, d_new, d[idx])
        active[idx] = ok & (change > _CONVERGED)
    idx = np.flatnonzero(active)
    if idx.size:
        res = _nearest(ref, c[idx, None] * q[idx] + d[idx, None], exact)
        for full, part in zip(near, res, strict=True):
            full[idx] = part
    return c, d, near


def _score(ref: Reference, q, qn, c, d, near, perimeter):
    """Return ``φ`` (the smaller share of either shape's samples lying on the other) and the fit gap.

    The forward share counts candidate samples within ``_INLIER`` of the representative
    (with compatible normals).  The reverse share counts the representative's dense
    samples that lie, along its outline, within reach of a matched candidate sample.
    The gap is the RMS point-to-line distance of the matched samples (``_FAR`` if none).
    """
    dist, nn, found, foot, n = near
    b, s = q.shape
    rot = c / np.maximum(np.abs(c), 1e-300)
    compat = np.abs((rot[:, None] * qn * np.conj(n)).real) > _NORMAL_COS
    inl = found & (dist < _INLIER) & compat
    forward = inl.mean(axis=1)
    line = ((c[:, None] * q + d[:, None] - foot) * np.conj(n)).real
    cnt = inl.sum(axis=1)
    sq = np.sum(np.where(inl, line * line, 0.0), axis=1)
    gap = np.where(cnt > 0, np.sqrt(sq / np.maximum(cnt, 1)), _FAR)
    m = ref.dense.size
    hits = np.zeros((b, m), np.int32)
    rows = np.repeat(np.arange(b), s)
    hits[rows[inl.ravel()], nn[inl]] = 1
    reach = (0.6 * perimeter * np.abs(c) / s + _INLIER) / ref.dense_step
    w = np.clip(np.ceil(reach).astype(np.int64), 1, m // 2)
    wmax = int(w.max())
    padded = np.concatenate([hits[:, m - wmax :], hits, hits[:, :wmax]], axis=1)
    cs = np.zeros((b, m + 2 * wmax + 1), np.int32)
    np.cumsum(padded, axis=1, out=cs[:, 1:])
    backward = np.empty(b)
    for wv in np.unique(w):
        sel = w == wv
        lo = wmax - wv
        covered = cs[sel, lo + 2 * wv + 1 : lo + 2 * wv + 1 + m] - cs[sel, lo : lo + m]
        backward[sel] = (covered > 0).mean(axis=1)
    return np.minimum(forward, backward), gap


def match_batch(
    ref: Reference, batch: Batch, perimeter: np.ndarray, *, threshold: float = 0.6, peaks: int = 3
) -> MatchResult:
    """Vote, refine and score candidates against a representative.

    Parameters
    ----------
    ref : Reference
        The representative in its normalised frame.
    batch : Batch
        Candidates in their normalised frames (centroid 0, RMS radius 1).
    perimeter : ndarray of float, shape (b,)
        Arc length of each candidate in its normalised frame.
    threshold : float
        The similarity that decides; candidates whose coarse fit stays far below it are
        not refined further (their ``phi`` is the coarse estimate).
    peaks : int
        How many distinct vote peaks (rotations) to refine per candidate; the one whose
        refinement fits best wins (nearly symmetric shapes have several strong peaks).

    Returns
    -------
    MatchResult
        ``phi``, ``gap`` and the refined ``rep ≈ c * cand + d`` per candidate.
    """
    b = batch.points.shape[0]
    space = VoteSpace(ref, batch)
    qs = batch.points[:, ::_COARSE_STRIDE]
    ns = batch.normals[:, ::_COARSE_STRIDE]
    c1 = np.ones(b, complex)
    d1 = np.zeros(b, complex)
    key = np.full(b, -np.inf)
    best = np.zeros(b)
    gap1 = np.full(b, _FAR)
    rows = np.arange(b)
    for attempt in range(peaks):
        if rows.size == 0:
            break
        r0, t0, valid = space.peak(rows)
        if attempt:
            rows, r0, t0 = rows[valid], r0[valid], t0[valid]
            if rows.size == 0:
                break
        c0 = np.conj(r0)
        c, d, near = _icp(ref, qs[rows], ns[rows], c0, -c0 * t0, _COARSE_ITERS)
        sc, gap = _score(ref, qs[rows], ns[rows], c, d, near, perimeter[rows] * _COARSE_STRIDE)
        k = sc - 2.0 * gap
        better = k > key[rows]
        sel = rows[better]
        c1[sel], d1[sel], key[sel] = c[better], d[better], k[better]
        best[sel], gap1[sel] = sc[better], gap[better]
        # another peak only for imperfect fits that are not hopeless
        rows = rows[((sc < 1.0) | (gap >= PERFECT)) & (best[rows] >= 0.5 * threshold)]
    phi, gap = best.copy(), gap1
    fine = np.flatnonzero(best >= threshold - _COARSE_MARGIN)
    if fine.size:
        q, qn = batch.points[fine], batch.normals[fine]
        u = (np.arange(q.shape[1]) + 0.5) / q.shape[1] if ref.open_path else None
        c2, d2, near = _icp(ref, q, qn, c1[fine], d1[fine], _FINE_ITERS, u, exact=True)
        phi[fine], gap[fine] = _score(ref, q, qn, c2, d2, near, perimeter[fine])
        c1[fine], d1[fine] = c2, d2
    return MatchResult(phi, gap, c1, d1)
