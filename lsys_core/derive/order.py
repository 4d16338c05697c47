"""Positions of derived terminals in the derived string (the L-system's own order).

The vectorised derivation expands calls level by level, not left to right.  Each call it
expands (an *item*) and each terminal it draws records its parent item and a *rank* that
orders the siblings of one parent as they stand in the parent's body (a sequence's steps
rank one after the other).  Then the position of a terminal in the fully rewritten string
follows from subtree sizes: sizes bottom-up, offsets top-down, both chunk by chunk (a
chunk's parents are always in earlier chunks), so the work is a few numpy calls per chunk.
"""

from __future__ import annotations

import numpy as np

__all__ = ["Items", "string_positions"]


class Items:
    """The items of one derivation: item 0 is the axiom; later ones are added in chunks."""

    def __init__(self) -> None:
        self.count = 1
        self.chunks: list[tuple[int, np.ndarray, np.ndarray]] = []  # (first id, parent ids, ranks)

    def add(self, parent: np.ndarray, rank: np.ndarray) -> np.ndarray:
        """Register items with their parents and ranks; return their ids."""
        first = self.count
        self.count += parent.size
        self.chunks.append((first, np.asarray(parent, np.int64), np.asarray(rank, np.int64)))
        return np.arange(first, self.count, dtype=np.int64)


def string_positions(items: Items, parent: np.ndarray, rank: np.ndarray) -> np.ndarray:
    """Return the 0-based position of every drawn terminal in the derived string.

    Parameters
    ----------
    items : Items
        The expanded calls with their parents and ranks.
    parent, rank : ndarray of int
        Parent item and rank of every drawn terminal.
    """
    n_items = items.count
    item_parent = np.full(n_items, -1, np.int64)
    item_rank = np.zeros(n_items, np.int64)
    for first, par, rk in items.chunks:
        item_parent[first : first + par.size] = par
        item_rank[first : first + par.size] = rk
    size = np.bincount(parent, minlength=n_items).astype(np.int64)
    for first, par, _ in reversed(items.chunks):
        np.add.at(size, par, size[first : first + par.size])
    # Offsets of every child (item or terminal) within its parent: siblings in rank order.
    child_parent = np.concatenate([item_parent[1:], parent])
    child_rank = np.concatenate([item_rank[1:], rank])
    child_size = np.concatenate([size[1:], np.ones(parent.size, np.int64)])
    order = np.lexsort((child_rank, child_parent))
    sizes = child_size[order]
    csum = np.cumsum(sizes) - sizes
    par_sorted = child_parent[order]
    starts = np.r_[True, par_sorted[1:] != par_sorted[:-1]] if order.size else np.zeros(0, bool)
    group_first = np.maximum.accumulate(np.where(starts, np.arange(order.size), 0)) if order.size else order
    local = np.empty(order.size, np.int64)
    local[order] = csum - csum[group_first]
    offset = np.zeros(n_items, np.int64)
    item_local = local[: n_items - 1]
    for first, par, _ in items.chunks:
        sl = slice(first, first + par.size)
        offset[sl] = offset[par] + item_local[first - 1 : first - 1 + par.size]
    return offset[parent] + local[n_items - 1 :]
