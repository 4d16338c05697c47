"""What the choice of a level's rules reads besides the weights, kept with its candidates.

Re-weighting (:func:`~lsys_core.pipeline.rules_from_analysis`) meets the same levels again
(:class:`~lsys_core.hierarchy.cache.LevelCache`).  At each, the choice (§5.4–§5.5) reads the
candidates' start orders, the level's description length (:class:`~lsys_core.hierarchy.gain.Ledger`),
the terms of their importance, which nodes each covers, the bound of each one's gain and
whether it is worthwhile (:func:`~lsys_core.hierarchy.select.worthwhile`).  None of it depends
on the weights, so a :class:`LevelView` keeps them, made once per *context*: the level's nodes'
members and slack, its symbols, the tolerance, rounding and symmetry periods
(:func:`context_key`).  Only the importance, the order and the walk down it are computed per
weight change.
"""

from __future__ import annotations

import hashlib
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import replace

import numpy as np

from lsys_core.hierarchy.candidates import Candidate
from lsys_core.hierarchy.gain import Ledger
from lsys_core.hierarchy.nodes import Nodes
from lsys_core.hierarchy.rivals import Rivals
from lsys_core.hierarchy.select import Weights, importance_order, importance_terms
from lsys_core.hierarchy.symbols import SymbolTable
from lsys_core.memo import IdentityMemo

__all__ = ["Level", "LevelView", "context_key", "start_orders"]

#: Contexts a level keeps views for (a level is met again mostly in one context).
VIEWS = 4
#: Bytes a candidate object and one of its arrays take besides the arrays' data (estimate).
_OBJECT_BYTES, _ARRAY_BYTES = 600, 120


def start_orders(cands: list[Candidate], first: np.ndarray) -> list[tuple[float, float]]:
    """Mean input order of the first and of the second elements of each candidate's applications.

    One pass over all candidates' applications (a mean per candidate cost 4,224 numpy calls per
    weight change on a 1,200-element scene: 40 ms); the orders are integers, so the sums are
    exact and the means those of ``np.mean``.
    """
    counts = np.array([len(c.groups) for c in cands], np.int64)
    if cands:
        # every candidate's groups in one flat array: its group bounds shifted by the nodes before it
        sizes = np.array([c.groups.nodes.size for c in cands], np.int64)
        flat = np.concatenate([c.groups.nodes for c in cands])
        shift = np.repeat(np.cumsum(sizes) - sizes, counts)
        lo = np.concatenate([c.groups.offsets[:-1] for c in cands]) + shift
        hi = np.concatenate([c.groups.offsets[1:] for c in cands]) + shift
        heads, seconds = flat[lo], flat[lo + (hi - lo > 1)]
    else:
        heads = seconds = np.zeros(0, np.int64)
    offsets = np.concatenate(([0], np.cumsum(counts)[:-1]))
    order = np.asarray(first, np.float64)
    head = np.add.reduceat(order[heads], offsets) / counts
    second = np.add.reduceat(order[seconds], offsets) / counts
    return list(zip(head.tolist(), second.tolist(), strict=True))


def context_key(nodes: Nodes, table: SymbolTable, period: np.ndarray, limit: float, snap: float) -> bytes:
    """A digest of what a level's choice reads besides its candidates and the weights.

    The nodes' members (input order, exact checks of single elements) and slack, every
    symbol's name, counter and family, the symmetry periods, the tolerance and the rounding.
    """
    h = hashlib.blake2b(repr((limit, snap, table.n_terminals, tuple(table.infos))).encode(), digest_size=20)
    sizes = np.fromiter(map(len, nodes.members), np.int64, len(nodes.members))
    members = np.concatenate(nodes.members).astype(np.int64) if nodes.members else np.zeros(0, np.int64)
    for arr in (sizes, members, np.asarray(nodes.slack, np.float64), np.asarray(period, np.float64)):
        h.update(f"{arr.shape}".encode())
        h.update(np.ascontiguousarray(arr).data)
    return h.digest()


class LevelView:
    """A level's candidates in one context, with what the choice reads from them besides the weights.

    Parameters
    ----------
    cands : list of Candidate
        The level's candidates (as found: without start orders).
    ledger : Ledger
        The level's description length.
    first : ndarray of int
        The first input element of every node (:meth:`~lsys_core.hierarchy.nodes.Nodes.first_members`).
    """

    def __init__(self, cands: list[Candidate], ledger: Ledger, first: np.ndarray) -> None:
        self.ledger = ledger
        starts = start_orders(cands, first) if cands else []
        self.cands = [replace(c, start=st) for c, st in zip(cands, starts, strict=True)]
        self.terms = importance_terms(self.cands)
        self._tested: IdentityMemo[Candidate, Candidate | None] = IdentityMemo()
        self._ceilings: np.ndarray | None = None
        self._index = {id(c): i for i, c in enumerate(self.cands)}
        self._rivals: Rivals | None = None

    def order(self, weights: Weights) -> tuple[np.ndarray, list[int]]:
        """:func:`~lsys_core.hierarchy.select.importance_order` of the candidates for ``weights``."""
        return importance_order(self.cands, weights, self.terms)

    def index(self) -> Rivals:
        """The :class:`~lsys_core.hierarchy.rivals.Rivals` of the candidates (made once)."""
        if self._rivals is None:
            self._rivals = Rivals(self.cands, len(self.ledger.nodes))
        return self._rivals

    def ceiling(self, c: Candidate) -> float:
        """:meth:`~lsys_core.hierarchy.gain.Ledger.ceiling` of ``c``, one of the candidates.

        Those of all the candidates are worked out together when the first is asked
        (:meth:`~lsys_core.hierarchy.gain.Ledger.ceilings`): the choice asks nearly all of them.
        """
        if self._ceilings is None:
            self._ceilings = self.ledger.ceilings(self.cands)
        i = self._index.get(id(c))
        if i is None or self.cands[i] is not c:
            return self.ledger.ceiling(c)
        return float(self._ceilings[i])

    def tested(
        self, test: Callable[[Candidate], Candidate | None]
    ) -> Callable[[Candidate], Candidate | None]:
        """``test`` (:func:`~lsys_core.hierarchy.select.worthwhile` in this context), remembering its outcomes."""

        return lambda c: self._tested.get(c, test)


class Level:
    """A level's candidates and their views by context (see :class:`LevelView`).

    Parameters
    ----------
    cands : list of Candidate
        The candidates found at the level.
    """

    def __init__(self, cands: list[Candidate]) -> None:
        self.cands = cands
        data = sum(c.groups.nodes.nbytes + c.groups.offsets.nbytes for c in cands)
        #: bytes held, with as much again for a view's copies of the candidates and their outcomes
        #: (a 164-element flag's 195 levels: 0.63 MiB each measured, 0.66 estimated)
        self.nbytes = 2 * (len(cands) * (_OBJECT_BYTES + 2 * _ARRAY_BYTES) + data)
        self._views: OrderedDict[bytes, LevelView] = OrderedDict()

    def view(
        self, context: bytes, ledger: Callable[[], Ledger], first: Callable[[], np.ndarray]
    ) -> LevelView:
        """The view of ``context`` (:func:`context_key`), made with ``ledger()`` and ``first()`` if new."""
        found = self._views.get(context)
        if found is None:
            found = self._views[context] = LevelView(self.cands, ledger(), first())
            while len(self._views) > VIEWS:
                self._views.popitem(last=False)
        self._views.move_to_end(context)
        return found
