"""The candidates of hierarchy levels, kept across rule generations (cheap re-weighting).

A level's candidates (§5.3) depend on its live nodes, the symbols' sizes and families, the
clustering bandwidths and the number of neighbours, never on the importance weights (§5.4):
those only choose among them.  Keyed by a digest of exactly those inputs, the candidates of a
level found once are reused when rules are generated again with other weights, as long as
the levels before it chose the same rules (always for the first level, which dominates).
"""

from __future__ import annotations

import hashlib
from collections import OrderedDict

import numpy as np

__all__ = ["LevelCache"]


class LevelCache:
    """A bounded store of level candidates keyed by :meth:`key` (least recently used goes first).

    Parameters
    ----------
    capacity : int
        Levels kept at most.
    """

    def __init__(self, capacity: int = 64) -> None:
        self.capacity = capacity
        self._store: OrderedDict[bytes, list] = OrderedDict()
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

    def get(self, key: bytes) -> list | None:
        """The candidates stored under ``key``, or None."""
        found = self._store.get(key)
        if found is None:
            self.misses += 1
            return None
        self.hits += 1
        self._store.move_to_end(key)
        return found

    def put(self, key: bytes, cands: list) -> None:
        """Store a level's candidates (frozen values, shared by every later use)."""
        self._store[key] = cands
        self._store.move_to_end(key)
        while len(self._store) > self.capacity:
            self._store.popitem(last=False)

    def __len__(self) -> int:
        return len(self._store)
