"""Copies of a nearly symmetric shape turned the way their neighbours are.

A window drawn by hand is a rectangle that is not quite symmetric: the similarity stage (§4.1)
matches a copy turned by 180° about as well as one turned by 0°, and keeps whichever fits its
jitter better.  In a row of three windows the middle one may then be "turned" by 180°: the
step between neighbours is no longer one transform and no rule finds the row.  For shapes
that are exactly symmetric, :func:`~lsys_core.instancing.orientation.unwrap_symmetric`
chooses among the equivalent turns; here the same is done for shapes symmetric only within
the tolerance.  A group's shape turned by a half (or a quarter) turn about its centre must
draw itself within :data:`~lsys_core.instancing.merge.MERGE_SHARE` of the tolerance; then
every instance takes, among its equivalent poses, the one whose turn is closest to its
neighbours' (along a minimum spanning tree), and keeps it when its measured deviation stays
within the same share and grows by at most :data:`~lsys_core.instancing.merge.UNTOLD` of
the tolerance (its drawing does not tell the two turns apart: exact copies of a nearly
symmetric leaf keep theirs).  The terminal stays asymmetric: the deviations are measured at
the poses kept, and no rotation is ever taken as free.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from lsys_core.instancing.deviation import pose_deviations
from lsys_core.instancing.merge import MERGE_SHARE, UNTOLD
from lsys_core.instancing.model import Instancing, terminal_shapes
from lsys_core.instancing.orientation import unwrap_turns
from lsys_core.instancing.sampling import arc_fractions, sample_elements
from lsys_core.svg.model import Element, Scene

__all__ = ["turn_near_symmetric"]

#: Samples of an outline for its centre.
_SAMPLES = 64


def _self_turn(shape: Element, scale: float, limit: float) -> tuple[float, complex] | None:
    """The smallest period (radians) under which ``shape`` drawn at ``scale`` matches itself within ``limit``.

    Returns the period (``π/2`` or ``π``) and the shape's centre (local frame), or None.
    """
    centre = complex(sample_elements([shape], arc_fractions(_SAMPLES)).points.mean())
    for period in (np.pi / 2, np.pi):
        q = complex(np.exp(1j * period))
        a = np.array([scale * q])
        b = np.array([scale * (1.0 - q) * centre])
        d = pose_deviations([replace(shape, cubics=scale * shape.cubics)], [shape], np.zeros(1, int), a, b)
        if float(d[0]) <= limit:
            return period, centre
    return None


def turn_near_symmetric(scene: Scene, inst: Instancing, tolerance: float) -> Instancing:
    """Return ``inst`` with instances of nearly symmetric shapes turned like their neighbours (module doc).

    Parameters
    ----------
    scene : Scene
        The input elements.
    inst : Instancing
        Groups, poses and deviations.
    tolerance : float
        The tolerance (document units); 0 changes nothing.
    """
    if inst.deviation is None or tolerance <= 0.0:
        return inst
    limit = MERGE_SHARE * tolerance
    shapes = terminal_shapes(inst)
    a, b, dev = inst.a.copy(), inst.b.copy(), inst.deviation.copy()
    changed = False
    for g, order in enumerate(np.asarray(inst.symmetry).tolist()):
        sel = np.flatnonzero(inst.group == g)
        if order != 1 or sel.size < 2 or not shapes[g].cubics.size:
            continue
        found = _self_turn(shapes[g], float(np.abs(a[sel]).max()), limit)
        if found is None:
            continue
        period, centre = found
        theta = np.angle(a[sel])
        q = np.exp(1j * (unwrap_turns(a[sel], b[sel], period) - theta))
        moved = np.flatnonzero(np.abs(q - 1.0) > 1e-6)
        if moved.size == 0:
            continue
        idx = sel[moved]
        pa = a[idx] * q[moved]
        pb = b[idx] + a[idx] * (1.0 - q[moved]) * centre
        d = pose_deviations(
            [scene.elements[int(i)] for i in idx], [shapes[g]], np.zeros(idx.size, int), pa, pb
        )
        ok = d <= np.minimum(limit, dev[idx] + UNTOLD * tolerance)
        a[idx[ok]], b[idx[ok]], dev[idx[ok]] = pa[ok], pb[ok], d[ok]
        changed = changed or bool(ok.any())
    return replace(inst, a=a, b=b, deviation=dev) if changed else inst
