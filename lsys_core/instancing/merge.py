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

Distinct shapes (a map, a chart of varied glyphs) have many pairs of close descriptors
(335,000 among 2,000 random polygons), and each pair's alignment was tried in Python: a
quarter turn's lower bound :func:`_apart` took about 0.2 ms.  A coarser lower bound of it,
:func:`_apart_bounds`, is computed for all pairs at once first (a distance field of every
host's samples on a grid, looked up at the other shape's samples; Lipschitz, so never above
:func:`_apart`), and only pairs with a quarter turn that it cannot rule out are tried: the
merges are the same, and the tries grow with the pairs that could merge.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.spatial import cKDTree

from lsys_core.instancing.deviation import pose_deviations
from lsys_core.instancing.model import Instancing, terminal_shapes
from lsys_core.instancing.sampling import arc_fractions, sample_elements
from lsys_core.svg.model import Element, Scene

__all__ = ["MERGE_RELATIVE", "MERGE_SHARE", "SAME_SIZE", "UNTOLD", "merge_within", "without_groups"]

#: Share of the tolerance a merged instance may deviate from its new terminal (the rest is left
#: to the rules' placements).
MERGE_SHARE = 0.5
#: Largest deviation of a merged instance relative to its drawn RMS radius: near-identical
#: shapes, not shapes that only a tolerance large against their size cannot tell apart.
MERGE_RELATIVE = 0.1
#: Largest relative difference in size (RMS radius as drawn) between a merged instance and its host's.
SAME_SIZE = 0.15
#: Share of the tolerance by which two readings of one drawing (turned or mirrored) must differ
#: to be told apart: a copy that fits its other reading as well within it is taken either way.
UNTOLD = 0.1
#: Samples per outline for the alignment frames.
_SAMPLES = 96
#: Largest difference of descriptors (anisotropy; length over radius, scaled) between shapes tried.
_NEAR = 0.15
_LENGTH_SCALE = 10.0
#: Margin of :func:`_apart` (radius 1) for the deviations being measured on flattened outlines.
_SLACK = 0.02
#: Cells per side of the distance fields of :func:`_apart_bounds`, and pairs bounded per block.
_GRID = 64
_BLOCK = 8192
#: Every this many samples give the first, cheaper bound of :func:`_hopeless`.
_COARSE_STRIDE = 8
_QUARTERS = (1, 1j, -1, -1j)


@dataclass(frozen=True)
class _Frames:
    """Outline frames of the terminal shapes (see :func:`_frames`)."""

    centre: np.ndarray  # (n,) complex: centroid of the outline samples
    radius: np.ndarray  # (n,) RMS radius
    axis: np.ndarray  # (n,) unit complex: principal axis
    desc: np.ndarray  # (n, 2): anisotropy, length over radius (scaled)
    unit: np.ndarray  # (n, s) complex: samples in the shape's own frame (centre 0, radius 1, axis 1)
    gap: np.ndarray  # (n,) half the spacing of the samples in that frame; inf: several subpaths


def _frames(shapes: list[Element]) -> _Frames:
    """Centroid, RMS radius, principal axis, descriptors and normalised samples of every outline.

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
    unit = z / (np.maximum(r, 1e-300) * axis)[:, None]
    single = np.array([np.unique(np.asarray(e.subpaths)).size <= 1 for e in shapes])
    # A subpath shorter than the spacing may have no sample: then no bound from the samples.
    gap = np.where(single, smp.length / _SAMPLES / 2 / np.maximum(r, 1e-300), np.inf)
    return _Frames(c, r, axis, desc, unit, gap)


def _apart(frames: _Frames, host: int, i: int, quarter: complex) -> float:
    """A lower bound of how far shape ``i``'s outline lies from ``host``'s turned by ``quarter``.

    In shape ``i``'s own frame (radius 1): every sample of ``i`` lies on its outline, and every
    point of the host's outline within half a sample spacing of one of the host's samples, so
    the farthest sample of ``i`` from the host's samples, less that half spacing, is at most the
    true deviation (less :data:`_SLACK`, for the measured deviations being taken on flattened
    outlines).  It needs a few thousand distances; measuring a try took 5 ms.
    """
    if not np.isfinite(frames.gap[host]):
        return 0.0
    d = np.abs(frames.unit[i][:, None] - quarter * frames.unit[host][None, :]).min(axis=1)
    return float(d.max()) - float(frames.gap[host]) - _SLACK


@dataclass(frozen=True)
class _Fields:
    """Distance fields of sample sets on one grid (see :func:`_apart_bounds`)."""

    field: np.ndarray  # (n, G * G) float32: each cell centre's distance to an occupied cell
    reach: float  # the grid spans [-reach, reach] on both axes
    step: float  # cell size

    @classmethod
    def of(cls, frames: _Frames) -> _Fields:
        """The fields of all shapes of ``frames`` (one small transform per shape, not per pair)."""
        reach = float(np.abs(frames.unit).max()) * 1.001 + 1e-9 if frames.unit.size else 1.0
        out = cls(np.empty((frames.unit.shape[0], _GRID * _GRID), np.float32), reach, 2.0 * reach / _GRID)
        # imported here: only scenes with several near-identical terminals get here, and importing
        # scipy.ndimage took about 50 ms of every run
        from scipy.ndimage import distance_transform_edt

        for k, z in enumerate(frames.unit):
            grid = np.ones((_GRID, _GRID), bool)
            grid[out.cell(z)] = False
            out.field[k] = distance_transform_edt(grid, sampling=out.step).ravel()
        return out

    def cell(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Column and row of the cells of points ``z`` (clipped to the grid)."""
        ix = np.clip(np.floor((z.real + self.reach) / self.step).astype(np.int64), 0, _GRID - 1)
        iy = np.clip(np.floor((z.imag + self.reach) / self.step).astype(np.int64), 0, _GRID - 1)
        return ix, iy


def _upright(frames: _Frames, host, i):
    """The turn of the unit frames that aligns the terminals as drawn (not by their principal axes)."""
    return frames.axis[host] / frames.axis[i]


def _turns(frames: _Frames, host: int, i: int) -> list[complex]:
    """The turns of the unit frames tried: the quarter turns of the principal axes, and of the
    terminals as drawn.  The axes of a nearly square outline are ill-defined (a window drawn by
    hand: 6° off); the frames of two copies drawn upright are not.
    """
    upright = complex(_upright(frames, host, i))
    turns = list(_QUARTERS)
    if abs(upright - 1.0) > 1e-3:
        turns += [q * upright for q in _QUARTERS]
    return turns


def _apart_bounds(
    frames: _Frames,
    fields: _Fields,
    host: np.ndarray,
    other: np.ndarray,
    stride: int = 1,
    turn: np.ndarray | None = None,
) -> np.ndarray:
    """Lower bounds of :func:`_apart` for the pairs ``(host[k], other[k])`` and each quarter turn.

    Every unit-frame sample set is rasterised on one grid covering all samples; the Euclidean
    distance transform of a host's occupied cells, less half a cell diagonal (a sample lies
    anywhere in its cell), bounds from below the distance of a cell's centre to the host's
    samples, and less the distance to that centre it bounds the distance of any point of the
    cell (the distance is 1-Lipschitz).  The largest bound over the other shape's samples,
    less the host's half spacing and :data:`_SLACK`, is at most :func:`_apart`.  Taken over every
    ``stride``-th sample only, the bound is cheaper and weaker, and still a lower bound.
    ``turn`` (one unit complex per pair) turns every quarter turn further (the upright frames
    of :func:`_turns`).

    Returns
    -------
    ndarray of float, shape (p, 4)
        One bound per quarter turn of :data:`_QUARTERS`; ``-inf`` where :func:`_apart` gives no
        bound (a host of several subpaths).
    """
    out = np.full((host.size, len(_QUARTERS)), -np.inf)
    rows = np.flatnonzero(np.isfinite(frames.gap[host]))
    half = (np.arange(_GRID) + 0.5) * fields.step - fields.reach  # cell centres along an axis
    half_cell = fields.step * np.sqrt(0.5)
    for lo in range(0, rows.size, _BLOCK):
        sel = rows[lo : lo + _BLOCK]
        fk = host[sel, None]
        u = frames.unit[other[sel], ::stride]
        extra = 1.0 if turn is None else turn[sel, None]
        for j, q in enumerate(_QUARTERS):
            x = u * np.conj(q * extra)  # |u - q v| = |conj(q) u - v|
            ix, iy = fields.cell(x)
            near = fields.field[fk, ix * _GRID + iy].astype(float)
            off = np.abs(x - (half[ix] + 1j * half[iy]))
            out[sel, j] = (near - half_cell - off).max(axis=1)
    out[rows] -= (frames.gap[host[rows]] + _SLACK + 1e-5)[:, None]  # 1e-5: float32 field, rounding
    return out


def _hopeless(
    frames: _Frames,
    drawable: np.ndarray,
    inst: Instancing,
    pairs: np.ndarray,
    rank: np.ndarray,
    tolerance: float,
) -> np.ndarray:
    """Which pairs ``(host, i)`` no quarter turn can merge, by :func:`_apart_bounds`.

    :func:`_aligned` skips a quarter turn when ``apart * drawn - dev > limit`` for one of the
    members of ``i``'s group, that is when ``apart`` exceeds the smallest ``(limit + dev) /
    drawn`` over them: a bound above that rules the turn out.  Pairs are oriented host first
    (the lower rank).  The members of ``i``'s group keep their poses until it is tried.
    """
    host = np.where(rank[pairs[:, 0]] < rank[pairs[:, 1]], pairs[:, 0], pairs[:, 1])
    other = pairs[:, 0] + pairs[:, 1] - host
    slot = np.full(len(inst.terminals), -1)
    slot[drawable] = np.arange(drawable.size)
    member = slot[inst.group]
    inside = member >= 0
    drawn = np.abs(inst.a[inside]) * frames.radius[member[inside]]
    limit = np.minimum(MERGE_RELATIVE * drawn, MERGE_SHARE * tolerance)
    dev = inst.deviation if inst.deviation is not None else np.zeros(inst.group.size)
    with np.errstate(all="ignore"):
        ratio = (limit + dev[inside]) / drawn
    ratio = np.where((drawn > 0) & ~np.isnan(ratio), ratio, np.inf)
    thr = np.full(drawable.size, np.inf)
    np.minimum.at(thr, member[inside], ratio)
    t = thr[other][:, None]
    t = t + 1e-9 * (1.0 + np.abs(t))
    fields = _Fields.of(frames)
    upright = _upright(frames, host, other)
    out = np.ones(host.size, bool)
    for turn in (None, upright):  # the turns of _turns: the principal axes', then the upright frames'
        rest = np.flatnonzero(out)
        spin = None if turn is None else turn[rest]
        bound = _apart_bounds(frames, fields, host[rest], other[rest], _COARSE_STRIDE, spin)
        keep = ~(bound > t[rest]).all(axis=1)  # most pairs end at the coarse bound
        rest, spin = rest[keep], None if spin is None else spin[keep]
        out[rest] = (_apart_bounds(frames, fields, host[rest], other[rest], 1, spin) > t[rest]).all(axis=1)
    return out


def merge_within(scene: Scene, inst: Instancing, tolerance: float) -> Instancing:
    """Return ``inst`` with groups merged whose instances another group's terminal draws within ``tolerance``.

    Terminals are aligned by their outlines' centroids, RMS radii and principal axes (each
    of the four quarter turns tried, and the terminals' own frames; never flipped: a group of
    mirror images joins only when its shape is symmetric within the tolerance), proposed only when their
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
    frames = _frames([shapes[g] for g in drawable])
    r = frames.radius
    group, a, b, dev = inst.group.copy(), inst.a.copy(), inst.b.copy(), inst.deviation.copy()
    counts = np.bincount(group, minlength=len(shapes))[drawable]
    order = np.argsort(-counts, kind="stable")  # larger groups host smaller ones
    # Copies are drawn at one size (SAME_SIZE): the median drawn sizes of two groups that can
    # merge differ by at most that much, so their logarithms are a third coordinate of the
    # search (without it, 80 random polygons tried 488 pairs, 2,000 nearly all 2 million).
    sizes = np.array([float(np.median(np.abs(inst.a[inst.group == g]))) for g in drawable.tolist()]) * r
    log_size = np.log(np.maximum(sizes, 1e-300)) * (_NEAR / -np.log1p(-SAME_SIZE))
    pairs = cKDTree(np.column_stack([frames.desc, log_size])).query_pairs(
        _NEAR, p=np.inf, output_type="ndarray"
    )
    rank = np.empty_like(order)
    rank[order] = np.arange(order.size)
    if pairs.size:
        pairs = pairs[~_hopeless(frames, drawable, inst, pairs, rank, tolerance)]
    near: dict[int, list[int]] = {}
    for i, j in pairs.tolist():
        near.setdefault(i, []).append(j)
        near.setdefault(j, []).append(i)
    gone: set[int] = set()
    for host in order.tolist():
        g = int(drawable[host])
        if g in gone:
            continue
        own = float(sizes[host])  # the host's size as drawn (its members have not moved yet)
        for i in sorted(near.get(host, []), key=lambda k: rank[k]):
            h = int(drawable[i])
            if h in gone or rank[i] < rank[host] or g == h:
                continue
            # A mirror image (the flips of §5.4) is tried as well, turned but not flipped, and
            # joins only when its drawing does not tell the two readings apart (UNTOLD): a
            # window drawn by hand, not the exact mirror image of a nearly symmetric leaf.
            flipped = g == inst.mirrored_of[h] or inst.mirrored_of[g] == h
            members = np.flatnonzero(group == h)
            size = np.abs(a[members]) * r[i]
            if not (own > 0.0 and r[i] > 0.0) or np.abs(size / own - 1.0).max() > SAME_SIZE:
                continue  # copies are drawn at one size; a shape like another at another size is not its copy
            pose = _aligned(
                scene,
                shapes[g],
                members,
                (a, b, dev),
                frames,
                (host, i),
                MERGE_SHARE * tolerance,
                UNTOLD * tolerance if flipped else np.inf,
            )
            if pose is None:
                continue
            members, pa, pb, d = pose
            group[members], a[members], b[members], dev[members] = g, pa, pb, d
            gone.add(h)
            own = float(np.median(np.abs(a[group == g]))) * r[host]
    if not gone:
        return inst
    return without_groups(replace(inst, group=group, a=a, b=b, deviation=dev), sorted(gone))


def _aligned(
    scene: Scene,
    shape: Element,
    members: np.ndarray,
    poses: tuple[np.ndarray, np.ndarray, np.ndarray],
    frames: _Frames,
    pair: tuple[int, int],
    tolerance: float,
    untold: float = np.inf,
):
    """Poses of ``shape`` over the elements ``members`` (terminal ``i``'s instances), if all within ``tolerance``.

    ``poses`` are every element's pose and deviation ``(a, b, dev)``; ``pair`` is ``(host, i)``,
    the frames of the host's terminal and of the members'.  Returns ``(members, a, b,
    deviations)`` for the quarter turn of the principal axes (or of the terminals' own frames)
    that fits best, or None.  A member may deviate by at most ``untold`` more than it did
    from its own terminal (a mirror image joins only when its drawing cannot tell).  A quarter
    turn whose lower bound (:func:`_apart`, less each member's own deviation from terminal
    ``i``) already exceeds a member's limit is not measured.
    """
    a, b, dev = poses
    host, i = pair
    c, r, axis = frames.centre, frames.radius, frames.axis
    elements = [scene.elements[int(j)] for j in members]
    drawn = np.abs(a[members]) * r[i]  # each member's radius as drawn
    limit = np.minimum(np.minimum(MERGE_RELATIVE * drawn, tolerance), dev[members] + untold)
    best = None
    for quarter in _turns(frames, host, i):
        if (_apart(frames, host, i, quarter) * drawn - dev[members] > limit).any():
            continue
        rel_a = r[i] / r[host] * axis[i] / axis[host] * quarter
        rel_b = c[i] - rel_a * c[host]
        pa, pb = a[members] * rel_a, a[members] * rel_b + b[members]
        d = pose_deviations(elements, [shape], np.zeros(members.size, int), pa, pb)
        if (
            (d <= MERGE_RELATIVE * np.abs(pa) * r[host]).all()
            and d.max() <= tolerance
            and (d <= dev[members] + untold).all()
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
