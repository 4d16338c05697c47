"""Which of a level's candidates lie on some of a given set of nodes (the rivals of a choice).

A candidate yields to rivals on its nodes that save far more
(:func:`~lsys_core.hierarchy.select.choose`); finding them is asked once per chosen candidate.
A level where one candidate covers every node asks once: a scan of every candidate's nodes
against a mark of the asked ones answers it (a 50,052-leaf grid's first level: 757 candidates
on 2.46 million nodes; the sorted index of every node's candidates took 0.16 s and reading it
for the 50,052 asked nodes one slice each 0.07 s, the scan takes about 10 ms).  A level
asked many times (small rules among clutter) builds the index after :data:`SCANS` scans.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

import numpy as np

from lsys_core.sorting import sorted_unique

__all__ = ["SCANS", "Rivals", "node_index"]

#: Scans of every candidate's nodes made before the index is built (it costs some 15 scans).
SCANS = 8


class _HasNodes(Protocol):
    def nodes(self) -> np.ndarray: ...


def node_index(cands: Sequence[_HasNodes], n_nodes: int) -> tuple[np.ndarray, np.ndarray]:
    """The candidates on every node: ``owners[start[k]:start[k + 1]]`` are those on node ``k``.

    Each node's candidates are listed once, in increasing order: one sort of the (node,
    candidate) pairs packed into one integer (a ``np.unique`` per candidate took 0.5 s of a
    50,052-leaf grid).
    """
    if not cands:
        return np.zeros(0, np.int64), np.zeros(n_nodes + 1, np.int64)
    flat, which = _entries(cands)
    node, owner = np.divmod(sorted_unique(flat * len(cands) + which), len(cands))
    return owner, np.searchsorted(node, np.arange(n_nodes + 1))


def _entries(cands: Sequence[_HasNodes]) -> tuple[np.ndarray, np.ndarray]:
    """Every candidate's nodes one after another, and the candidate of each entry."""
    nodes = [c.nodes() for c in cands]
    flat = np.concatenate(nodes).astype(np.int64)
    which = np.repeat(np.arange(len(cands), dtype=np.int64), [x.size for x in nodes])
    return flat, which


class Rivals:
    """The candidates on any of a set of nodes, for one level's candidates.

    Parameters
    ----------
    cands : list of Candidate
        The level's candidates (anything with ``nodes()``).
    n_nodes : int
        Number of nodes of the level (every candidate's nodes lie below it).
    """

    def __init__(self, cands: Sequence[_HasNodes], n_nodes: int) -> None:
        self._cands = cands
        self._n = n_nodes
        self._scans = 0
        self._entries: tuple[np.ndarray, np.ndarray] | None = None
        self._index: tuple[np.ndarray, np.ndarray] | None = None

    def on(self, nodes: np.ndarray) -> np.ndarray:
        """Indices (increasing, each once) of the candidates with a node in ``nodes``."""
        nodes = np.asarray(nodes, np.int64)
        if not self._cands or nodes.size == 0:
            return np.zeros(0, np.int64)
        if self._index is None and self._scans >= SCANS:
            self._index = node_index(self._cands, self._n)
            self._entries = None
        if self._index is not None:
            return _read_index(self._index, sorted_unique(nodes))
        self._scans += 1
        if self._entries is None:
            self._entries = _entries(self._cands)
        flat, which = self._entries
        mark = np.zeros(self._n, bool)
        mark[nodes] = True
        hit = np.bincount(which[mark[flat]], minlength=len(self._cands))
        return np.flatnonzero(hit).astype(np.int64)


def _read_index(index: tuple[np.ndarray, np.ndarray], nodes: np.ndarray) -> np.ndarray:
    """The candidates :func:`node_index` lists on any of ``nodes`` (distinct), increasing, each once."""
    owners, start = index
    lo, count = start[nodes], start[nodes + 1] - start[nodes]
    total = int(count.sum())
    # the positions lo[k] .. lo[k] + count[k] - 1 of every node, one after another
    shift = np.repeat(lo - (np.cumsum(count) - count), count)
    return sorted_unique(owners[shift + np.arange(total)])
