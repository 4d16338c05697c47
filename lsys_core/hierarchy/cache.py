"""The candidates of hierarchy levels, kept across rule generations (cheap re-weighting).

A level's candidates (§5.3) depend on its live nodes, the symbols' sizes, counters and
families, the clustering bandwidths and the number of neighbours, never on the importance
weights (§5.4): those only choose among them.  Keyed by a digest of exactly those inputs, the
candidates of a level found once are reused when rules are generated again with other
weights, as long as the levels before it chose the same rules (always for the first level,
which dominates).  What the choice reads from them besides the weights is kept with them
(:mod:`lsys_core.hierarchy.reuse`).

The store is bounded by the bytes its levels hold, not by their number: a scene whose rule
generation (with its relaxed tries) meets more levels than a count would allow evicted every
level before it was met again, and no weight change reused anything.
"""

from __future__ import annotations

import hashlib
from collections import OrderedDict
from typing import Any

import numpy as np

__all__ = ["LevelCache"]

#: Bytes the stored levels may hold (an estimate of their candidates' arrays and objects).
BUDGET = 256 * 2**20


class LevelCache:
    """A store of level candidates keyed by :meth:`key`, the least recently used going first.

    Parameters
    ----------
    capacity : int
        Levels kept at most.
    budget : int
        Bytes kept at most (as :meth:`put` is told them); the last level stored is always kept.
    """

    def __init__(self, capacity: int = 4096, budget: int = BUDGET) -> None:
        self.capacity = capacity
        self.budget = budget
        self._store: OrderedDict[bytes, tuple[Any, int]] = OrderedDict()
        self._bytes = 0
        self.hits = 0
        self.misses = 0

    @staticmethod
    def key(arrays: list[np.ndarray], extra: tuple) -> bytes:
        """A digest of the level's inputs: the arrays' dtypes, shapes and bytes, and ``extra``."""
        h = hashlib.blake2b(repr(extra).encode(), digest_size=20)
        for arr in arrays:
            arr = np.ascontiguousarray(arr)
            h.update(f"{arr.dtype.str}{arr.shape}".encode())
            h.update(arr.data)
        return h.digest()

    def get(self, key: bytes) -> Any | None:
        """The level stored under ``key``, or None."""
        found = self._store.get(key)
        if found is None:
            self.misses += 1
            return None
        self.hits += 1
        self._store.move_to_end(key)
        return found[0]

    def put(self, key: bytes, level: Any, nbytes: int = 0) -> None:
        """Store a level (shared by every later use) that holds about ``nbytes``."""
        old = self._store.pop(key, None)
        if old is not None:
            self._bytes -= old[1]
        self._store[key] = (level, nbytes)
        self._bytes += nbytes
        while len(self._store) > 1 and (len(self._store) > self.capacity or self._bytes > self.budget):
            self._bytes -= self._store.popitem(last=False)[1][1]

    @property
    def nbytes(self) -> int:
        """Bytes the stored levels hold (as :meth:`put` was told)."""
        return self._bytes

    def __len__(self) -> int:
        return len(self._store)
