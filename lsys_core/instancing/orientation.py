"""Choose the rotations of symmetric elements so that their arrangement reads as regular.

A rectangle turned by 120° looks the same as one turned by -60°: for a shape with k-fold
symmetry the rotation of an instance is only known modulo 360/k, and the similarity stage
reports the representative in (-180/k, 180/k].  In a ring of bars turned 30° apart that
wraps from 90° to -60° half way round, and the constant transform between neighbours is
lost.  Here rotations are *unwrapped* like a phase: along a minimum spanning tree of each
group's nearest-neighbour graph, every instance takes the equivalent rotation closest to its
parent's, so a constant step stays constant.  The drawing does not change.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import breadth_first_order, connected_components, minimum_spanning_tree
from scipy.spatial import cKDTree

from lsys_core.instancing.model import Instancing
from lsys_core.parallel import jobs

__all__ = ["ring_headings", "unwrap_symmetric", "unwrap_turns"]

#: Points from which neighbours are looked up on all workers (for fewer, starting threads costs more).
_THREADED = 4096

#: Radians within which an instance is taken to be exactly half a period from its parent: both
#: equivalent rotations are as close, and the instance keeps the one nearest its own reported
#: rotation (a tick beside an axis line at 90° to it stays as upright as the other ticks).
TIE = 1e-9


def unwrap_turns(a: np.ndarray, b: np.ndarray, period: float) -> np.ndarray:
    """Return the rotations (radians) of one group's instances, unwrapped along an MST."""
    n = a.size
    theta = np.angle(a)
    if n < 2:
        return theta
    k = min(6, n - 1)
    pts = np.column_stack([b.real, b.imag])
    # the same neighbours for any number of workers (threads only pay off for many points)
    dist, idx = cKDTree(pts).query(pts, k=k + 1, workers=jobs() if n >= _THREADED else 1)
    w = dist[:, 1:].ravel() + 1e-12  # zero weights would be dropped from the sparse graph
    # rows of k neighbours, none twice: the matrix COO entries give, without their sort
    graph = csr_matrix((w, idx[:, 1:].ravel(), np.arange(0, n * k + 1, k)), shape=(n, n))
    graph.sort_indices()
    tree = minimum_spanning_tree(graph)
    tree = tree + tree.T
    _, comp = connected_components(tree, directed=False)
    # Python floats, not numpy scalars: the same IEEE operations (``%`` is ``np.mod``), in a
    # quarter of the time (the walk took 60 ms for the 50,052 leaves of a grid)
    own = theta.tolist()
    out = theta.tolist()
    half = period / 2
    for root in np.unique(comp, return_index=True)[1].tolist():  # each component from its first node
        order, parent = breadth_first_order(tree, root, directed=False, return_predecessors=True)
        below = order[1:]
        for node, up in zip(below.tolist(), parent[below].tolist(), strict=True):
            p = out[up]
            turn = (own[node] - p + half) % period - half
            if abs(abs(turn) - half) < TIE:  # half a period from the parent: keep its own side
                turn = half if abs(p + half - own[node]) <= abs(p - half - own[node]) else -half
            out[node] = p + turn
    return np.array(out)


def unwrap_symmetric(inst: Instancing) -> Instancing:
    """Return ``inst`` with the rotations of k-fold symmetric terminals unwrapped (see module doc)."""
    a = inst.a.copy()
    for g, order in enumerate(np.asarray(inst.symmetry)):
        if order < 2:
            continue  # no symmetry, or continuous (a circle: every rotation is the same)
        sel = np.flatnonzero(inst.group == g)
        if sel.size < 2:
            continue
        theta = unwrap_turns(inst.a[sel], inst.b[sel], 2 * np.pi / order)
        a[sel] = np.abs(inst.a[sel]) * np.exp(1j * theta)
    return replace(inst, a=a)


def _circle(z: np.ndarray) -> tuple[complex, float]:
    """Least-squares circle through the points ``z`` (Kåsa's algebraic fit): centre and radius."""
    m = np.column_stack([z.real, z.imag, np.ones(z.size)])
    rhs = np.abs(z) ** 2
    (p, q, r), *_ = np.linalg.lstsq(m, rhs, rcond=None)
    c = complex(p / 2.0, q / 2.0)
    return c, float(np.sqrt(max(r + abs(c) ** 2, 0.0)))


def _on_a_ring(b: np.ndarray, tolerance: float) -> complex | None:
    """The centre of the circle the points ``b`` lie on within ``tolerance``, or None.

    Points on a line (within the tolerance) are a row, not a ring; a circle much larger than
    the spread of the points is a bent row.
    """
    if b.size < 3:
        return None
    z = b - b.mean()
    _, _, vt = np.linalg.svd(np.column_stack([z.real, z.imag]), full_matrices=False)
    across = np.abs(z.real * vt[-1, 0] + z.imag * vt[-1, 1])
    if across.max() <= tolerance:
        return None
    c, radius = _circle(b)
    spread = float(np.abs(z).max())
    if not np.isfinite(radius) or radius > 4.0 * spread or np.abs(np.abs(b - c) - radius).max() > tolerance:
        return None
    if np.abs(b - c).min() <= tolerance:
        return None  # a point at the centre has no direction
    return c


def ring_headings(inst: Instancing, tolerance: float) -> Instancing:
    """Turn the instances of round terminals that lie on a ring to face away from its centre.

    A round terminal (symmetry order 0) shows no rotation, so its instances carry none and
    neighbours on a ring are related by a different shift each: the ring is not a constant
    transform.  Facing every instance away from the ring's centre makes it one (a turn of
    ``360°/n`` and a step), which a single sequence rule writes.  The drawing does not change:
    the terminal stays round (order 0), its rotation about its centre unseen.
    """
    a = inst.a.copy()
    for g, order in enumerate(np.asarray(inst.symmetry)):
        if order != 0:
            continue
        sel = np.flatnonzero(inst.group == g)
        c = _on_a_ring(inst.b[sel], tolerance)
        if c is None:
            continue
        u = inst.b[sel] - c
        a[sel] = np.abs(inst.a[sel]) * u / np.abs(u)
    return replace(inst, a=a)
