"""Unit tests of the hierarchy's stages on small constructed inputs (nodes, chains, candidates, rules)."""

from __future__ import annotations

import numpy as np

from lsys_core.geometry.transforms import rel_from_t4
from lsys_core.grammar.model import Count, Pop, Push, Symbol, Turtle
from lsys_core.hierarchy.analysis import find_candidates
from lsys_core.hierarchy.branching import branch_candidates
from lsys_core.hierarchy.candidates import (
    BranchCandidate,
    ConstantCluster,
    LinearCandidate,
    PairCandidate,
    SeqCandidate,
)
from lsys_core.hierarchy.chains import chains, edge_chains, follow, successor_pairs
from lsys_core.hierarchy.clustering import group_indices
from lsys_core.hierarchy.emit import const_t, emit, nice
from lsys_core.hierarchy.flat import Groups
from lsys_core.hierarchy.nodes import Nodes
from lsys_core.hierarchy.rules import Tolerance, _Context
from lsys_core.hierarchy.spaces import pair_space
from lsys_core.hierarchy.symbols import SymbolTable


def _table(n: int = 2, size: float = 1.0) -> SymbolTable:
    names = [chr(ord("A") + i) for i in range(n)]
    return SymbolTable(names, np.full(n, size), np.eye(n))


def _sequence_frames(n: int, step, start=(1 + 0j, 0j)):
    A, B = (complex(v) for v in rel_from_t4(*step))
    a, b = start
    out = []
    for _ in range(n):
        out.append((a, b))
        a, b = a * A, b + a * B
    return np.array([f[0] for f in out]), np.array([f[1] for f in out])


# -- clustering helpers ------------------------------------------------------------------------


def test_group_indices_drops_noise_and_keeps_label_order() -> None:
    groups = group_indices(np.array([1, 0, -1, 1, 0, 2]))
    assert [g.tolist() for g in groups] == [[1, 4], [0, 3], [5]]


# -- nodes -------------------------------------------------------------------------------------


def test_nodes_merge_replaces_groups_by_their_first_node() -> None:
    a = np.array([1, 1j, 2, 1], complex)
    b = np.array([0, 10, 20, 30], complex)
    nodes = Nodes.of_elements(np.zeros(4, int), a, b, b, np.ones(4))
    merged, mapping = nodes.merge([np.array([2, 1])], [7])
    assert mapping.tolist() == [0, -1, -1, 1]
    assert len(merged) == 3
    assert merged.sym.tolist() == [0, 0, 7]
    assert merged.a[2] == 2 and merged.b[2] == 20  # pose of the group's first node
    assert merged.center[2] == 15 and merged.radius[2] == 6  # circle around both
    assert merged.members[2].tolist() == [2, 1]
    assert nodes.first_members().tolist() == [0, 1, 2, 3]
    assert merged.first_members().tolist() == [0, 3, 1]


def test_first_members_is_each_nodes_smallest_element() -> None:
    rng = np.random.default_rng(2)
    members = tuple(rng.permutation(50)[: rng.integers(1, 7)] for _ in range(300))
    n = len(members)
    z = np.zeros(n, complex)
    nodes = Nodes(np.zeros(n, np.int64), z + 1, z, z, np.ones(n), members, np.ones(n))
    assert nodes.first_members().tolist() == [int(m.min()) for m in members]
    assert (
        Nodes(z[:0].real.astype(np.int64), z[:0], z[:0], z[:0], z[:0].real, (), z[:0].real)
        .first_members()
        .size
        == 0
    )


# -- chains ------------------------------------------------------------------------------------


def test_chains_link_pairs_and_keep_rings_whole() -> None:
    src = np.array([0, 1, 2, 5, 6, 7])
    dst = np.array([1, 2, 3, 6, 7, 5])
    found, succ = chains(src, dst, np.zeros(6))
    assert found == [[0, 1, 2, 3], [5, 6, 7]]
    assert succ[2] == 3


def test_chains_give_each_node_one_successor_cheapest_first() -> None:
    found, _ = chains(np.array([0, 0]), np.array([1, 2]), np.array([1.0, 0.5]))
    assert found == [[0, 2]]


def test_follow_and_edge_chains() -> None:
    paths, loops = follow({1: 2, 2: 3, 7: 8, 8: 7}, [1])
    assert paths == [[1, 2, 3]] and loops == [[7, 8]]
    assert edge_chains(np.array([0, 1]), np.array([1, 2])) == [[0, 1, 2]]


def test_successor_pairs_find_consecutive_pairs_only() -> None:
    src = np.array([0, 1, 1])
    dst = np.array([1, 2, 0])
    e1, e2 = successor_pairs(src, dst, np.arange(3))
    assert list(zip(e1.tolist(), e2.tolist(), strict=True)) == [(0, 1)]  # 0→1 then 1→2 (not back to 0)


# -- candidates ----------------------------------------------------------------------------------


def _candidates(a, b, sym, table, tol: Tolerance | None = None):
    tol = tol or Tolerance()
    radius = np.full(a.size, 0.5)
    ps = pair_space(a, b, b, radius, k=8)
    return find_candidates(_Context(table, tol), np.asarray(sym), ps, radius)


def test_a_row_gives_one_sequence_candidate_with_its_step() -> None:
    a, b = _sequence_frames(6, (0.0, 3.0, 1.0, 0.0))
    cands = _candidates(a, b, np.zeros(6, int), _table(1))
    seqs = [c for c in cands if isinstance(c, SeqCandidate) and len(c.groups) == 1 and c.covered == 6]
    assert len(seqs) == 2  # read forwards and backwards
    assert sorted(c.B.real for c in seqs) == [-3, 3] and all(abs(c.A - 1) < 1e-9 for c in seqs)
    assert all(c.repeats == 5 and c.l == 5 for c in seqs)
    # every second element: two interleaved sequences of 3
    assert any(isinstance(c, SeqCandidate) and len(c.groups) == 2 and abs(abs(c.B) - 6) < 1e-9 for c in cands)


def test_two_symbols_alternating_give_pairs_with_the_alternation_length() -> None:
    b = np.arange(8) * 2.0 + 0j
    sym = np.arange(8) % 2
    cands = _candidates(np.ones(8, complex), b, sym, _table(2))
    pairs = [c for c in cands if isinstance(c, PairCandidate) and c.space == (0, 1)]
    assert pairs
    assert max(c.l for c in pairs) > 1  # A B A B … : the pairs start alternating sequences


def test_a_turning_row_gives_a_linear_candidate() -> None:
    # unturned copies along a path that turns 10° more at every step: α = 10°·k, β = -α
    b = np.concatenate([[0], np.cumsum(3.0 * np.exp(1j * np.deg2rad(10.0 * np.arange(8))))])
    cands = _candidates(np.ones(9, complex), b, np.zeros(9, int), _table(1))
    lins = [c for c in cands if isinstance(c, LinearCandidate)]
    assert lins
    assert any(abs(abs(c.d_alpha) - 10.0) < 0.5 or abs(abs(c.d_beta) - 10.0) < 0.5 for c in lins)


def test_branch_candidates_build_full_binary_trees() -> None:
    # node 0 branches to 1 and 2, 1 to 3 and 4, 2 to 5 and 6 (depth 2)
    left = {0: 1, 1: 3, 2: 5}
    right = {0: 2, 1: 4, 2: 6}
    n = 7
    ps = pair_space(np.ones(n, complex), np.arange(n) + 0j, np.arange(n) + 0j, np.ones(n), k=6)
    look = {(int(s), int(d)): k for k, (s, d) in enumerate(zip(ps.src, ps.dst, strict=True))}
    idx1 = np.array([look[(s, d)] for s, d in left.items()])
    idx2 = np.array([look[(s, d)] for s, d in right.items()])
    clusters = {
        (0, 0): [
            ConstantCluster((0, 0), idx1, np.array(list(left)), np.array(list(left.values()))),
            ConstantCluster((0, 0), idx2, np.array(list(right)), np.array(list(right.values()))),
        ]
    }
    found = branch_candidates(ps, clusters, np.ones(len(ps)), n)
    assert len(found) == 1
    tree = found[0]
    assert isinstance(tree, BranchCandidate)
    assert (
        tree.depths == (2,) and tree.groups[0][0] == 0 and sorted(tree.groups[0].tolist()) == list(range(7))
    )


# -- rule writing ------------------------------------------------------------------------------


def test_nice_and_const_t_write_short_values_without_identities() -> None:
    assert nice(45.0000049, abs_tol=1e-5) == 45.0
    assert const_t(1 + 0j, 0j) == ()
    mods = const_t(1 + 0j, 3 + 0j)
    assert len(mods) == 1 and isinstance(mods[0], Turtle) and mods[0].op == "f" and mods[0].value.c0 == 3


def test_emit_sequence_registers_one_symbol_per_length() -> None:
    table = _table(1)
    cand = SeqCandidate(
        space=(0, 0), groups=(np.array([0, 1, 2]), np.array([3, 4])), h=1, phi=1, l=1.5, A=1 + 0j, B=2 + 0j
    )
    out = emit(table, cand)
    assert out.rule.parametric and out.rule.name == "P1" and len(out.rule.cases) == 2
    assert [table.infos[s].m for s in out.syms] == [2, 1]
    gt = out.rule.cases[0].body
    assert gt[0] == Symbol("A") and gt[-1] == Symbol("P1", Count(-1, 1))
    assert table.draw(out.syms[0]) == (Push(), Symbol("P1", Count(2)), Pop())


def test_symbol_table_names_avoid_terminal_names() -> None:
    table = SymbolTable(["Z", "P1"], np.ones(2), np.eye(2))
    assert table.new_name("Z") == "Z1"
    assert table.new_name("P") == "P2"
    assert table.phi(0, 0) == 1.0 and table.phi(0, 1) == 0.0


def test_candidate_holds_its_groups_flat_and_renumbers_them() -> None:
    cand = SeqCandidate(
        space=(0, 0), groups=(np.array([4, 1, 2]), np.array([0, 3])), h=1, phi=1, l=1.5, A=1 + 0j, B=2 + 0j
    )
    assert isinstance(cand.groups, Groups)
    assert cand.groups.nodes.tolist() == [4, 1, 2, 0, 3] and cand.groups.offsets.tolist() == [0, 3, 5]
    assert cand.covered == 5 and cand.repeats == 3 and cand.nodes().tolist() == [4, 1, 2, 0, 3]
    assert not cand.nodes().flags.writeable
    moved = cand.remapped(np.array([10, 11, 12, 13, 14]))
    assert [g.tolist() for g in moved.groups] == [[14, 11, 12], [10, 13]]
    assert [g.tolist() for g in cand.groups] == [[4, 1, 2], [0, 3]]  # the original is untouched


def test_shared_places_is_whether_two_entries_are_equal_in_both() -> None:
    from lsys_core.hierarchy.rules import _shared_places

    rng = np.random.default_rng(4)
    for n in (0, 1, 2, 5, 40, 300):
        for spread in (3, 30, 10**6):
            x = rng.integers(0, spread, n).astype(float)
            y = rng.integers(0, spread, n).astype(float)
            want = np.unique(np.column_stack([x, y]), axis=0).shape[0] < n
            assert _shared_places(x, y) == want
    assert _shared_places(np.array([0.0, -0.0]), np.array([1.0, 1.0]))  # as ``np.unique`` groups them
    assert not _shared_places(np.array([np.nan, np.nan]), np.array([1.0, 1.0]))


def test_duplicates_stacks_copies_drawn_at_one_pose() -> None:
    from lsys_core.hierarchy.rules import _duplicates
    from lsys_core.hierarchy.symbols import SymbolTable

    table = SymbolTable(["A", "B"], np.ones(2), np.eye(2))
    b = np.array([0, 5, 0, 5, 0, 9], complex)
    a = np.array([1, 1, 1, 1j, 1, 1], complex)
    sym = np.array([0, 0, 0, 0, 1, 0])
    nodes = Nodes.of_elements(sym, a, b, b, np.ones(6))
    got = _duplicates(table, nodes)
    assert [c.groups.nodes.tolist() for c in got] == [[0, 2]]  # same place and turn, same symbol
    assert _duplicates(table, Nodes.of_elements(sym[:2], a[:2], b[:2], b[:2], np.ones(2))) == []
