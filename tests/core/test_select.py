"""Which candidates a level applies (:func:`lsys_core.hierarchy.select.choose`).

A reference written the plain way (every tie group found by scanning the whole rest of the
ordered list) is checked against the linear grouping of equal scores, on random candidates
with many ties, overlaps and rejections.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from lsys_core.hierarchy.candidates import Candidate, SeqCandidate
from lsys_core.hierarchy.select import WEAK_COVER, Weights, choose, importance_order


def _reference(
    cands: list[Candidate],
    weights: Weights,
    n_nodes: int,
    worthwhile: Callable[[Candidate], Candidate | None],
) -> list[Candidate]:
    """The candidate choice with each tie group found by a scan of the rest of the order."""
    score, order = importance_order(cands, weights)  # the same order: only the tie groups differ
    taken = np.zeros(n_nodes, bool)
    out: list[Candidate] = []
    k = 0
    while k < len(order):
        tied = [i for i in order[k:] if score[i] == score[order[k]]]
        k += len(tied)
        found = [
            c for i in tied if not taken[cands[i].nodes()].any() and (c := worthwhile(cands[i])) is not None
        ]
        for c in sorted(found, key=lambda c: (c.gain, c.covered, -c.start[0], -c.start[1]), reverse=True):
            if taken[c.nodes()].any():
                continue
            taken[c.nodes()] = True
            out.append(c)
            if out[0].covered >= WEAK_COVER * n_nodes:
                return out
    return out


def _candidate(nodes: list[int], h: float, start: float, gain: float) -> SeqCandidate:
    groups = tuple(np.array([n]) for n in nodes)
    return SeqCandidate(
        space=(0, 0), groups=groups, h=h, phi=1.0, l=1.0, A=1 + 0j, B=0j, start=(start, 0.0), gain=gain
    )


_CAND = st.tuples(
    st.lists(st.integers(0, 199), min_size=2, max_size=4, unique=True),
    st.sampled_from([0.25, 0.5, 1.0]),  # few distinct proximities: many equal importances
    st.integers(0, 5),
    st.sampled_from([-1.0, 1.0, 2.0, 3.0]),  # gain <= 0: not worthwhile
)


@settings(max_examples=200, deadline=None)
@given(st.lists(_CAND, min_size=1, max_size=40))
def test_choose_matches_the_plain_tie_scan(raw):
    cands = [_candidate(nodes, h, start, gain) for nodes, h, start, gain in raw]

    def worthwhile(c: Candidate) -> Candidate | None:
        return c if c.gain > 0 else None

    got = choose(cands, Weights(), 200, worthwhile)
    want = _reference(cands, Weights(), 200, worthwhile)
    assert [id(c) for c in got] == [id(c) for c in want]


def test_equal_importance_goes_by_bits_saved():
    small = _candidate([0, 1], 1.0, 0, gain=1.0)
    large = _candidate([1, 2], 1.0, 1, gain=5.0)  # same importance, overlaps ``small``, saves more
    other = _candidate([3, 4], 0.25, 2, gain=9.0)  # less important, disjoint
    got = choose([small, large, other], Weights(), 1000, lambda c: c)
    assert got == [large, other]


def test_a_candidate_that_saves_far_fewer_bits_yields_to_one_on_its_nodes():
    important = _candidate([0, 1], 1.0, 0, gain=0.5)  # close pairs: the most important, saves little
    rings = _candidate([1, 2, 3, 4], 0.25, 1, gain=100.0)  # less important, on one of its nodes
    modest = _candidate([4, 5], 0.25, 2, gain=20.0)

    def ceiling(c: Candidate) -> float:
        return c.gain

    assert choose([important, rings], Weights(), 6, lambda c: c, ceiling) == [rings]
    assert choose([important, rings], Weights(), 6, lambda c: c) == [important]  # importance alone
    # saving 4 times as much and 32 bits more: a candidate worth 20 bits keeps its place
    worth = _candidate([0, 4], 1.0, 0, gain=20.0)
    assert choose([worth, modest], Weights(), 6, lambda c: c, ceiling)[0] is worth
    # a candidate that saves more than a quarter of what its rivals save: importance decides
    paying = _candidate([0, 1], 1.0, 0, gain=40.0)
    assert choose([paying, rings], Weights(), 6, lambda c: c, ceiling) == [paying]


def test_a_candidate_yields_to_rivals_that_together_save_far_more():
    # a row of 13 ticks (nodes 0-12) and one of 12 grid lines (nodes 13-24); a branching of a
    # line, its neighbour and the tick below, three times, is the most important but saves far
    # less than the two rows it would cut (neither alone saves four times as much)
    ticks = _candidate(list(range(13)), 0.5, 1, gain=167.0)
    lines = _candidate(list(range(13, 25)), 0.5, 2, gain=133.0)
    branching = _candidate([13, 14, 0, 16, 17, 3, 19, 20, 6], 1.0, 0, gain=51.0)

    def ceiling(c: Candidate) -> float:
        return c.gain

    got = choose([branching, ticks, lines], Weights(), 25, lambda c: c, ceiling)
    assert got[0] is ticks
    # rivals that each save no more than the candidate do not add up against it
    small = [_candidate([13 + 3 * k, 14 + 3 * k], 0.5, 3 + k, gain=50.0) for k in range(3)]
    assert choose([branching, *small], Weights(), 25, lambda c: c, ceiling)[0] is branching


def test_node_index_lists_each_nodes_candidates_once_in_order() -> None:
    from lsys_core.hierarchy.rivals import node_index

    class Cand:
        def __init__(self, nodes: np.ndarray) -> None:
            self._nodes = nodes

        def nodes(self) -> np.ndarray:
            return self._nodes

    rng = np.random.default_rng(3)
    cands = [Cand(rng.integers(0, 40, rng.integers(1, 12))) for _ in range(300)]  # repeats within one
    owners, start = node_index(cands, 45)
    for k in range(45):
        want = [i for i, c in enumerate(cands) if k in c.nodes()]
        assert owners[start[k] : start[k + 1]].tolist() == want
    assert start[-1] == owners.size
    empty_owners, empty_start = node_index([], 3)
    assert empty_owners.size == 0 and empty_start.tolist() == [0, 0, 0, 0]


def test_rivals_by_scan_and_by_index_are_the_candidates_on_the_nodes() -> None:
    from lsys_core.hierarchy.rivals import SCANS, Rivals

    class Cand:
        def __init__(self, nodes: np.ndarray) -> None:
            self._nodes = nodes

        def nodes(self) -> np.ndarray:
            return self._nodes

    rng = np.random.default_rng(5)
    cands = [Cand(rng.integers(0, 60, rng.integers(1, 15))) for _ in range(200)]  # repeats within one
    rivals = Rivals(cands, 64)
    for q in range(3 * SCANS):  # the first SCANS by scanning, the rest from the index
        asked = rng.integers(0, 64, rng.integers(0, 30) if q % 5 else 64)
        want = [i for i, c in enumerate(cands) if np.isin(c.nodes(), asked).any()]
        got = rivals.on(asked)
        assert got.dtype == np.int64 and got.tolist() == want
    assert Rivals([], 5).on(np.array([1, 2])).size == 0
