"""What a candidate rule would save, in bits, and how far its derivation would move the nodes.

The baseline is the grammar that places every live node one by one (the catch-all rule,
coded as one set of placements per symbol family, :mod:`lsys_core.hierarchy.mdl`).  Applying a
candidate takes its nodes out of their sets, adds one placement per application to a new
set (with its counter), and writes the rule.  The candidate is worth applying only when that
is shorter (a positive *gain*) and when the rule, derived from each application's first node,
puts every node within the tolerance of where it was drawn.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from lsys_core.geometry.transforms import rel_from_t4
from lsys_core.grammar.model import Rule
from lsys_core.hierarchy.candidates import (
    BranchCandidate,
    Candidate,
    LinearCandidate,
    PairCandidate,
    SeqCandidate,
)
from lsys_core.hierarchy.describe import rule_bits, structured_bits, symbol_bits
from lsys_core.hierarchy.emit import counters, rule_cases
from lsys_core.hierarchy.flat import Groups, as_groups
from lsys_core.hierarchy.mdl import (
    KIND_BITS,
    Precision,
    count_bits,
    placement_set_bits,
    pose_bits,
    stack_table,
    token_bits,
    transform_bits,
)
from lsys_core.hierarchy.nodes import Nodes
from lsys_core.hierarchy.symbols import SymbolTable
from lsys_core.sorting import distinct_counts, sorted_unique

__all__ = ["Ledger", "cluster_bounds", "group_reach", "placement_error"]

#: Bits of a transform whose offset, turn and scale are all zero: its four flags
#: (:func:`~lsys_core.hierarchy.mdl.transform_bits`, the least any transform costs).
_FLAGS = 4.0


class Ledger:
    """The description of one level's live nodes placed one by one, and the gain of candidates.

    Parameters
    ----------
    prec : Precision
        The precision (tolerance) of the description.
    nodes : Nodes
        The live nodes.
    table : SymbolTable
        Their symbols.
    """

    def __init__(self, prec: Precision, nodes: Nodes, table: SymbolTable):
        self.prec = prec
        self.nodes = nodes
        self.table = table
        fam_of_sym = table.families()
        self.family = fam_of_sym[nodes.sym]
        n_fam = int(fam_of_sym.max()) + 1 if fam_of_sym.size else 0
        self.token = token_bits(n_fam + 1)
        self.count = np.bincount(self.family, minlength=n_fam)
        m = np.array([-1 if s.m is None else s.m for s in table.infos])[nodes.sym]
        self.node_counts = np.where(m >= 0, count_bits(np.maximum(m, 0)), 0.0)
        self.counts = np.bincount(self.family, self.node_counts, minlength=n_fam)
        # the cell of every node, numbered per family, and how many nodes of its family share it
        cell = prec.cell_ids(nodes.b)
        key = np.unique(np.column_stack([self.family, cell]), axis=0, return_inverse=True)[1].ravel()
        self.cell = key
        self.stacked = np.bincount(key)
        #: whether every node has a cell of its own
        self.single = bool(self.stacked.size == 0 or self.stacked.max() == 1)
        self.key_family = np.zeros(self.stacked.size, int)
        self.key_family[key] = self.family
        self.occupied = np.bincount(self.key_family, minlength=n_fam)
        self.headings = np.zeros(n_fam)
        self.scale = np.zeros(n_fam)
        order = np.argsort(self.family, kind="stable")
        cuts = np.flatnonzero(np.diff(self.family[order])) + 1
        for grp in np.split(order, cuts):
            if grp.size:
                f = int(self.family[grp[0]])
                lever = np.abs(nodes.center[grp] - nodes.b[grp]) + nodes.radius[grp]
                self.headings[f], self.scale[f] = prec.pose_model(nodes.a[grp], lever)
        by_family = np.argsort(self.key_family, kind="stable")
        cuts = np.searchsorted(self.key_family[by_family], np.arange(n_fam + 1))
        #: the keys of every family, increasing (what ``key_family == f`` selects)
        self.family_keys = [by_family[cuts[f] : cuts[f + 1]] for f in range(n_fam)]
        #: per family, how many of its cells hold 0, 1, 2, … of its nodes, and how many nodes
        self.heights = [np.bincount(self.stacked[keys]) for keys in self.family_keys]
        self.stacked_sum = np.bincount(self.key_family, self.stacked, minlength=n_fam).astype(np.int64)
        #: per family, ``log2 C(max(headings, k), k)`` for every height ``k`` (None: no headings)
        self.tables = [
            stack_table(float(self.headings[f]), self.heights[f].size - 1) if self.headings[f] > 0 else None
            for f in range(n_fam)
        ]
        #: the bits of every family's whole set (what :meth:`_moved` subtracts from), by family
        self._whole: dict[int, float] = {}
        self._last: tuple[Groups, tuple[float, float, np.ndarray, np.ndarray]] | None = None
        #: what :meth:`ceilings` found each candidate's nodes save, by their groups (its rounded
        #: variants keep them), for :meth:`gain`
        self._saved: dict[int, tuple[Groups, float]] = {}
        self.pose = np.array(
            [self._key_pose(f, int(self.stacked_sum[f]), self.heights[f]) for f in range(n_fam)]
        )

    def _key_pose(self, f: int, total: int, heights: np.ndarray) -> float:
        """:func:`~lsys_core.hierarchy.mdl.pose_bits` of ``total`` nodes of family ``f`` in cells of these ``heights``.

        ``heights[k]`` cells hold ``k`` nodes each.  The terms ``log2 C(max(headings, k), k)``
        come from a table (:func:`~lsys_core.hierarchy.mdl.stack_table`), one product per
        height: a candidate changes the heights of its own cells only, so pricing it takes
        time in proportion to its nodes, not to the family's cells (with one term per cell,
        choosing among the 66,000 candidates of a 4,817-element chart's levels took 5.6 s).
        The sum is the same as one per cell up to rounding; :meth:`_savings` forms it in the
        same operations for many candidates at once.
        """
        bits = float(total) * float(self.scale[f])
        table = self.tables[f]
        if table is not None:
            bits += float((table * heights).sum())
        return bits

    def _family_bits(self, f, n, counts, occupied=None, pose=None):
        u = self.occupied[f] if occupied is None else occupied
        p = self.pose[f] if pose is None else pose
        return placement_set_bits(self.prec, n, occupied=u, pose=p, counts=counts, token=self.token)

    def removal(self, fam: np.ndarray, k: np.ndarray) -> np.ndarray:
        """Bits saved by taking ``k`` nodes out of the sets of families ``fam``, at best (an upper bound)."""
        fam = np.asarray(fam, int)
        n = self.count[fam]
        k = np.minimum(np.asarray(k), n)
        u = self.occupied[fam]
        share = np.where(n > 0, (n - k) / np.maximum(n, 1), 0.0)
        per = np.log2(np.maximum(self.headings[fam], 1.0)) + self.scale[fam]
        before = self._family_bits(fam, n, self.counts[fam], u, 0.0)
        after = self._family_bits(fam, n - k, self.counts[fam] * share, np.maximum(u - k, 0), 0.0)
        return before - after + k * per

    def bound(
        self, fam_a: np.ndarray, k_a: np.ndarray, fam_b: np.ndarray, k_b: np.ndarray, groups
    ) -> np.ndarray:
        """An optimistic gain: ``k_a``/``k_b`` nodes of families ``fam_a``/``fam_b`` (-1: none) in ``groups``.

        The new set is charged without headings or counters and the rule as one symbol and
        no numbers, so a candidate whose bound is not positive cannot pay for itself.
        """
        saved = self.removal(fam_a, k_a) + np.where(fam_b >= 0, self.removal(np.maximum(fam_b, 0), k_b), 0.0)
        new = placement_set_bits(self.prec, groups, token=self.token)
        return saved - new - (self.token + KIND_BITS)

    def gain(self, c: Candidate) -> float:
        """Bits saved by applying ``c`` (positive: the description gets shorter).

        When ``c`` cannot pay, the value returned is not positive but may be less negative than
        the exact loss: the new set is first priced without its headings, scales and counters
        (at a 4,817-element chart, 36,000 candidates were priced and 296 paid).
        """
        saved, new, first, stacks = self._moved(c)
        rule = self.rule_bits(c)
        least = saved - new - rule
        if least <= 0.0:
            return least  # headings, scales and counters only add bits: it cannot pay
        ms = [m for m in counters(c) if m is not None]
        pose = pose_bits(
            *self.prec.pose_model(self.nodes.a[first], group_reach(self.nodes, c.groups)), stacks
        )
        new = placement_set_bits(
            self.prec,
            len(c.groups),
            occupied=stacks.size,
            pose=pose,
            counts=float(np.sum(count_bits(ms))) if ms else 0.0,
            token=self.token,
        )
        return saved - new - rule

    def ceiling(self, c: Candidate) -> float:
        """A gain no rounding of ``c``'s numbers can exceed (its nodes and groups stay; not positive: it cannot pay).

        The rule is charged its kind, symbols and the flags of its transforms (nothing for rules
        not of the paper's kinds) and the new set no headings, scales or counters.
        """
        saved, new, _, _ = self._moved(c)
        return saved - new - self._least_rule_bits(c)

    def _least_rule_bits(self, c: Candidate) -> float:
        """What :meth:`rule_bits` gives at least, whatever the numbers: a transform costs its 4 flags."""
        si, sj = c.space
        refs = [symbol_bits(self.token, self.table.ref(si))]
        if isinstance(c, PairCandidate):
            refs.append(symbol_bits(self.token, self.table.ref(sj)))
        if isinstance(c, (SeqCandidate, PairCandidate)):
            return structured_bits(self.prec, self.token, refs, [_FLAGS])
        if isinstance(c, BranchCandidate):
            return structured_bits(self.prec, self.token, refs, [_FLAGS, _FLAGS])
        return 0.0

    def _moved(self, c: Candidate) -> tuple[float, float, np.ndarray, np.ndarray]:
        """Bits saved taking ``c``'s nodes out of their sets, and of its new set without poses or counters.

        Also its groups' first nodes and how many share each cell.  Remembered for the last
        groups: a candidate and its rounded variants share them.
        """
        if self._last is not None and self._last[0] is c.groups:
            return self._last[1]
        known = self._saved.get(id(c.groups))
        saved = known[1] if known is not None and known[0] is c.groups else float(self._savings([c])[0])
        first = c.groups.firsts
        stacks = _run_lengths(np.sort(self.cell[first]))  # np.unique(..., return_counts=True)[1]
        new = placement_set_bits(self.prec, len(c.groups), occupied=stacks.size, token=self.token)
        out = (saved, float(new), first, stacks)
        self._last = (c.groups, out)
        return out

    def _whole_bits(self, f: int) -> float:
        """Bits of family ``f``'s whole set (remembered)."""
        before = self._whole.get(f)
        if before is None:
            before = self._whole[f] = self._family_bits(f, int(self.count[f]), float(self.counts[f]))
        return before

    def ceilings(self, cands: Sequence[Candidate]) -> np.ndarray:
        """:meth:`ceiling` of every candidate of ``cands``, bit for bit, in one pass over all of them.

        The sets of a level's families and their cell heights are priced for every candidate at
        once (numpy over all their nodes) instead of one candidate at a time: choosing among the
        66,000 candidates of a 4,817-element chart's levels asked 66,000 ceilings.
        """
        m = len(cands)
        if m == 0:
            return np.zeros(0)
        saved = self._savings(cands)
        self._saved.update((id(c.groups), (c.groups, v)) for c, v in zip(cands, saved.tolist(), strict=True))
        n_keys = self.stacked.size
        n_groups = np.fromiter((len(c.groups) for c in cands), np.int64, m)
        if self.single:  # distinct first nodes, distinct cells
            occupied = n_groups
        else:
            firsts = np.concatenate([c.groups.firsts for c in cands])
            occupied = distinct_counts(np.repeat(np.arange(m), n_groups), self.cell[firsts], m, n_keys)
        new = placement_set_bits(
            self.prec, n_groups.astype(float), occupied=occupied.astype(float), token=self.token
        )
        least: dict[tuple[type, tuple[int, int]], float] = {}  # by kind and space
        for c in cands:
            if (type(c), c.space) not in least:
                least[type(c), c.space] = self._least_rule_bits(c)
        rules = np.array([least[type(c), c.space] for c in cands])
        return saved - new - rules

    def _savings(self, cands: Sequence[Candidate]) -> np.ndarray:
        """Bits saved taking every candidate's nodes out of their families' sets (see :meth:`_moved`).

        Per candidate and family, the family's set is priced again with its cell heights less
        the candidate's nodes (:meth:`_key_pose`, the same operations on rows of heights), all
        candidates at once; the savings of a candidate's families are added in increasing order.
        """
        m = len(cands)
        sizes = np.fromiter((c.nodes().size for c in cands), np.int64, m)
        nodes = np.concatenate([c.nodes() for c in cands])
        owner = np.repeat(np.arange(m), sizes)
        n_fam, n_keys = self.count.size, self.stacked.size
        family = self.family[nodes]
        # one row per candidate and family it takes nodes from, families in increasing order
        heads = np.cumsum(sizes) - sizes
        if sizes.min() > 0 and np.array_equal(family, family[heads][owner]):  # each in one family
            row, cand, fam = owner, np.arange(m), family[heads]
        else:
            pairs, row = np.unique(owner * n_fam + family, return_inverse=True)
            cand, fam = np.divmod(pairs, n_fam)
        k = np.bincount(row, minlength=cand.size)
        gone = np.bincount(row, self.node_counts[nodes], minlength=cand.size)  # whole numbers: exact
        # every row's cells and how many nodes each loses (a node a cell: the nodes themselves)
        if self.single:
            hit_row, key, taken = row, self.cell[nodes], np.ones(nodes.size, np.int64)
        else:
            hit = np.sort(row * n_keys + self.cell[nodes])
            taken = _run_lengths(hit)
            hit_row, key = np.divmod(hit[np.cumsum(taken) - 1], n_keys)
        stacks = self.stacked[key]
        u = self.occupied[fam] - np.bincount(hit_row[stacks == taken], minlength=cand.size)
        pose = (self.stacked_sum[fam] - k).astype(float) * self.scale[fam]
        present = sorted_unique(fam).tolist()
        hit_fam = fam[hit_row]
        for f in present:
            table = self.tables[f]
            if table is None:
                continue
            rows = np.flatnonzero(fam == f)
            local = np.full(cand.size, -1)
            local[rows] = np.arange(rows.size)
            mine = hit_fam == f
            width = table.size
            at = local[hit_row[mine]] * width
            moved = np.bincount(at + stacks[mine] - taken[mine], minlength=rows.size * width) - np.bincount(
                at + stacks[mine], minlength=rows.size * width
            )
            heights = self.heights[f] + moved.reshape(rows.size, width)
            pose[rows] = pose[rows] + (table * heights).sum(axis=1)
        whole = np.zeros(n_fam)
        whole[present] = [self._whole_bits(f) for f in present]  # only the families taken from
        before = whole[fam]
        after = placement_set_bits(
            self.prec,
            (self.count[fam] - k).astype(float),
            occupied=u.astype(float),
            pose=pose,
            counts=self.counts[fam] - gone,
            token=self.token,
        )
        return np.bincount(cand, before - after, minlength=m)

    def rule_bits(self, c: Candidate) -> float:
        """Bits of the rule candidate ``c`` would write."""
        si, sj = c.space
        refs = [symbol_bits(self.token, self.table.ref(si))]
        if isinstance(c, PairCandidate):
            refs.append(symbol_bits(self.token, self.table.ref(sj)))
            return structured_bits(self.prec, self.token, refs, [transform_bits(self.prec, c.A, c.B)])
        if isinstance(c, SeqCandidate):
            return structured_bits(self.prec, self.token, refs, [transform_bits(self.prec, c.A, c.B)])
        if isinstance(c, BranchCandidate):
            runs = [transform_bits(self.prec, *c.first), transform_bits(self.prec, *c.second)]
            return structured_bits(self.prec, self.token, refs, runs)
        return rule_bits(self.prec, self.token, Rule("_", True, rule_cases(self.table, c, "_")))


def _run_lengths(s: np.ndarray) -> np.ndarray:
    """The lengths of the runs of equal values of a sorted array (``np.unique``'s counts, without hashing)."""
    if s.size == 0:
        return np.zeros(0, np.intp)
    change = np.flatnonzero(s[1:] != s[:-1])
    bounds = np.empty(change.size + 2, np.intp)
    bounds[0], bounds[-1] = -1, s.size - 1
    bounds[1:-1] = change
    return bounds[1:] - bounds[:-1]


def group_reach(nodes: Nodes, groups: Groups | Sequence[np.ndarray]) -> np.ndarray:
    """How far every group's geometry reaches from its first node's origin (the lever of its heading)."""
    groups = as_groups(groups)
    flat, owner = groups.nodes, groups.owner()
    origin = nodes.b[groups.firsts]
    reach = np.zeros(len(groups))
    np.maximum.at(reach, owner, np.abs(nodes.center[flat] - origin[owner]) + nodes.radius[flat])
    return reach


def cluster_bounds(ledger: Ledger, labels: np.ndarray, src: np.ndarray, dst: np.ndarray) -> np.ndarray:
    """The optimistic gain (:meth:`Ledger.bound`) of every cluster of pairs ``src → dst``.

    A cluster of ``c`` pairs on ``u`` distinct nodes of one family forms at least ``u - c``
    chains; pairs of two families are ``min(sources, targets)`` pairs at most.
    """
    n_lab = int(labels.max()) + 1 if labels.size else 0
    ok = labels >= 0
    lab, s, d = labels[ok], src[ok], dst[ok]
    c = np.bincount(lab, minlength=n_lab)
    n = len(ledger.nodes)

    both = distinct_counts(np.concatenate([lab, lab]), np.concatenate([s, d]), n_lab, n)
    n_src, n_dst = distinct_counts(lab, s, n_lab, n), distinct_counts(lab, d, n_lab, n)
    fam_s = np.zeros(n_lab, int)
    fam_d = np.zeros(n_lab, int)
    fam_s[lab] = ledger.family[s]
    fam_d[lab] = ledger.family[d]
    same = fam_s == fam_d
    pairs = np.minimum(n_src, n_dst)
    chained = ledger.bound(fam_s, both, np.full(n_lab, -1), np.zeros(n_lab), np.maximum(both - c, 1))
    paired = ledger.bound(fam_s, pairs, np.where(same, -1, fam_d), pairs, pairs)
    return np.where(same, np.maximum(chained, paired), paired)


def _pose_error(
    nodes: Nodes, idx: np.ndarray, a_pred: np.ndarray, b_pred: np.ndarray, sizes, period
) -> np.ndarray:
    """Displacement (translation plus rotation/scale at the rim) of nodes from predicted poses."""
    sym = nodes.sym[idx]
    ratio = nodes.a[idx] / a_pred
    p = period[sym]
    ang = np.angle(ratio)
    ang = np.where(p > 0, ang - np.round(ang / np.where(p > 0, p, 1.0)) * p, ang)
    ratio = np.where(p < 0, np.abs(ratio), np.abs(ratio) * np.exp(1j * ang))
    return np.abs(b_pred - nodes.b[idx]) + np.abs(a_pred) * np.abs(ratio - 1.0) * sizes[sym]


def _chain_poses(nodes: Nodes, groups, A: complex, B: complex, lever: np.ndarray, own_scale: float = 0.0):
    """Poses the sequences ``P(m) -> X T P(m-1)`` derive, from the start that fits each group best.

    The start of every application is the pose ``(a0, b0)`` minimising the squared
    displacements (positions, and turns/scales at each node's ``lever``) of all its nodes, not
    the first node's own pose: a jittered first element would otherwise tilt the whole row.
    A start whose scale is within the relative ``own_scale`` of its first node's keeps that
    node's scale (only its turn and place are fitted): a rule does not start at a scale of
    1.00002 to absorb rounding.
    """
    groups = as_groups(groups)
    idx, owner = groups.nodes, groups.owner()
    k = groups.positions().astype(float)
    u = A**k
    v = B * (k if abs(A - 1) < 1e-12 else (u - 1.0) / (A - 1.0))
    a, b, r2 = nodes.a[idx], nodes.b[idx], lever**2
    n = len(groups)

    def total(x: np.ndarray) -> np.ndarray:
        return np.bincount(owner, x.real, n) + 1j * np.bincount(owner, x.imag, n)

    p = np.bincount(owner, r2 * np.abs(u) ** 2 + np.abs(v) ** 2, n)
    sv, count = total(v), np.bincount(owner, minlength=n)
    rhs_a, rhs_b = total(r2 * np.conj(u) * a + np.conj(v) * b), total(b)
    det = p * count - np.abs(sv) ** 2
    ok = np.abs(det) > 1e-12 * np.maximum(p * count, 1e-300)
    a0 = np.where(
        ok,
        (rhs_a * count - np.conj(sv) * rhs_b) / np.where(ok, det, 1.0),
        nodes.a[idx[np.searchsorted(owner, np.arange(n))]],
    )
    if own_scale > 0.0:
        own = np.abs(nodes.a[idx[np.searchsorted(owner, np.arange(n))]])
        near = ok & (np.abs(np.abs(a0) - own) <= own_scale * own) & (np.abs(a0) > 0)
        a0 = np.where(near, a0 / np.where(near, np.abs(a0), 1.0) * own, a0)
    b0 = np.where(
        ok, (rhs_b - sv * a0) / np.maximum(count, 1), nodes.b[idx[np.searchsorted(owner, np.arange(n))]]
    )
    return idx, a0[owner] * u, b0[owner] + a0[owner] * v, (a0, b0)


def _linear_poses(nodes: Nodes, c: LinearCandidate):
    g = c.groups.nodes.reshape(len(c.groups), -1)  # all of one length: steps + 1
    a = nodes.a[g[:, 0]].copy()
    b = nodes.b[g[:, 0]].copy()
    pa, pb = [a.copy()], [b.copy()]
    for j in range(g.shape[1] - 1):
        A, B = rel_from_t4(c.alpha0 + j * c.d_alpha, c.d, c.s, c.beta0 + j * c.d_beta)
        a, b = a * complex(A), b + a * complex(B)
        pa.append(a.copy())
        pb.append(b.copy())
    return g.ravel(), np.stack(pa, axis=1).ravel(), np.stack(pb, axis=1).ravel()


def _tree_poses(nodes: Nodes, c: BranchCandidate):
    (A1, B1), (A2, B2) = c.first, c.second
    idx, pa, pb = [], [], []
    for tree, depth in zip(c.groups, c.depths, strict=True):
        a = nodes.a[tree[:1]]
        b = nodes.b[tree[:1]]
        start = 0
        for level in range(depth + 1):
            width = 1 << level
            idx.append(tree[start : start + width])
            pa.append(a)
            pb.append(b)
            start += width
            a, b = np.concatenate([a * A1, a * A2]), np.concatenate([b + a * B1, b + a * B2])
    return np.concatenate(idx), np.concatenate(pa), np.concatenate(pb)


def placement_error(
    c: Candidate, nodes: Nodes, sizes: np.ndarray, period: np.ndarray, *, own_scale: float = 0.0
) -> tuple[np.ndarray, np.ndarray, tuple[np.ndarray, np.ndarray] | None, tuple[np.ndarray, np.ndarray]]:
    """Distance between every node of ``c`` and where the candidate's rule would derive it.

    Parameters
    ----------
    c : Candidate
        The candidate.
    nodes : Nodes
        The live nodes.
    sizes : ndarray
        Radius of every symbol in its own frame.
    period : ndarray
        Per symbol, the rotation (radians) that maps its shape onto itself: 0 for none,
        negative for any rotation (a circle).
    own_scale : float
        Sequences and pairs whose best start is within this relative scale of their first
        node's start at that node's scale (see :func:`_chain_poses`).

    Returns
    -------
    idx, err : ndarray
        The nodes, group after group, and their distances (document units).
    starts : tuple of ndarray, or None
        For sequences and pairs, the pose ``(a0, b0)`` every application starts from (fitted
        to all its nodes); None where the application starts at its first node.
    derived : tuple of ndarray
        The poses ``(a, b)`` the rule derives for the nodes.
    """
    starts = None
    if isinstance(c, (SeqCandidate, PairCandidate)):
        lever = sizes[nodes.sym[c.groups.nodes]]
        idx, pa, pb, starts = _chain_poses(nodes, c.groups, c.A, c.B, lever, own_scale)
    elif isinstance(c, LinearCandidate):
        idx, pa, pb = _linear_poses(nodes, c)
    elif isinstance(c, BranchCandidate):
        idx, pa, pb = _tree_poses(nodes, c)
    else:  # pragma: no cover
        raise TypeError(f"unknown candidate {type(c).__name__}")
    return idx, _pose_error(nodes, idx, pa, pb, sizes, period), starts, (pa, pb)
