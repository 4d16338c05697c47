"""Step 1 of matching (§4.1, steps 5–6): transform votes of compatible sample pairs, and their peaks.

Sample pairs of similar radius and curvature each imply a rotation (from their normals, both
senses since the drawing direction is unknown) and a residual translation; the votes go into
a 3D grid ``(angle, tx, ty)`` per candidate, and the peaks of the smoothed grid are the
candidate transforms that :mod:`lsys_core.instancing.match` refines.
"""

from __future__ import annotations

import numpy as np

from lsys_core.instancing.reference import Batch, Reference

__all__ = ["VoteSpace"]

_ANGLE_BINS = 36
_T_BINS = 6
_T_RANGE = 0.3
_RADIUS_TOL = 0.06
_CURV_TOL = 0.2
_PAIR_CAP = 24
_VOTE_STRIDE = 2


def _votes(ref: Reference, batch: Batch, stride: int):
    """Cast the transform votes of all radius- and curvature-compatible sample pairs."""
    q = batch.points[:, ::stride]
    s = q.shape[1]
    rho_q = np.abs(q).ravel()
    lo = np.searchsorted(ref.radius_sorted, rho_q - _RADIUS_TOL, side="left")
    hi = np.searchsorted(ref.radius_sorted, rho_q + _RADIUS_TOL, side="right")
    span = hi - lo
    take = np.minimum(span, _PAIR_CAP)
    qi = np.repeat(np.arange(rho_q.size), take)
    within = np.arange(qi.size) - np.repeat(np.cumsum(take) - take, take)
    step = np.where(take > 0, span / np.maximum(take, 1), 0.0)
    pi = ref.order[lo[qi] + (within * step[qi]).astype(np.int64)]
    kq = np.arctan(batch.curvature[:, ::stride].ravel()[qi])
    kp = np.arctan(ref.curvature[pi])
    keep = np.abs(kq - kp) < _CURV_TOL
    qi, pi = qi[keep], pi[keep]
    rot = batch.normals[:, ::stride].ravel()[qi] * np.conj(ref.normals[pi])
    rot = rot / np.maximum(np.abs(rot), 1e-300)
    rot = np.concatenate([rot, -rot])  # the drawing direction may differ: both normal senses
    qi = np.concatenate([qi, qi])
    pi = np.concatenate([pi, pi])
    t = q.ravel()[qi] - rot * ref.points[pi]
    inside = (np.abs(t.real) < _T_RANGE) & (np.abs(t.imag) < _T_RANGE)
    return qi[inside] // s, rot[inside], t[inside]


def _vote_grid(cand, rot, t, b):
    """Bin the votes and return bin indices and the smoothed ``(b, A, T, T)`` counts."""
    ab = np.floor((np.angle(rot) % (2 * np.pi)) / (2 * np.pi) * _ANGLE_BINS).astype(np.int64) % _ANGLE_BINS
    scale = _T_BINS / (2 * _T_RANGE)
    xb = np.clip(((t.real + _T_RANGE) * scale).astype(np.int64), 0, _T_BINS - 1)
    yb = np.clip(((t.imag + _T_RANGE) * scale).astype(np.int64), 0, _T_BINS - 1)
    flat = ((cand * _ANGLE_BINS + ab) * _T_BINS + xb) * _T_BINS + yb
    grid = np.bincount(flat, minlength=b * _ANGLE_BINS * _T_BINS * _T_BINS).astype(np.float32)
    grid = grid.reshape(b, _ANGLE_BINS, _T_BINS, _T_BINS)
    # imported here: drawings of exact copies never vote, and the import took 46 ms of every run
    from scipy.ndimage import uniform_filter1d

    grid = uniform_filter1d(grid, 3, axis=1, mode="wrap")
    grid = uniform_filter1d(grid, 3, axis=2, mode="constant")
    grid = uniform_filter1d(grid, 3, axis=3, mode="constant")
    return (ab, xb, yb), grid


class VoteSpace:
    """The smoothed vote grids of a batch, from which successive distinct peaks are taken."""

    def __init__(self, ref: Reference, batch: Batch):
        b = batch.points.shape[0]
        self.cand, self.rot, self.t = _votes(ref, batch, _VOTE_STRIDE)
        self.bins, self.grid = _vote_grid(self.cand, self.rot, self.t, b)
        self.excluded = np.zeros((b, _ANGLE_BINS), bool)
        self.first = np.zeros(b, np.float32)

    def peak(self, rows: np.ndarray):
        """Return rotation, translation and validity of the best untried peak of ``rows``.

        The peak's angle bin and its neighbours are then excluded from later peaks; a
        peak weaker than a fifth of the first one is not valid.
        """
        b = rows.size
        g = np.where(self.excluded[rows, :, None, None], -1.0, self.grid[rows]).reshape(b, -1)
        best = np.argmax(g, axis=1)
        val = g[np.arange(b), best]
        if not self.first.any():
            self.first[rows] = val
        valid = (val > 0) & (val >= 0.2 * self.first[rows])
        pa, rem = np.divmod(best, _T_BINS * _T_BINS)
        px, py = np.divmod(rem, _T_BINS)
        for k in (-2, -1, 0, 1, 2):
            self.excluded[rows, (pa + k) % _ANGLE_BINS] = True
        local = np.full(self.excluded.shape[0], -1)
        local[rows] = np.arange(b)
        sel = local[self.cand] >= 0
        cand, rot, t = local[self.cand[sel]], self.rot[sel], self.t[sel]
        ab, xb, yb = (x[sel] for x in self.bins)
        da = (ab - pa[cand] + _ANGLE_BINS // 2) % _ANGLE_BINS - _ANGLE_BINS // 2
        near = (np.abs(da) <= 1) & (np.abs(xb - px[cand]) <= 1) & (np.abs(yb - py[cand]) <= 1)
        cn = cand[near]
        rsum = np.bincount(cn, rot[near].real, b) + 1j * np.bincount(cn, rot[near].imag, b)
        tsum = np.bincount(cn, t[near].real, b) + 1j * np.bincount(cn, t[near].imag, b)
        cnt = np.bincount(cn, minlength=b)
        rot0 = np.where(np.abs(rsum) > 0, rsum / np.maximum(np.abs(rsum), 1e-300), 1.0)
        t0 = np.where(cnt > 0, tsum / np.maximum(cnt, 1), 0.0)
        return rot0, t0, valid
