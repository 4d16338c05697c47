"""Flat, vectorised chain primitives: following successor maps, greedy matchings, greedy disjoint sets.

The cluster analysis links pairs of nodes into sequences many thousand times per level.
Done one Python step per link, it dominated inference on large scenes; here the same
results come from whole-array operations: walking all chains one step at a time, and a
greedy choice decided for every item as soon as the items before it at each of its keys are
(exactly what a sequential greedy pass decides, in rounds as deep as the longest chain of
such dependencies).  Groups are held flat: chain ``k`` is ``nodes[offsets[k]:offsets[k + 1]]``.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterable, Iterator
from dataclasses import dataclass

import numpy as np

from lsys_core.sorting import sorted_unique

__all__ = [
    "Groups",
    "as_groups",
    "follow_links",
    "greedy_disjoint",
    "greedy_links",
    "greedy_sets",
    "isin",
]


def as_groups(groups: Groups | Iterable[Iterable[int]]) -> Groups:
    """``groups`` as :class:`Groups` (made with :meth:`Groups.of` unless it is one already)."""
    return groups if isinstance(groups, Groups) else Groups.of(groups)


def isin(x: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """``np.isin(x, ref)`` for integer arrays, by sorting and binary search."""
    s = sorted_unique(ref)
    if s.size == 0:
        return np.zeros(np.shape(x), bool)
    pos = np.minimum(np.searchsorted(s, x), s.size - 1)
    return s[pos] == x


@dataclass(frozen=True, eq=False)
class Groups:
    """Groups of integers (chains of nodes, trees, the elements under each node) in two flat arrays.

    Behaves like a sequence of integer arrays: ``len``, indexing and iteration give each
    group as an array (a view into :attr:`nodes`); the vectorised code reads the flat arrays.

    Attributes
    ----------
    nodes : ndarray of int64
        The members of all groups, group after group.
    offsets : ndarray of int64, shape (count + 1,)
        Group ``k`` is ``nodes[offsets[k]:offsets[k + 1]]``.
    """

    nodes: np.ndarray
    offsets: np.ndarray

    @staticmethod
    def of(groups: Iterable[Iterable[int]]) -> Groups:
        """Groups from a sequence of integer sequences (or arrays)."""
        parts = [np.asarray(g, np.int64).ravel() for g in groups]
        lengths = np.array([p.size for p in parts], np.int64)
        nodes = np.concatenate(parts) if parts else np.zeros(0, np.int64)
        return Groups(nodes, np.concatenate([[0], np.cumsum(lengths)]).astype(np.int64))

    @staticmethod
    def singletons(n: int) -> Groups:
        """The groups ``[0], [1], …, [n - 1]``."""
        return Groups(np.arange(n, dtype=np.int64), np.arange(n + 1, dtype=np.int64))

    def __len__(self) -> int:
        return int(self.offsets.size - 1)

    def __getitem__(self, k: int) -> np.ndarray:
        k = range(len(self))[k]
        return self.nodes[self.offsets[k] : self.offsets[k + 1]]

    def __iter__(self) -> Iterator[np.ndarray]:
        nodes = self.nodes
        for lo, hi in itertools.pairwise(self.offsets.tolist()):
            yield nodes[lo:hi]

    def tolist(self) -> list[list[int]]:
        """Every group as a list of ints."""
        flat = self.nodes.tolist()
        return [flat[lo:hi] for lo, hi in itertools.pairwise(self.offsets.tolist())]

    def positions(self) -> np.ndarray:
        """Position of every entry of :attr:`nodes` within its chain (0 for the first node)."""
        return np.arange(self.nodes.size) - np.repeat(self.offsets[:-1], self.lengths)

    @property
    def lengths(self) -> np.ndarray:
        """Number of nodes of every chain."""
        offsets = self.offsets
        return offsets[1:] - offsets[:-1]  # np.diff, without its Python-level checks (called per candidate)

    @property
    def firsts(self) -> np.ndarray:
        """First node of every chain (chains are never empty)."""
        return self.nodes[self.offsets[:-1]]

    def owner(self) -> np.ndarray:
        """Chain index of every entry of :attr:`nodes`."""
        return np.repeat(np.arange(len(self)), self.lengths)

    def take(self, which: np.ndarray) -> Groups:
        """The chains ``which`` (indices, in that order)."""
        which = np.asarray(which, np.int64)
        lengths = self.lengths[which]
        offsets = np.concatenate([[0], np.cumsum(lengths)]).astype(np.int64)
        pos = (
            np.arange(int(offsets[-1]))
            - np.repeat(offsets[:-1], lengths)
            + np.repeat(self.offsets[which], lengths)
        )
        return Groups(self.nodes[pos], offsets)

    def head(self, count: int) -> Groups:
        """Every chain cut to its first ``count`` nodes (these groups themselves when none is longer)."""
        lengths = self.lengths
        if lengths.size == 0 or int(lengths.max()) <= count:
            return self  # nothing to cut (immutable: sharing is safe)
        return self.take_prefix(np.minimum(lengths, count))

    def take_prefix(self, lengths: np.ndarray) -> Groups:
        """Every chain cut to its first ``lengths[k]`` nodes."""
        offsets = np.concatenate([[0], np.cumsum(lengths)]).astype(np.int64)
        pos = (
            np.arange(int(offsets[-1]))
            - np.repeat(offsets[:-1], lengths)
            + np.repeat(self.offsets[:-1], lengths)
        )
        return Groups(self.nodes[pos], offsets)

    def remap(self, mapping: np.ndarray) -> Groups:
        """The same chains with every node ``v`` replaced by ``mapping[v]``."""
        return Groups(np.asarray(mapping)[self.nodes].astype(np.int64), self.offsets)

    def links(self) -> tuple[np.ndarray, np.ndarray]:
        """Positions in :attr:`nodes` of every consecutive pair ``(c[t], c[t + 1])``, chain by chain."""
        last = np.zeros(self.nodes.size, bool)
        last[self.offsets[1:] - 1] = True
        first = np.flatnonzero(~last)
        return first, first + 1

    def concat(self, other: Groups) -> Groups:
        """These chains followed by ``other``."""
        return Groups(
            np.concatenate([self.nodes, other.nodes]),
            np.concatenate([self.offsets, other.offsets[1:] + self.offsets[-1]]),
        )


def _walk(nxt: np.ndarray, heads: np.ndarray) -> Groups:
    """Groups from every head along ``nxt`` (-1: end), one step for all walkers at a time."""
    rec_c, rec_v = [], []
    cur = heads.astype(np.int64)
    chain = np.arange(heads.size, dtype=np.int64)
    while cur.size:
        rec_c.append(chain)
        rec_v.append(cur)
        cur = nxt[cur]
        more = cur >= 0
        cur, chain = cur[more], chain[more]
    if not rec_c:
        return Groups(np.zeros(0, np.int64), np.zeros(1, np.int64))
    c = np.concatenate(rec_c)
    del rec_c
    lengths = np.bincount(c, minlength=heads.size)
    offsets = np.concatenate([[0], np.cumsum(lengths)]).astype(np.int64)
    # Every visit's place: its chain's offset plus its step (the record it is in), without a
    # step array per record beside the others.
    pos = offsets[c]
    del c
    pos += np.repeat(np.arange(len(rec_v), dtype=np.int64), [v.size for v in rec_v])
    flat = np.empty(pos.size, np.int64)
    flat[pos] = np.concatenate(rec_v)
    return Groups(flat, offsets)


def follow_links(src: np.ndarray, dst: np.ndarray, starts: np.ndarray) -> tuple[Groups, Groups]:
    """Follow a successor map (each node ≤ 1 successor and ≤ 1 predecessor) into chains.

    Parameters
    ----------
    src, dst : ndarray of int
        The links ``src[k] → dst[k]`` (``src`` distinct, ``dst`` distinct, no self links).
    starts : ndarray of int
        Where paths start, in the order wanted; every node with a successor but no
        predecessor must be among them.

    Returns
    -------
    paths : Groups
        One chain per start, in the order of ``starts``, following successors to the end.
    loops : Groups
        The closed loops the paths do not reach, each listed from its smallest node and in
        the order of those nodes (the link closing a loop is not repeated).
    """
    src = np.asarray(src, np.int64)
    dst = np.asarray(dst, np.int64)
    starts = np.asarray(starts, np.int64)
    ids = sorted_unique(np.concatenate([src, dst, starts]))
    m = ids.size
    s, d = np.searchsorted(ids, src), np.searchsorted(ids, dst)
    nxt = np.full(m, -1, np.int64)
    nxt[s] = d
    paths = _walk(nxt, np.searchsorted(ids, starts))
    seen = np.zeros(m, bool)
    seen[paths.nodes] = True
    rest = s[~seen[s]]  # nodes with a successor the paths never reach: they lie on loops
    if rest.size == 0:
        return paths.remap(ids), Groups(np.zeros(0, np.int64), np.zeros(1, np.int64))
    # Smallest node of every loop: min-propagation along doubling successor jumps.
    q = nxt.copy()
    mn = np.arange(m, dtype=np.int64)
    sub = rest
    for _ in range(max(1, int(np.ceil(np.log2(rest.size + 1))) + 1)):
        mn[sub] = np.minimum(mn[sub], mn[q[sub]])
        q[sub] = q[q[sub]]
    heads = sorted_unique(mn[rest])
    cut = nxt.copy()
    cut[rest[nxt[rest] == mn[rest]]] = -1  # drop each loop's closing link
    return paths.remap(ids), _walk(cut, heads).remap(ids)


def greedy_sets(
    offsets: np.ndarray, items: np.ndarray, order: np.ndarray, *, skip_repeating: bool = False
) -> np.ndarray:
    """Which sets a greedy pass in ``order`` takes when taken sets must not share items.

    Set ``c`` holds ``items[offsets[c]:offsets[c + 1]]`` (distinct); it is taken iff no
    earlier taken set (in ``order``) shares an item with it.  Sets not in ``order`` are never
    taken and block nothing.  Exact, and linear in the entries after one sort: a set is
    decided as soon as every set before it at each of its items is (rounds follow the
    longest chain of such dependencies, each touching only entries whose state changed).
    With ``skip_repeating``, sets whose items are not distinct are dropped from ``order``
    first (found as equal neighbours in that sort, not in one of their own).

    Parameters
    ----------
    offsets : ndarray of int
        Set boundaries in ``items``.
    items : ndarray of int
        The items of all sets, set after set (items ≥ 0).
    order : ndarray of int
        The sets to consider, best first.

    Returns
    -------
    ndarray of bool
        Whether each set is taken.
    """
    count = offsets.size - 1
    accept = np.zeros(count, bool)
    order = np.asarray(order, np.int64)
    if order.size == 0 or items.size == 0:
        return accept
    lengths = np.diff(offsets)
    rank = np.full(count, count, np.int64)
    rank[order] = np.arange(order.size)
    live = np.repeat(rank < count, lengths)
    owner = np.repeat(np.arange(count, dtype=np.int64), lengths)[live]
    items = np.asarray(items, np.int64)[live]
    # Entries sorted by item, then by the rank of their set: per item, the sets in greedy order.
    e_key = items * np.int64(count)
    e_key += rank[owner]
    del live, owner, items  # entry-sized arrays are held only while needed (10^7 entries at 60k elements)
    e_key.sort()
    if skip_repeating:
        repeated = np.flatnonzero(e_key[1:] == e_key[:-1])
        if repeated.size:
            bad = np.zeros(count, bool)
            bad[order[e_key[repeated] % count]] = True
            rank[bad] = count
            e_key = e_key[~bad[order[e_key % count]]]
            if e_key.size == 0:
                return accept
    e_item = e_key // count
    e_key %= count
    e_set = order[e_key]
    del e_key
    cut = np.flatnonzero(e_item[1:] != e_item[:-1]) + 1
    del e_item
    n_entries = e_set.size
    starts = np.concatenate([[0], cut])
    ends = np.concatenate([cut, [n_entries]])
    end_of = np.repeat(ends, ends - starts)  # per entry: end of its item's run
    head = np.zeros(e_set.size, bool)
    head[starts] = True  # entries that are their item's first undecided set
    del cut, starts, ends, lengths
    wait = np.bincount(e_set[~head], minlength=count)  # items where a set is not first yet
    # Per set, its entries' positions in the sorted order (second sort: by set), sorted in place.
    by_set = e_set * np.int64(e_set.size)
    by_set += np.arange(e_set.size)
    by_set.sort()
    by_set %= e_set.size
    set_lo = np.concatenate([[0], np.cumsum(np.bincount(e_set, minlength=count))])
    state = np.zeros(count, np.int8)  # 0 undecided, 1 taken, 2 not taken

    def entries_of(sets: np.ndarray) -> np.ndarray:
        lo, n = set_lo[sets], set_lo[sets + 1] - set_lo[sets]
        return by_set[_ranges(lo, n)]

    frontier = np.flatnonzero((wait == 0) & (rank < count))
    del rank
    while frontier.size:
        state[frontier] = 1
        accept[frontier] = True
        ent = entries_of(frontier)
        # Every later set at a taken item is not taken (the first round holds most entries:
        # its arrays are made in place and dropped as soon as used).
        span = end_of[ent]
        span -= ent
        span -= 1
        ent += 1
        later = _ranges(ent, span)
        del ent, span
        rej = e_set[later]
        del later
        rej = sorted_unique(rej)
        rej = rej[state[rej] == 0]
        state[rej] = 2
        # Items where a rejected set was first: the first undecided set moves on.
        ent = entries_of(rej)
        p = ent[head[ent]] + 1
        while True:
            skip = p < end_of[p - 1]
            skip[skip] = state[e_set[p[skip]]] != 0
            if not skip.any():
                break
            p[skip] += 1
        p = p[p < end_of[p - 1]]
        head[p] = True
        gained = e_set[p]
        np.subtract.at(wait, gained, 1)
        frontier = sorted_unique(gained[wait[gained] == 0])
    return accept


def _ranges(lo: np.ndarray, n: np.ndarray) -> np.ndarray:
    """Concatenated ``arange(lo[k], lo[k] + n[k])``."""
    n = np.maximum(n, 0)
    total = int(n.sum())
    if total == 0:
        return np.zeros(0, np.int64)
    # Per run, its first value less its first position, spread over the run, plus the positions:
    # two arrays of the total at a time, where the three terms spread one by one held four.
    out = np.repeat(np.asarray(lo, np.int64) - (np.cumsum(n) - n), n)
    out += np.arange(total, dtype=np.int64)
    return out


def greedy_links(keys: list[np.ndarray], order: np.ndarray, size: int) -> np.ndarray:
    """Which items a greedy pass in ``order`` takes when an item blocks its key values.

    Item ``e`` is taken iff no earlier taken item has the same value in any of ``keys``
    (e.g. ``keys = [src, dst]``: every node keeps ≤ 1 successor and ≤ 1 predecessor).

    Parameters
    ----------
    keys : list of ndarray of int
        Per item, its value in each key (values in ``[0, size)``).
    order : ndarray of int
        The items to consider, best first (items not listed are never taken).
    size : int
        Bound on the key values.

    Returns
    -------
    ndarray of bool
        Per item, whether it is taken.
    """
    n, k = keys[0].size, len(keys)
    offsets = np.arange(n + 1, dtype=np.int64) * k
    # The entries are not named here: greedy_sets frees them once it has read them (19 of the
    # 241 MiB at the peak of the largest level of a 50,052-leaf grid).
    return greedy_sets(
        offsets,
        np.column_stack(
            [key.astype(np.int64, copy=False) + i * np.int64(size) for i, key in enumerate(keys)]
        ).ravel(),
        order,
    )


def greedy_disjoint(chains: Groups, order: np.ndarray, size: int) -> np.ndarray:
    """Which chains a greedy pass in ``order`` takes when taken chains must not share nodes.

    Groups that repeat a node are never taken.  ``size`` bounds the nodes (kept for callers:
    the keys no longer need it).  Returns a boolean mask over the chains.
    """
    if len(chains) == 0:
        return np.zeros(0, bool)
    # Groups repeating a node are equal neighbours in greedy_sets' sort of (node, rank) keys
    # (their own sort of (group, node) keys took a fifth of the linear sequences' time).
    return greedy_sets(chains.offsets, chains.nodes, np.asarray(order, np.int64), skip_repeating=True)
