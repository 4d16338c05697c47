"""Per-instance jitter of a derived drawing (``randomize … jitter instance``).

The cumulative jitter perturbs the turtle moves while deriving (see :mod:`.derivation`); the
per-instance jitter moves every instance drawn by a rule on its own, after the derivation, so
the next instance of a sequence is placed as without noise and a row stays a row.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from lsys_core.derive.model import Drawing
from lsys_core.geometry.transforms import DEG
from lsys_core.grammar.model import Randomize

__all__ = ["jitter_instances"]


def jitter_instances(drawing: Drawing, rnd: Randomize) -> Drawing:
    """Perturb every instance drawn by a rule on its own (``jitter="instance"``, see ``Randomize``)."""
    sel = np.flatnonzero(drawing.rule >= 0)
    if sel.size == 0:
        return drawing
    rng = np.random.default_rng(rnd.seed)
    a, b = drawing.a.copy(), drawing.b.copy()
    n = sel.size
    turn = np.exp(1j * DEG * rng.uniform(-rnd.angle, rnd.angle, n)) if rnd.angle else 1.0
    grow = 1.0 + rng.uniform(-rnd.scale, rnd.scale, n) if rnd.scale else 1.0
    if rnd.distance:
        gap = _nearest_gap(b)[sel]
        heading = a[sel] / np.where(np.abs(a[sel]) > 0, np.abs(a[sel]), 1.0)
        offset = rng.uniform(-1.0, 1.0, n) + 1j * rng.uniform(-1.0, 1.0, n)
        b[sel] = b[sel] + rnd.distance * gap * heading * offset
    a[sel] = a[sel] * turn * grow
    return replace(drawing, a=a, b=b)


def _nearest_gap(points: np.ndarray) -> np.ndarray:
    """Return each point's distance to its nearest other point (0 when it is alone)."""
    if points.size < 2:
        return np.zeros(points.size)
    from scipy.spatial import cKDTree

    xy = np.column_stack([points.real, points.imag])
    dist, _ = cKDTree(xy).query(xy, k=2)
    gap = dist[:, 1]
    return np.where(np.isfinite(gap), gap, 0.0)
