"""Translation bandwidths no wider than the spacing of the nodes they measure.

The paper's bandwidths are relative to the size of the nodes (§5.3).  Nodes of upper levels
can be far longer than the distance between them: a row of 365 leaves is 14,600 units long and
lies 40 units from the next row; 2 % of its radius (146) spans three steps, so mean shift puts
the steps 40, 80 and 120 into one mode near 80, the rows come back as two interleaved
sequences of every other row, and the hierarchy does not close (a 100,010-leaf grid then ran
its whole rule generation a second time with relaxed bandwidths: 117 s instead of ~60 s).

The translation bandwidth of a pair of composite nodes is therefore at most
:data:`SHARE` of the typical distance from a node to its nearest neighbour in the pair's space
(a step and a double step then lie four bandwidths apart), but never below ``floor``: a
composite's frame is that of its first member, placed as precisely as a terminal.  Terminals
keep the paper's bandwidth (copies stacked closer than their size, such as concentric rings,
are told apart by their size).
"""

from __future__ import annotations

import numpy as np

from lsys_core.hierarchy.spaces import PairSpace

__all__ = ["SHARE", "spacing_cap"]

#: Share of the nearest-neighbour spacing a composite pair's translation bandwidth may reach.
SHARE = 0.25


def spacing_cap(
    ps: PairSpace, key: np.ndarray, composite: np.ndarray, n_nodes: int, floor: float
) -> np.ndarray:
    """The largest translation bandwidth of every pair (``inf`` where none applies).

    Parameters
    ----------
    ps : PairSpace
        The pairs of the level.
    key : ndarray of int
        Every pair's space (:func:`~lsys_core.hierarchy.candidates.space_key`).
    composite : ndarray of bool
        Per pair, whether its source node is a composite (a rule's symbol, not a terminal).
    n_nodes : int
        Number of live nodes.
    floor : float
        The smallest cap (source-frame units), e.g. the terminals' bandwidth.

    Returns
    -------
    ndarray of float
        Per pair: ``max(SHARE · median nearest-neighbour distance of its space, floor)`` for
        composite sources, ``inf`` for terminals.
    """
    cap = np.full(len(ps), np.inf)
    idx = np.flatnonzero(composite)
    if idx.size == 0:
        return cap
    # nearest neighbour of every source within each space: minimum over its (space, source) group
    group = key[idx].astype(np.int64) * np.int64(n_nodes) + ps.src[idx]
    order = np.argsort(group, kind="stable")
    g = group[order]
    starts = np.flatnonzero(np.r_[True, g[1:] != g[:-1]])
    nearest = np.minimum.reduceat(ps.d[idx][order], starts)
    space = g[starts] // n_nodes
    # the median of these per space (the lower one of an even count)
    o2 = np.lexsort((nearest, space))
    sp, near = space[o2], nearest[o2]
    first = np.flatnonzero(np.r_[True, sp[1:] != sp[:-1]])
    last = np.r_[first[1:], sp.size] - 1
    median = near[(first + last) // 2]
    where = np.searchsorted(sp[first], key[idx])
    cap[idx] = np.maximum(SHARE * median[where], floor)
    return cap
