"""Groups whose shapes draw each other's instances within the tolerance become one group.

The similarity φ of §4.1 counts the samples of two outlines that lie close *relative to the
shapes' size*: two small windows drawn by hand, 4.65 and 5.05 wide, do not pass at the
threshold 0.6, although either drawn in the other's place moves no outline by more than a
fifth of a unit — well within a tolerance of a few tenths of a percent of a 170-unit
drawing.  The tolerance is a length in document units, and for near-identical shapes it is
the better judge: here terminals with close outline descriptors are aligned by their
centroids, sizes and principal axes (no mirror images), and a group joins another when the
other's terminal, so posed, draws every one of its instances within the tolerance (measured,
not estimated).  The medoid
step that follows picks the group's best representative.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy.spatial import cKDTree

from lsys_core.instancing.deviation import pose_deviations
from lsys_core.instancing.model import Instancing, terminal_shapes
from lsys_core.instancing.sampling import arc_fractions, sample_elements
from lsys_core.svg.model import Element, Scene

__all__ = ["MERGE_RELATIVE", "MERGE_SHARE", "SAME_SIZE", "merge_within", "without_groups"]

#: Share of the tolerance a merged instance may deviate from its new terminal (the rest is left
#: to the rules' placements).
MERGE_SHARE = 0.5
#: Largest deviation of a merged instance relative to its drawn RMS radius: near-identical
#: shapes, not shapes that only a tolerance large against their size cannot tell apart.
MERGE_RELATIVE = 0.1
#: Largest relative difference in size (RMS radius as drawn) between a merged instance and its host's.
SAME_SIZE = 0.15
#: Samples per outline for the alignment frames.
_SAMPLES = 96
#: Largest difference of descriptors (anisotropy; length over radius, scaled) between shapes tried.
_NEAR = 0.15
_LENGTH_SCALE = 10.0


def _frames(shapes: list[Element]) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Centroid, RMS radius, principal axis (unit complex) and descriptors of every shape's outline.

    The descriptors are the outline's anisotropy (ratio of its second moments) and its
    length over its RMS radius: near-identical shapes have nearly equal ones.
    """
    smp = sample_elements(shapes, arc_fractions(_SAMPLES))
    c = smp.points.mean(axis=1)
    z = smp.points - c[:, None]
    r = np.sqrt(np.mean(np.abs(z) ** 2, axis=1))
    m2 = np.mean(z**2, axis=1)  # second moment: its angle is twice the principal axis
    axis = np.exp(0.5j * np.angle(m2))
    aniso = np.abs(m2) / np.maximum(r**2, 1e-300)
    desc = np.column_stack([aniso, smp.length / np.maximum(r, 1e-300) / _LENGTH_SCALE])
    return c, r, axis, desc


def merge_within(scene: Scene, inst: Instancing, tolerance: float) -> Instancing:
    """Return ``inst`` with groups merged whose instances another group's terminal draws within ``tolerance``.

    Terminals are aligned by their outlines' centroids, RMS radii and principal axes (each
    of the four quarter turns tried, no mirror images), proposed only when their
    descriptors are close (:func:`_frames`); a group joins the larger one whose terminal,
    so aligned, draws every one of its instances within the tolerance.

    Parameters
    ----------
    scene : Scene
        The input elements.
    inst : Instancing
        Groups and poses, deviations filled in (:func:`~lsys_core.instancing.fidelity.split_unfaithful`).
    tolerance : float
        The tolerance (document units); 0 merges nothing.

    Returns
    -------
    Instancing
        With fewer groups where shapes agree within the tolerance; deviations measured at the
        new poses.
    """
    if inst.deviation is None or tolerance <= 0.0 or len(inst.terminals) < 2:
        return inst
    shapes = terminal_shapes(inst)
    drawable = np.array([g for g, s in enumerate(shapes) if s.cubics.size], int)
    if drawable.size < 2:
        return inst
    c, r, axis, desc = _frames([shapes[g] for g in drawable])
    group, a, b, dev = inst.group.copy(), inst.a.copy(), inst.b.copy(), inst.deviation.copy()
    counts = np.bincount(group, minlength=len(shapes))[drawable]
    order = np.argsort(-counts, kind="stable")  # larger groups host smaller ones
    pairs = cKDTree(desc).query_pairs(_NEAR, p=np.inf, output_type="ndarray")
    near: dict[int, list[int]] = {}
    for i, j in pairs.tolist():
        near.setdefault(i, []).append(j)
        near.setdefault(j, []).append(i)
    rank = np.empty_like(order)
    rank[order] = np.arange(order.size)
    gone: set[int] = set()
    for host in order.tolist():
        g = int(drawable[host])
        if g in gone:
            continue
        for i in sorted(near.get(host, []), key=lambda k: rank[k]):
            h = int(drawable[i])
            if h in gone or rank[i] < rank[host] or g in (inst.mirrored_of[h], h) or inst.mirrored_of[g] == h:
                continue  # a mirror image is kept as one (the flips of §5.4)
            members = np.flatnonzero(group == h)
            own = float(np.median(np.abs(a[group == g]))) * r[host]
            size = np.abs(a[members]) * r[i]
            if not (own > 0.0 and r[i] > 0.0) or np.abs(size / own - 1.0).max() > SAME_SIZE:
                continue  # copies are drawn at one size; a shape like another at another size is not its copy
            pose = _aligned(scene, shapes[g], members, a, b, (c, r, axis), host, i, MERGE_SHARE * tolerance)
            if pose is None:
                continue
            members, pa, pb, d = pose
            group[members], a[members], b[members], dev[members] = g, pa, pb, d
            gone.add(h)
    if not gone:
        return inst
    return without_groups(replace(inst, group=group, a=a, b=b, deviation=dev), sorted(gone))


def _aligned(
    scene: Scene, shape: Element, members: np.ndarray, a, b, frames, host: int, i: int, tolerance: float
):
    """Poses of ``shape`` over the elements ``members`` (terminal ``i``'s instances), if all within ``tolerance``.

    Returns ``(members, a, b, deviations)`` for the quarter turn of the principal axes that
    fits best, or None.
    """
    c, r, axis = frames
    elements = [scene.elements[int(j)] for j in members]
    best = None
    for quarter in (1, 1j, -1, -1j):
        rel_a = r[i] / r[host] * axis[i] / axis[host] * quarter
        rel_b = c[i] - rel_a * c[host]
        pa, pb = a[members] * rel_a, a[members] * rel_b + b[members]
        d = pose_deviations(elements, [shape], np.zeros(members.size, int), pa, pb)
        if (
            (d <= MERGE_RELATIVE * np.abs(pa) * r[host]).all()
            and d.max() <= tolerance
            and (best is None or d.max() < best[3].max())
        ):
            best = (members, pa, pb, d)
    return best


def without_groups(inst: Instancing, gone: list[int]) -> Instancing:
    """``inst`` without the (now empty) groups ``gone``: terminals renumbered and renamed, mirror links kept."""
    from lsys_core.instancing.similarity import terminal_name

    k = len(inst.terminals)
    keep = np.setdiff1d(np.arange(k), gone)
    new = np.full(k, -1)
    new[keep] = np.arange(keep.size)
    mirrored = np.where(inst.mirrored_of[keep] >= 0, new[np.maximum(inst.mirrored_of[keep], 0)], -1)
    terminals = tuple(
        replace(inst.terminals[g], name=terminal_name(i), mirror_of=terminal_name(m) if m >= 0 else None)
        for i, (g, m) in enumerate(zip(keep.tolist(), mirrored.tolist(), strict=True))
    )
    return replace(
        inst,
        group=new[inst.group],
        terminals=terminals,
        symmetry=inst.symmetry[keep],
        mirrored_of=mirrored,
    )
