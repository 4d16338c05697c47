"""Values worked out from an object, remembered by the object's identity.

Shared styles (:mod:`lsys_core.svg`) and the candidates of a cached level
(:mod:`lsys_core.hierarchy.reuse`) are met again as the same objects, so what is derived from
them is looked up by ``id`` instead of being hashed or computed again.  Each entry holds its
object, so no other object can take its ``id`` while the entry lives.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Generic, TypeVar

__all__ = ["IdentityMemo"]

K = TypeVar("K")
V = TypeVar("V")


class IdentityMemo(Generic[K, V]):
    """``compute(obj)`` remembered per object identity.

    Parameters
    ----------
    size : int, optional
        Objects kept at most: the memo starts again when full (None: no bound).
    """

    def __init__(self, size: int | None = None) -> None:
        self.size = size
        self._memo: dict[int, tuple[K, V]] = {}

    def get(self, obj: K, compute: Callable[[K], V]) -> V:
        """``compute(obj)``, from memory when ``obj`` itself was seen before."""
        got = self._memo.get(id(obj))
        if got is not None and got[0] is obj:
            return got[1]
        value = compute(obj)
        if self.size is not None and len(self._memo) >= self.size:
            self._memo.clear()
        self._memo[id(obj)] = (obj, value)
        return value
