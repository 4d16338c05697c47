"""Mean-shift clustering with a flat kernel, vectorised with a KD-tree.

scikit-learn's ``MeanShift`` needs tens of seconds for 10⁴ points; here the points are
first binned into cells of half a bandwidth (bin seeding: one seed per occupied cell,
weighted by its count), the seeds climb to their modes with ball queries on the
*weighted cell centroids* (few, so each iteration is cheap), modes closer than half a
bandwidth are merged, and every point is labelled with its nearest mode.  Coordinates
are expected pre-scaled so that the bandwidth is 1 in every dimension.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from lsys_core import parallel
from lsys_core.hierarchy.flat import Groups
from lsys_core.sorting import sorted_unique, stable_argsort

__all__ = ["RANK", "group_indices", "mean_shift", "rank_order", "ranked_mean_shift", "spread"]

#: Up to this many points, the labels come from one KD-tree query (cheaper than per-cell reasoning).
_DIRECT = 20_000
#: Points per occupied cell below which the labels come from one KD-tree query whatever their
#: number: per-cell reasoning pays where cells hold many points (the pairs of a grid: 10^3 to
#: 10^4 a cell), not where nearly every point has a cell of its own (120,356 pairs of a wind
#: chart in 84,106 cells: 1.07 s per cell, 0.29 s by one query, the same labels).
_PER_CELL = 4
#: Points binned at once.
_BLOCK = 1 << 18
#: Neighbours asked of the KD-tree per seed before falling back to a ball query.
_NEAR = 8
#: Queries of at least this many seeds run on every core: scipy starts and joins its threads
#: at every call, and a drawing of 4,817 elements makes 5,282 mostly small calls (48 s in
#: thread joins when every call was threaded).
_THREADED = 20_000
#: Seeds with more than :data:`_NEAR` neighbours from which their ball queries are split among
#: the workers (``sparse_distance_matrix`` runs on one core): the 42,468 of a wind chart's
#: 84,106 cells took 0.29 s on one core, 0.16 s in two halves on two.
_THREADED_FULL = 4_096
#: From this many seeds, seeds at the same place (bit for bit) are queried once: see :func:`_distinct_rows`.
_DISTINCT = 4_096
#: Seeds a part of a mean shift's climb (:func:`_climb`) holds at least: see :func:`_climb_parts`.
_CLIMB_PART = 8_192
#: The fields of :func:`ranked_mean_shift`'s cluster keys.
RANK = np.dtype([("size", np.int64), ("support", np.float64), ("seed", np.int64)])


def _row_keys(cells: np.ndarray) -> np.ndarray:
    """Hash integer rows to int64 keys (sorting 1-D keys is much faster than ``unique(axis=0)``).

    Two large odd multipliers per column make a collision between distinct occupied cells
    astronomically unlikely (~n²/2⁶⁴); a collision would only merge two seeds' cells.
    """
    mult = np.array(
        [
            0x9E3779B97F4A7C15,
            0xC2B2AE3D27D4EB4F,
            0x165667B19E3779F9,
            0xD6E8FEB86659FD93,
            0xFF51AFD7ED558CCD,
            0xC4CEB9FE1A85EC53,
            0x2545F4914F6CDD1D,
            0x9FB21C651E98DF25,
        ],
        dtype=np.uint64,
    )
    k = cells.shape[1]
    reps = -(-k // mult.size)
    m = np.tile(mult, reps)[:k]
    with np.errstate(over="ignore"):
        h = (cells.astype(np.uint64) * m).sum(axis=1, dtype=np.uint64)
        h ^= h >> np.uint64(29)
    return h.view(np.int64)


def _ball_pairs(
    query: np.ndarray, tree: cKDTree, r: float = 1.0, crowded: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Return ``(i, j)`` for every point ``j`` of ``tree`` within ``r`` of ``query[i]`` (vectorised).

    The :data:`_NEAR` nearest points of every query come from one ``query`` call (on
    :func:`lsys_core.parallel.jobs` threads from :data:`_THREADED` queries up); only queries
    whose :data:`_NEAR` nearest are all within ``r`` may have more, and only those go through
    ``sparse_distance_matrix``.  Most seeds of a pair space are nearly isolated: for 10^5 of
    them the query takes 0.20 s of CPU where ``sparse_distance_matrix`` took 0.25 s, and a
    large query runs on every core (so do the ball queries of many seeds, in parts).
    Queries flagged ``crowded`` (they had that many neighbours at their last place) skip the
    nearest-points query and go straight to the ball query: the same pairs, one query fewer.
    Each query's points come in increasing order of ``j``.
    """
    k = min(_NEAR, tree.n)
    near = np.arange(len(query)) if crowded is None else np.flatnonzero(~crowded)
    workers = parallel.jobs() if len(near) >= _THREADED else 1  # threads cost ~1 ms per call
    dist, idx = tree.query(query[near], k=k, distance_upper_bound=r * (1 + 1e-9), workers=workers)
    dist, idx = dist.reshape(len(near), k), idx.reshape(len(near), k)
    inside = dist <= r
    full = np.flatnonzero(inside[:, -1]) if k < tree.n else np.zeros(0, np.intp)
    inside[full] = False
    # Every query's points in increasing order, whatever the tree: sums over them are then
    # the same bit for bit when the points are those of a part of the tree (ranked_mean_shift).
    idx = np.where(inside, idx, tree.n)
    idx.sort(axis=1)
    i, col = np.nonzero(idx < tree.n)
    j = idx[i, col]
    i = near[i]
    full = near[full] if crowded is None else np.union1d(near[full], np.flatnonzero(crowded))
    if full.size:
        parts = np.array_split(full, parallel.jobs()) if full.size >= _THREADED_FULL else [full]
        found = parallel.pmap(lambda part: _ball(query[part], tree, r, part), parts)
        # sorted by (query, point) as one key: a tenth of the time of a lexsort of the two
        key = np.concatenate([f[0].astype(np.int64) * tree.n + f[1] for f in found])
        key.sort()
        fi, fj = np.divmod(key, tree.n)
        i = np.concatenate([i, fi])
        j = np.concatenate([j, fj])
    return i.astype(np.intp), j.astype(np.intp)


def _ball(query: np.ndarray, tree: cKDTree, r: float, index: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(index[i], j)`` for every point ``j`` of ``tree`` within ``r`` of ``query[i]``, unordered."""
    pairs = cKDTree(query).sparse_distance_matrix(tree, r, output_type="ndarray")
    return index[pairs["i"]], pairs["j"]


def _suppress(seeds: np.ndarray, order: np.ndarray) -> np.ndarray:
    """Greedy suppression, strongest first: a seed within half a bandwidth of a kept mode merges into it.

    Returns the kept seeds of ``order``, in its order.  A seed with no other seed that near is
    kept without looking further; only the others go through the loop (with nearly isolated
    points, 10^5 seeds went one by one through ``query_ball_point`` lists; mean shift of 10^5
    isolated 4-D points took 1.83 s of CPU, now 0.65 s).

    Seeds at one place (bit for bit) are one: the first of them in ``order`` is kept or
    suppressed as the place is, the others are suppressed by it or with it.  So are seeds
    outside ``order``: they suppress nothing.  Only the leading seed of every place is
    examined: 42,653 of the 84,106 seeds of a wind chart's pair space (3.0·10^6 pairs of
    seeds within half a bandwidth, most of them of equal seeds; 1.35 -> 0.11 s).
    """
    first, _ = _distinct_rows(seeds[order])
    if first.size == order.size:
        return _suppress_distinct(seeds, order)
    lead = order[np.sort(first)]  # the first seed of every place, in order
    return lead[_suppress_distinct(seeds[lead], np.arange(lead.size))]


def _suppress_distinct(seeds: np.ndarray, order: np.ndarray) -> np.ndarray:
    """:func:`_suppress` of seeds of ``order`` at places of their own."""
    pairs = cKDTree(seeds).query_pairs(r=0.5, output_type="ndarray")
    if pairs.size == 0:
        return order
    a = np.concatenate([pairs[:, 0], pairs[:, 1]])
    b = np.concatenate([pairs[:, 1], pairs[:, 0]])
    by = stable_argsort(a)
    a, b = a[by], b[by]
    lo = np.searchsorted(a, np.arange(len(seeds)))
    hi = np.searchsorted(a, np.arange(len(seeds)), side="right")
    kept = np.zeros(len(seeds), bool)
    kept[order] = lo[order] == hi[order]  # nobody near: nobody suppresses it, it suppresses nobody
    suppressed = np.zeros(len(seeds), bool)
    for i in order[lo[order] < hi[order]].tolist():
        if suppressed[i]:
            continue
        kept[i] = True
        suppressed[b[lo[i] : hi[i]]] = True
    return order[kept[order]]


def _support(
    seeds: np.ndarray,
    tree: cKDTree,
    w: np.ndarray,
    still_owner: list[np.ndarray],
    still_flat: list[np.ndarray],
) -> np.ndarray:
    """The weight of the cells within a bandwidth of every seed.

    A seed whose last step left it exactly where it was has the neighbours its last query
    found (``still_owner``, ``still_flat``); only the others are queried again.  The weights
    are cell counts, so the sums are exact in any order: the support is bit for bit that of
    one query of all seeds.  Isolated seeds stop at once: of 78,748 seeds of 3,000 copies at
    random places, 39,658 were not queried again (0.20 -> 0.10 s).
    """
    n = len(seeds)
    support = np.zeros(n)
    if still_owner:
        owner, flat = np.concatenate(still_owner), np.concatenate(still_flat)
        support += np.bincount(owner, weights=w[flat], minlength=n)
        done = np.zeros(n, bool)
        done[owner] = True
        rest = np.flatnonzero(~done)
    else:
        rest = np.arange(n)
    if rest.size:
        first, inv = _distinct_rows(seeds[rest])
        owner, flat = _ball_pairs(seeds[rest[first]], tree)
        support[rest] += np.bincount(owner, weights=w[flat], minlength=first.size)[inv]
    return support


def _distinct_rows(rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(first, inverse)``: one row of every set of rows equal bit for bit, and every row's.

    Seeds that climb a dense mode meet: two seeds with the same neighbours move to the same
    place, bit for bit, and from there on have the same neighbours and steps, so one query
    serves them all.  Of the 566,485 seed steps of a wind chart's 120,356 pairs, 31 % were
    at a place another seed of the step had too (mean shift 20.5 -> 19.3 s).  Below
    :data:`_DISTINCT` rows (the pivots' thousands of small calls), or should two different
    rows share a hash, every row is its own.
    """
    n = len(rows)
    if n < _DISTINCT:
        return np.arange(n), np.arange(n)
    bits = np.ascontiguousarray(rows).view(np.int64)
    h = _row_keys(bits)
    order = np.argsort(h, kind="stable")
    hs = h[order]
    head = np.empty(n, bool)
    head[0] = True
    np.not_equal(hs[1:], hs[:-1], out=head[1:])
    first = order[head]
    inverse = np.empty(n, np.intp)
    inverse[order] = np.cumsum(head) - 1
    if first.size == n or not np.array_equal(bits[first[inverse]], bits):
        return np.arange(n), np.arange(n)
    return first, inverse


def _nearest_mode(pts: np.ndarray, modes: np.ndarray, cent: np.ndarray, inv: np.ndarray) -> np.ndarray:
    """The nearest of ``modes`` within a bandwidth of every point (-1: none), decided per cell.

    Every point of cell ``c`` lies within ``R_c`` (measured) of its centroid, so only modes within
    ``1 + R_c`` of the centroid can be within a bandwidth of it.  A cell with one such mode labels
    its points by their distance to that mode alone, a cell with none labels them -1; only the
    points of the other cells go through the KD-tree.  The labels are those of one KD-tree query
    of all points: of the 5·10^6 consecutive pairs of a 50,000-leaf grid, none needed the tree
    (1.8 -> 0.3 s of CPU).  A cell within ``1 - R_c`` of its one mode needs no distance per point.
    Where cells hold fewer than :data:`_PER_CELL` points on average, one query of all points
    costs less than the reach of every cell and gives the same labels.
    """
    if len(pts) <= _DIRECT or len(pts) < _PER_CELL * len(cent):
        dist, idx = cKDTree(modes).query(pts, k=1)
        return np.where(dist <= 1.0, idx, -1)
    reach = np.zeros(len(cent))
    for lo in range(0, len(pts), _BLOCK):  # in blocks: temporaries of the size of the points
        sl = slice(lo, lo + _BLOCK)
        np.maximum.at(reach, inv[sl], _dist(pts[sl], cent[inv[sl]]))
    tree = cKDTree(modes)
    near = tree.query_ball_point(cent, reach + (1.0 + 1e-9), return_sorted=False)
    only = np.fromiter((x[0] if len(x) == 1 else -len(x) for x in near), np.int64, len(near))
    # A cell whose points all lie well within a bandwidth of its one mode is labelled as a whole
    # (the margin dwarfs rounding: each point's own test would say the same).
    whole = np.full(len(cent), -1, np.int64)
    one = np.flatnonzero(only >= 0)
    all_in = one[_dist(cent[one], modes[only[one]]) + reach[one] <= 1.0 - 1e-9]
    whole[all_in] = only[all_in]
    only[all_in] = -1
    lab = np.empty(len(pts), np.int64)
    for lo in range(0, len(pts), _BLOCK):
        lab[lo : lo + _BLOCK] = whole[inv[lo : lo + _BLOCK]]
        m = only[inv[lo : lo + _BLOCK]]
        one = np.flatnonzero(m >= 0)
        inside = _dist(pts[lo + one], modes[m[one]]) <= 1.0
        lab[lo + one[inside]] = m[one[inside]]
        many = np.flatnonzero(m <= -2)
        if many.size:
            dist, idx = tree.query(pts[lo + many], k=1)
            lab[lo + many] = np.where(dist <= 1.0, idx, -1)
    return lab


def _dist(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Row-wise Euclidean distances."""
    d = p - q
    return np.sqrt(np.einsum("ij,ij->i", d, d))


def mean_shift(
    points: np.ndarray, *, max_iter: int = 30, min_count: int = 1
) -> tuple[np.ndarray, np.ndarray]:
    """Cluster ``points`` (already scaled to bandwidth 1) by mean shift.

    Parameters
    ----------
    points : ndarray, shape (n, k)
        Points in a space whose per-dimension bandwidths are 1.
    max_iter : int
        Iterations of the mode seeking.
    min_count : int
        Modes supported by fewer points are dropped (their points get label -1).

    Returns
    -------
    labels : ndarray of int, shape (n,)
        Cluster index of each point (-1: none), clusters sorted by decreasing size.
    modes : ndarray, shape (c, k)
        The cluster modes.
    """
    labels, modes, _ = ranked_mean_shift(points, max_iter=max_iter, min_count=min_count)
    return labels, modes


def ranked_mean_shift(
    points: np.ndarray, *, max_iter: int = 30, min_count: int = 1
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`mean_shift`, with the key that puts every cluster in its place (clustering in parts).

    Points farther than a bandwidth from every other part's never meet (no seed climbs across
    the gap), so a mean shift of the whole is that of its parts: the same clusters and modes,
    bit for bit (every seed sums its neighbours in the same order, see :func:`_ball_pairs`).
    Only the numbering is global: clusters are sorted by decreasing size, then by decreasing
    support of their mode, then by their seed's cell key.  :func:`rank_order` of the parts'
    keys, concatenated, gives the clusters in the order of one mean shift of all the points
    (a point equally near two modes may take either, as with one call).

    Returns
    -------
    labels, modes : ndarray
        As :func:`mean_shift`.
    rank : ndarray of :data:`RANK`, shape (c,)
        Per cluster: its size, its mode's support and its seed's cell key (a point farther
        than a bandwidth from every mode, a cluster of its own: support -1 and its index).
    """
    pts = np.asarray(points, dtype=float)
    n = pts.shape[0]
    if n == 0:
        return np.zeros(0, int), np.zeros((0, pts.shape[1] if pts.ndim == 2 else 0)), np.zeros(0, RANK)
    # Bin seeding on half-bandwidth cells: weighted centroids of occupied cells.
    keys = np.concatenate(
        [_row_keys(np.floor(pts[lo : lo + _BLOCK] * 2.0).astype(np.int64)) for lo in range(0, n, _BLOCK)]
    )  # in blocks: three temporaries of the size of the points for 6·10^6 points were 0.7 GiB
    if n == 1:
        return np.zeros(1, int), pts.copy(), np.array([(1, 1.0, keys[0])], RANK)
    cells = sorted_unique(keys)  # a plain sort: numpy's hashing took 15 s for 5·10^6 distinct keys
    inv = np.searchsorted(cells, keys)
    del keys
    counts = np.bincount(inv, minlength=cells.size)
    sums = [np.bincount(inv, weights=pts[:, k], minlength=cells.size) for k in range(pts.shape[1])]
    cent: np.ndarray = np.column_stack(sums).astype(float, copy=False)
    cent /= counts[:, None]
    w = counts.astype(float)
    tree = cKDTree(cent)
    seeds = cent.copy()
    climbed = parallel.pmap(lambda part: _climb(seeds, part, cent, w, tree, max_iter), _climb_parts(cent))
    # the neighbours of seeds that stopped exactly where they were
    still_owner = [o for owners, _ in climbed for o in owners]
    still_flat = [f for _, flats in climbed for f in flats]
    # Support of every converged seed, then merge modes closer than half a bandwidth (strongest first).
    support = _support(seeds, tree, w, still_owner, still_flat)
    order = np.argsort(-support, kind="stable")
    order = order[support[order] >= min_count]
    keep_idx = _suppress(seeds, order)
    if not keep_idx.size:
        return np.full(n, -1), np.zeros((0, pts.shape[1])), np.zeros(0, RANK)
    mode_arr = seeds[keep_idx]
    lab = _nearest_mode(pts, mode_arr, cent, inv)
    # Points farther than a bandwidth from every mode form their own singleton clusters.
    lone = np.flatnonzero(lab < 0)
    rank = np.zeros(keep_idx.size + lone.size, RANK)
    rank["support"] = np.concatenate([support[keep_idx], np.full(lone.size, -1.0)])
    rank["seed"] = np.concatenate([cells[keep_idx], lone])
    if lone.size:
        lab[lone] = mode_arr.shape[0] + np.arange(lone.size)
        mode_arr = np.vstack([mode_arr, pts[lone]])
    # Sort clusters by size (largest first).
    sizes = np.bincount(lab, minlength=mode_arr.shape[0])
    rank["size"] = sizes
    by = np.argsort(-sizes, kind="stable")
    remap = np.empty_like(by)
    remap[by] = np.arange(by.size)
    keep = sizes[by] > 0
    return remap[lab], mode_arr[by][keep], rank[by][keep]


def _climb_parts(cent: np.ndarray) -> list[np.ndarray]:
    """The seeds (cells ``cent``) of a mean shift in the parts that climb on their own, one a worker.

    Every level of a published wind-vector chart (4,817 arrows) has a mean shift of 10^4 to
    10^5 seeds, whose climb ran on one core for up to 5 s (its large KD-tree queries on two)
    while the other core waited.  In parts of at least :data:`_CLIMB_PART` seeds, slices across
    the widest dimension (seeds that meet are mostly in one), the climb of 84,106 seeds took
    4.0 s instead of 4.7 on two cores (6.2 s on one; the parts' smaller queries cost 17 % more
    CPU); whole ``lsys infer`` of the chart 0.96x the time, 1.03x the CPU (3 alternating pairs).
    One worker climbs all seeds at once.
    """
    n_parts = min(parallel.jobs(), len(cent) // _CLIMB_PART)
    if n_parts <= 1:
        return [np.arange(len(cent))]
    wide = int(np.argmax(np.ptp(cent, axis=0)))
    return [np.sort(p) for p in np.array_split(np.argsort(cent[:, wide], kind="stable"), n_parts)]


def _climb(
    seeds: np.ndarray, active: np.ndarray, cent: np.ndarray, w: np.ndarray, tree: cKDTree, max_iter: int
) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Move the seeds ``active`` up to their modes (``seeds`` in place): :func:`ranked_mean_shift`'s steps.

    Every seed climbs on its own (its steps read only the fixed cell centroids ``cent`` and
    weights ``w``), so the seeds of a large mean shift climb in parts, one a worker
    (:func:`_climb_parts`): each seed takes the same steps, its neighbours summed in the same
    order, bit for bit.  Returns the neighbours (seed, cell) of the seeds that stopped exactly
    where they were, for :func:`_support`.
    """
    still_owner: list[np.ndarray] = []
    still_flat: list[np.ndarray] = []
    crowded = np.zeros(len(seeds), bool)  # seeds with ≥ _NEAR neighbours at their last place
    for _ in range(max_iter):
        first, alike = _distinct_rows(seeds[active])  # seeds at one place are queried once
        owner, flat = _ball_pairs(seeds[active[first]], tree, crowded=crowded[active[first]])
        crowded[active] = (np.bincount(owner, minlength=first.size) >= _NEAR)[alike]
        ws = w[flat]
        dim = seeds.shape[1]
        num = np.column_stack(
            [np.bincount(owner, weights=cent[flat, k] * ws, minlength=first.size) for k in range(dim)]
        )
        den = np.bincount(owner, weights=ws, minlength=first.size)
        new = num / np.maximum(den, 1e-300)[:, None]
        step = np.abs(new - seeds[active[first]]).max(axis=1)
        still = step == 0.0
        if still.any():
            stopped = np.flatnonzero(still[alike])
            # each seed's neighbours in their order: numpy's stable sort merges the two sorted runs
            # (nearest, then ball pairs), several times quicker here than sorting.stable_argsort
            by = np.argsort(owner, kind="stable")
            offsets = np.concatenate([[0], np.cumsum(np.bincount(owner, minlength=first.size))])
            theirs = Groups(flat[by], offsets).take(alike[stopped])
            still_owner.append(active[stopped][theirs.owner()])
            still_flat.append(theirs.nodes)
        new, step = new[alike], step[alike]
        seeds[active] = new
        active = active[step >= 1e-4]  # converged seeds stay where they are
        if active.size == 0:
            break
    return still_owner, still_flat


def rank_order(rank: np.ndarray) -> np.ndarray:
    """The order of clusters keyed by :func:`ranked_mean_shift` (keys of several parts, concatenated).

    Within one call's keys this is ``arange``; over the parts of a point set, the order of
    the clusters of one call on all the points (lone points of a part: by their index in it).
    """
    return np.lexsort((rank["seed"], -rank["support"], -rank["size"]))


def group_indices(labels: np.ndarray) -> list[np.ndarray]:
    """Return the indices of every cluster of ``labels`` (label -1 is noise and left out).

    Clusters come in increasing label order, which :func:`mean_shift` sorts by decreasing size;
    within a cluster the indices are increasing.
    """
    labels = np.asarray(labels)
    order = stable_argsort(labels)
    cuts = np.flatnonzero(np.diff(labels[order])) + 1
    return [g for g in np.split(order, cuts) if g.size and labels[g[0]] >= 0]


def spread(points: np.ndarray, groups: list[np.ndarray]) -> np.ndarray:
    """Every member's distance from its group's mean, group after group.

    ``np.concatenate([np.linalg.norm(points[g] - points[g].mean(0), axis=1) for g in groups])``
    bit for bit (``bincount`` adds each group's rows in order, as ``mean(0)`` does), in a few
    passes instead of a few per group: the 758 clusters of 30,198 pairs of a 1,200-leaf grid's
    first level took 9.1 ms, now 2.6 ms (a few large clusters take as long as before).
    """
    if not groups:
        return np.zeros(0)
    sizes = np.fromiter((g.size for g in groups), np.int64, len(groups))
    rows = points[np.concatenate(groups)]
    gid = np.repeat(np.arange(sizes.size), sizes)
    dims = points.shape[1]
    sums = [np.bincount(gid, weights=rows[:, k], minlength=sizes.size) for k in range(dims)]
    mean = np.column_stack(sums) / sizes[:, None]
    rows -= mean[gid]
    return np.linalg.norm(rows, axis=1)
