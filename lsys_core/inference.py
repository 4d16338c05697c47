"""Cluster analysis, importance, rule generation and hierarchy (paper §5.3–§5.6).

The scene is a set of *live nodes*: at first the input elements (terminal instances with
their poses), later non-terminal instances covering groups of elements.  Each level:

1. pair every node with its nearest neighbours and measure the relative transforms
   (:mod:`lsys_core.transforms`);
2. cluster them by mean shift (:mod:`lsys_core.clustering`) in each space of a pair of
   symbols: clusters *C* of (nearly) equal transforms, and clusters *D* in the (d, s)
   subspace whose α and β change by a constant step along a sequence;
3. turn clusters into candidate rules: sequences (chains of pairs), branchings (two
   clusters sharing their first elements: full binary trees) and pairs of different
   symbols, scored by the importance ``w = wn·n + wh·h + wφ·φ + wl·l``;
4. apply the most important candidate: emit its rule, replace its nodes by one node of
   the new non-terminal (pose of the first element), and repeat until one node is left,
   which becomes the axiom.  When nothing repeats any more, a last rule places the
   remaining nodes, so no element is ever lost.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from .cancel import CancelToken, Progress, check, report
from .clustering import mean_shift
from .geometry import t4_from_rel, wrap_deg
from .grammar.model import COND_EQ0, COND_GT0, Case, Count, Linear, Module, Pop, Push, Rule, Symbol, Turtle
from .transforms import PairSpace, pair_space

__all__ = ["Hierarchy", "Tolerance", "Weights", "build_hierarchy"]


@dataclass(frozen=True)
class Weights:
    """User weights of the cluster importance ``w = wn·n + wh·h + wφ·φ + wl·l``, each in [0, 1]."""

    wn: float = 0.3
    wh: float = 1.0
    wphi: float = 0.3
    wl: float = 0.3


@dataclass(frozen=True)
class Tolerance:
    """Clustering bandwidths: translation relative to the symbol's size, angle (degrees), log-scale."""

    xy: float = 0.02
    angle: float = 1.0
    scale: float = 0.01

    def scaled(self, factor: float) -> Tolerance:
        """Return the bandwidths multiplied by ``factor``."""
        return Tolerance(self.xy * factor, self.angle * factor, self.scale * factor)


@dataclass
class _Sym:
    name: str
    m: int | None
    terminal: bool
    size: float
    family: str  # rule name or terminal name: symbols of one family are alike


@dataclass
class Hierarchy:
    """Result of :func:`build_hierarchy`: rules, the axiom and statistics."""

    rules: list[Rule]
    axiom: tuple[Module, ...]
    levels: int
    node_rule: np.ndarray  # for every input element: index of the first rule that covered it (-1: axiom)
    log: list[str] = field(default_factory=list)
    closed: bool = True  # False when a last rule had to place nodes no repetition explains


@dataclass
class _Candidate:
    kind: str  # "seq", "pair", "branch", "lin"
    space: tuple[int, int]
    groups: list  # chains (lists of node indices) or (root, depth) trees
    T: tuple  # transform(s)
    n: float = 0.0
    h: float = 0.0
    phi: float = 0.0
    l: float = 0.0
    covered: int = 0
    score: float = 0.0
    extra: dict = field(default_factory=dict)


def _t_modules(alpha: Linear, d: Linear, s: Linear, beta: Linear) -> tuple[Module, ...]:
    """Return ``+(α) f(d) *(s) +(β)`` without identity commands."""
    out: list[Module] = []
    if alpha.cd == 0 and beta.cd == 0 and d.cd == 0 and abs(float(wrap_deg(alpha.c0))) > 90.0:
        # +(α) f(d) … +(β) == +(α-180) f(-d) … +(β+180): keep the turn small.
        alpha = Linear(float(wrap_deg(alpha.c0 - 180.0)))
        d = Linear(-d.c0)
        beta = Linear(float(wrap_deg(beta.c0 + 180.0)))

    def angle(v: Linear) -> None:
        c0 = float(wrap_deg(v.c0)) if v.cd == 0 else v.c0
        if abs(c0) > 1e-9 or v.cd != 0:
            out.append(Turtle("+", Linear(_nice(c0, abs_tol=ANGLE_SNAP), _nice(v.cd, abs_tol=ANGLE_SNAP))))

    angle(alpha)
    if abs(d.c0) > 1e-12 or d.cd != 0:
        out.append(
            Turtle("f", Linear(_nice(d.c0, rel_tol=DISTANCE_SNAP), _nice(d.cd, rel_tol=DISTANCE_SNAP)))
        )
    if abs(s.c0 - 1.0) > 1e-9 or s.cd != 0:
        out.append(Turtle("*", Linear(_nice(s.c0, rel_tol=SCALE_SNAP), _nice(s.cd, rel_tol=SCALE_SNAP))))
    angle(beta)
    return tuple(out)


#: Written values are the shortest decimals within these tolerances of the measured ones
#: (degrees; relative for distances and scales, which compound along a sequence).
ANGLE_SNAP = 1e-5
DISTANCE_SNAP = 1e-6
SCALE_SNAP = 1e-8


def _nice(x: float, *, abs_tol: float = 0.0, rel_tol: float = 0.0) -> float:
    """Return the decimal with the fewest digits within the tolerance of ``x`` (``45.0000049`` → ``45``)."""
    x = float(x)
    if x == 0 or not np.isfinite(x):
        return 0.0 if x == 0 else x
    tol = max(abs_tol, rel_tol * abs(x))
    for digits in range(0, 12):
        y = round(x, digits)
        if abs(y - x) <= tol:
            return y + 0.0
    return float(f"{x:.12g}") + 0.0


def _const_t(A: complex, B: complex) -> tuple[Module, ...]:
    al, d, s, be = (float(v) for v in t4_from_rel(A, B))
    return _t_modules(Linear(al), Linear(d), Linear(s), Linear(be))


def _mean_rel(A: np.ndarray, B: np.ndarray) -> tuple[complex, complex]:
    """Average relative frames: geometric mean of ``A`` (log space), arithmetic mean of ``B``."""
    la = np.log(A)
    ang = np.angle(np.mean(np.exp(1j * la.imag)))
    return complex(np.exp(np.mean(la.real) + 1j * ang)), complex(np.mean(B))


class _Builder:
    """Mutable state of the hierarchy construction."""

    def __init__(self, terminal_names, terminal_sizes, a, b, center, radius, weights, tol, similarity):
        self.syms: list[_Sym] = [
            _Sym(nm, None, True, float(sz), nm) for nm, sz in zip(terminal_names, terminal_sizes, strict=True)
        ]
        self.sym_index: dict[tuple, int] = {("t", nm): i for i, nm in enumerate(terminal_names)}
        self.rules: list[Rule] = []
        self.rule_names: set[str] = set(terminal_names)
        self.counters = {"P": 0, "R": 0, "X": 0}
        self.weights = weights
        self.tol = tol
        self.similarity = similarity  # (n_terminals, n_terminals) similarity of terminal shapes
        self.log: list[str] = []
        self.n_terminals = len(terminal_names)

    # -- symbols ---------------------------------------------------------------------------------
    def new_name(self, prefix: str) -> str:
        while True:
            self.counters[prefix] += 1
            name = f"{prefix}{self.counters[prefix]}"
            if name not in self.rule_names:
                self.rule_names.add(name)
                return name

    def sym_id(self, name: str, m: int | None, size: float, family: str) -> int:
        key = ("r", name, m)
        if key not in self.sym_index:
            self.sym_index[key] = len(self.syms)
            self.syms.append(_Sym(name, m, False, size, family))
        return self.sym_index[key]

    def draw(self, sid: int, last: bool = False) -> tuple[Module, ...]:
        """Modules that draw symbol ``sid`` without moving the turtle (brackets for non-terminals)."""
        s = self.syms[sid]
        if s.terminal:
            return (Symbol(s.name),)
        mod = Symbol(s.name, Count(s.m) if s.m is not None else None)
        return (mod,) if last else (Push(), mod, Pop())

    def phi(self, si: int, sj: int) -> float:
        if si == sj:
            return 1.0
        a, b = self.syms[si], self.syms[sj]
        if a.terminal and b.terminal:
            return float(self.similarity[si, sj])
        if a.family == b.family:
            return 0.8
        return 0.3


def build_hierarchy(
    terminal_names: list[str],
    terminal_sizes: np.ndarray,
    group: np.ndarray,
    a: np.ndarray,
    b: np.ndarray,
    center: np.ndarray,
    radius: np.ndarray,
    *,
    weights: Weights = Weights(),
    tol: Tolerance = Tolerance(),
    similarity: np.ndarray | None = None,
    neighbours: int = 12,
    cancel: CancelToken | None = None,
    progress: Progress | None = None,
    timer: dict[str, float] | None = None,
) -> Hierarchy:
    """Generate rules level by level until one node is left (§5.5–§5.6).

    Parameters
    ----------
    terminal_names, terminal_sizes
        Terminal symbol names and the radius of each terminal's shape in its local frame.
    group, a, b
        Terminal index and pose of every input element.
    center, radius
        Bounding circle of every input element (for proximity and neighbourhoods).
    weights, tol
        Importance weights and clustering bandwidths.
    similarity
        Terminal-by-terminal shape similarity in [0, 1] (φ of pairs of different terminals).
    timer
        If given, seconds spent are added under ``transforms``, ``clustering`` and ``rules``.

    Returns
    -------
    Hierarchy
    """
    nt = len(terminal_names)
    sim = similarity if similarity is not None else np.full((nt, nt), 0.5) + 0.5 * np.eye(nt)
    bld = _Builder(terminal_names, terminal_sizes, a, b, center, radius, weights, tol, sim)
    sym = np.asarray(group, dtype=np.int64).copy()
    a = np.asarray(a, complex).copy()
    b = np.asarray(b, complex).copy()
    center = np.asarray(center, complex).copy()
    radius = np.asarray(radius, float).copy()
    members = [np.array([i]) for i in range(a.size)]
    node_rule = np.full(a.size, -1, np.int64)
    n0 = a.size
    level = 0
    clock = timer if timer is not None else {}
    for k in ("transforms", "clustering", "rules"):
        clock.setdefault(k, 0.0)
    while a.size > 1:
        check(cancel)
        report(progress, "rules", 1.0 - (a.size - 1) / max(n0 - 1, 1))
        t0 = time.perf_counter()
        ps = pair_space(a, b, center, radius, k=neighbours)
        t1 = time.perf_counter()
        cands = _candidates(bld, sym, a, b, ps, radius)
        t2 = time.perf_counter()
        if cands:
            first = np.array([m.min() for m in members])
            for c in cands:
                c.extra["start"] = float(np.mean([first[g[0]] for g in c.groups]))
            best = _select(cands, bld.weights)
            level += 1
            sym, a, b, center, radius, members = _apply(
                bld, best, sym, a, b, center, radius, members, node_rule
            )
        clock["transforms"] += t1 - t0
        clock["clustering"] += t2 - t1
        clock["rules"] += time.perf_counter() - t2
        if not cands:
            break
    axiom: tuple[Module, ...]
    if a.size == 1:
        axiom = _const_t(a[0], b[0]) + bld.draw(int(sym[0]), last=True)
    else:
        name = "Z"
        bld.rule_names.add(name)
        body: list[Module] = []
        a0, b0 = a[0], b[0]
        for i in range(a.size):
            t = _const_t(a[i] / a0, (b[i] - b0) / a0)
            body += (
                [Push(), *t, *bld.draw(int(sym[i]), last=True), Pop()]
                if i
                else [Push(), *bld.draw(int(sym[i]), last=True), Pop()]
            )
        bld.rules.append(Rule(name, False, (Case(None, tuple(body)),)))
        bld.log.append(f"{name}: places the {a.size} remaining nodes")
        axiom = (*_const_t(a0, b0), Symbol(name))
        for mem in members:
            node_rule[mem[node_rule[mem] < 0]] = len(bld.rules) - 1
    report(progress, "rules", 1.0)
    return Hierarchy(bld.rules, axiom, level, node_rule, bld.log, closed=a.size == 1)


# ---------------------------------------------------------------------------------------------
# Candidates


def _space_key(sym: np.ndarray, ps: PairSpace) -> np.ndarray:
    return sym[ps.src] * (int(sym.max()) + 1) + sym[ps.dst]


def _size_of(bld: _Builder, sym: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    sizes = np.array([s.size for s in bld.syms])
    return np.maximum(sizes[sym[nodes]], 1e-9)


def _proximity(ps: PairSpace, n_nodes: int, radius: np.ndarray) -> np.ndarray:
    """Per-pair proximity in (0, 1]: 1 for a node's nearest neighbour, lower for farther pairs.

    Distances are between the centres of the nodes' geometry, relative to the nearest
    neighbour of either node; neighbours up to :data:`NEAR_BAND` times farther than the
    nearest count as equally near (spacings that differ a little look alike).
    """
    nn = np.full(n_nodes, np.inf)
    np.minimum.at(nn, ps.src, ps.dist)
    eps = 0.1 * float(np.median(radius)) + 1e-12
    near = np.minimum(nn[ps.src], nn[ps.dst])
    return np.minimum(NEAR_BAND * (near + eps) / (ps.dist + eps), 1.0)


def _candidates(bld: _Builder, sym, a, b, ps: PairSpace, radius: np.ndarray) -> list[_Candidate]:
    if len(ps) == 0:
        return []
    tol = bld.tol
    size = _size_of(bld, sym, ps.src)
    key = _space_key(sym, ps)
    th = np.angle(ps.A)
    ang = np.deg2rad(tol.angle)
    emb = np.column_stack(
        [
            ps.B.real / (tol.xy * size),
            ps.B.imag / (tol.xy * size),
            np.cos(th) / ang,
            np.sin(th) / ang,
            np.log(np.abs(ps.A)) / tol.scale,
            key * 1e7,
        ]
    )
    labels, _ = mean_shift(emb)
    prox = _proximity(ps, a.size, radius)
    out: list[_Candidate] = []
    clusters = _group_indices(labels)
    seq_by_space: dict[tuple[int, int], list[tuple[np.ndarray, dict]]] = {}
    for idx in clusters:
        si, sj = int(sym[ps.src[idx[0]]]), int(sym[ps.dst[idx[0]]])
        cost = np.linalg.norm(emb[idx, :5] - emb[idx, :5].mean(0), axis=1)
        src, dst = ps.src[idx], ps.dst[idx]
        chains, succ = _chains(src, dst, cost, a.size)
        if not chains:
            continue
        used = _chain_pairs(chains, src, dst, idx)
        A, B = _mean_rel(ps.A[used], ps.B[used])
        lengths = [len(c) - 1 for c in chains]
        rep = len(chains) >= 2 or max(lengths) >= 2
        seq_by_space.setdefault((si, sj), []).append((idx, succ))
        if not rep:
            continue
        kind = "seq" if si == sj and max(lengths) >= 2 else "pair"
        if kind == "pair":
            chains = [c[:2] for c in chains]
            lengths = [1] * len(chains)
        cand = _Candidate(kind, (si, sj), chains, (A, B))
        cand.covered = sum(len(c) for c in chains)
        cand.h = float(np.mean(prox[used]))
        cand.phi = bld.phi(si, sj)
        cand.l = float(np.mean(lengths))
        if kind == "pair" and si != sj:
            cand.extra["succ"] = succ
        out.append(cand)
    _alternation_lengths(out, seq_by_space)
    out += _branch_candidates(bld, ps, {k: v for k, v in seq_by_space.items() if k[0] == k[1]}, prox, a.size)
    out += _linear_candidates(bld, sym, ps, prox, size, key)
    return out


def _alternation_lengths(cands: list[_Candidate], clusters: dict) -> None:
    """Give pair candidates A→B the length of the alternating sequences A B A B … they start.

    When a cluster of B→A pairs links each pair's B to the A of the next pair, the pairs
    are the steps of one sequence ``A T B T' A T B …``: merging them first lets the next
    level code it with a single sequence rule.
    """
    for c in cands:
        succ = c.extra.get("succ")
        if succ is None:
            continue
        si, sj = c.space
        best = 1.0
        for _, back in clusters.get((sj, si), [])[:4]:
            targets = set(back.values())
            lengths = []
            for x in (x for x in succ if x not in targets):
                n, cur, seen = 0, x, set()
                while cur in succ and cur not in seen:
                    seen.add(cur)
                    n += 1
                    cur = back.get(succ[cur], -1)
                lengths.append(n)
            if lengths:
                best = max(best, float(np.mean(lengths)))
        c.l = best


def _group_indices(labels: np.ndarray) -> list[np.ndarray]:
    order = np.argsort(labels, kind="stable")
    lab = labels[order]
    cuts = np.flatnonzero(np.diff(lab)) + 1
    return [g for g in np.split(order, cuts) if g.size and labels[g[0]] >= 0]


def _chains(src, dst, cost, n_nodes) -> tuple[list[list[int]], dict[int, int]]:
    """Link pairs into sequences: greedy best pairs, each node with ≤ 1 successor and predecessor."""
    order = np.argsort(cost, kind="stable")
    succ: dict[int, int] = {}
    pred: dict[int, int] = {}
    for e in order:
        i, j = int(src[e]), int(dst[e])
        if i == j or i in succ or j in pred:
            continue
        succ[i] = j
        pred[j] = i
    chains: list[list[int]] = []
    seen: set[int] = set()
    starts = [i for i in succ if i not in pred]
    for s0 in sorted(starts):
        ch = [s0]
        while ch[-1] in succ:
            ch.append(succ[ch[-1]])
        seen.update(ch)
        chains.append(ch)
    # Cycles (rings): cut each at its smallest node, dropping the closing pair.
    for i in sorted(succ):
        if i in seen:
            continue
        cyc = [i]
        while succ[cyc[-1]] != i:
            cyc.append(succ[cyc[-1]])
        k = int(np.argmin(cyc))
        ch = cyc[k:] + cyc[:k]
        seen.update(ch)
        chains.append(ch)
    return chains, succ


def _chain_pairs(chains, src, dst, idx) -> np.ndarray:
    look = {(int(s), int(d)): int(k) for s, d, k in zip(src, dst, idx, strict=True)}
    return np.array([look[(c[t], c[t + 1])] for c in chains for t in range(len(c) - 1)], int)


def _branch_candidates(bld, ps, seq_by_space, prox, n_nodes) -> list[_Candidate]:
    """Full binary trees from two clusters of one symbol space sharing their first elements (r3/r4)."""
    out = []
    for (si, sj), clusters in seq_by_space.items():
        big = [c for c in clusters if len(c[1]) >= 2][:8]
        for x in range(len(big)):
            for y in range(x + 1, len(big)):
                (i1, s1), (i2, s2) = big[x], big[y]
                both = set(s1) & set(s2)
                if len(both) < 1:
                    continue
                c1 = np.full(n_nodes, -1)
                c2 = np.full(n_nodes, -1)
                for k, v in s1.items():
                    c1[k] = v
                for k, v in s2.items():
                    c2[k] = v
                depth = np.zeros(n_nodes, int)
                has = (c1 >= 0) & (c2 >= 0)
                for _ in range(64):
                    new = np.where(has, 1 + np.minimum(depth[np.maximum(c1, 0)], depth[np.maximum(c2, 0)]), 0)
                    if np.array_equal(new, depth):
                        break
                    depth = new
                trees, covered = [], np.zeros(n_nodes, bool)
                for r in np.argsort(-depth, kind="stable"):
                    if depth[r] < 1 or covered[r]:
                        continue
                    dep = min(int(depth[r]), int(np.log2(n_nodes + 1)) - 1)
                    nodes = _tree_nodes(int(r), dep, c1, c2)
                    while dep >= 1 and (nodes is None or covered[nodes].any()):
                        dep -= 1
                        nodes = _tree_nodes(int(r), dep, c1, c2)
                    if dep < 1 or nodes is None:
                        continue
                    covered[nodes] = True
                    trees.append((int(r), dep, nodes))
                if not trees or (len(trees) < 2 and trees[0][1] < 2):
                    continue
                used1 = np.array([k for k in i1 if covered[ps.src[k]] and c1[ps.src[k]] == ps.dst[k]])
                used2 = np.array([k for k in i2 if covered[ps.src[k]] and c2[ps.src[k]] == ps.dst[k]])
                if used1.size == 0 or used2.size == 0:
                    continue
                T1 = _mean_rel(ps.A[used1], ps.B[used1])
                T2 = _mean_rel(ps.A[used2], ps.B[used2])
                cand = _Candidate("branch", (si, sj), trees, (T1, T2), extra={"c1": c1, "c2": c2})
                cand.covered = int(covered.sum())
                cand.h = float(max(np.mean(prox[used1]), np.mean(prox[used2])))
                cand.phi = 1.0
                cand.l = float(np.mean([t[1] for t in trees])) * 2.0
                out.append(cand)
    return out


def _tree_nodes(root: int, depth: int, c1: np.ndarray, c2: np.ndarray) -> np.ndarray | None:
    """Nodes of the full binary tree of ``depth`` under ``root``, or None if they are not distinct."""
    level = np.array([root])
    nodes = [level]
    for _ in range(depth):
        level = np.concatenate([c1[level], c2[level]])
        nodes.append(level)
    out = np.concatenate(nodes)
    return out if np.unique(out).size == out.size and (out >= 0).all() else None


#: Pairs up to this factor farther apart than a node's nearest neighbour have proximity 1.
NEAR_BAND = 1.25
#: Step clusters (Δα, Δβ) examined per (d, s) cluster, largest first: smaller ones cannot win.
_STEP_CLUSTERS = 12


def _linear_candidates(bld, sym, ps, prox, size, key) -> list[_Candidate]:
    """Sequences whose α and β change by a constant step (clusters D in the (d, s) subspace)."""
    tol = bld.tol
    ok = (ps.d / size > 0.1) & (sym[ps.src] == sym[ps.dst])
    if ok.sum() < 2:
        return []
    sel = np.flatnonzero(ok)
    emb = np.column_stack([ps.d[sel] / (size[sel] * tol.xy), np.log(ps.s[sel]) / tol.scale, key[sel] * 1e7])
    labels, _ = mean_shift(emb)
    out = []
    ang = np.deg2rad(tol.angle)
    for g in _group_indices(labels):
        if g.size < 2:
            continue
        idx = sel[g]
        e1a, e2a = _successor_pairs(ps.src, ps.dst, idx)
        if e1a.size < 1:
            continue
        da = np.deg2rad(wrap_deg(ps.alpha[e2a] - ps.alpha[e1a]))
        db = np.deg2rad(wrap_deg(ps.beta[e2a] - ps.beta[e1a]))
        emb2 = np.column_stack([np.cos(da), np.sin(da), np.cos(db), np.sin(db)]) / ang
        lab2, _ = mean_shift(emb2)
        for g2 in _group_indices(lab2)[:_STEP_CLUSTERS]:
            if g2.size < 2:
                continue  # a single consecutive pair is no sequence
            dA = float(np.rad2deg(np.arctan2(emb2[g2, 1].mean(), emb2[g2, 0].mean())))
            dB = float(np.rad2deg(np.arctan2(emb2[g2, 3].mean(), emb2[g2, 2].mean())))
            if abs(dA) < tol.angle and abs(dB) < tol.angle:
                continue  # constant transform: a cluster C already covers it
            cand = _linear_chains(bld, sym, ps, e1a[g2], e2a[g2], dA, dB, prox)
            if cand is not None:
                out.append(cand)
    return out


def _successor_pairs(src: np.ndarray, dst: np.ndarray, idx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """All pairs of pairs ``(i→j, j→k)`` with ``k != i`` among the pair indices ``idx``."""
    order = np.argsort(src[idx], kind="stable")
    s_sorted = src[idx][order]
    lo = np.searchsorted(s_sorted, dst[idx], "left")
    cnt = np.searchsorted(s_sorted, dst[idx], "right") - lo
    e1 = np.repeat(idx, cnt)
    offs = np.arange(int(cnt.sum())) - np.repeat(np.cumsum(cnt) - cnt, cnt)
    e2 = idx[order][np.repeat(lo, cnt) + offs]
    keep = dst[e2] != src[e1]
    return e1[keep], e2[keep]


def _edge_chains(e1: np.ndarray, e2: np.ndarray) -> list[list[int]]:
    """Follow links ``e1 → e2`` (each pair with at most one successor and predecessor) into chains."""
    _, first = np.unique(e1, return_index=True)
    e1, e2 = e1[np.sort(first)], e2[np.sort(first)]
    _, first = np.unique(e2, return_index=True)
    e1, e2 = e1[np.sort(first)], e2[np.sort(first)]
    keep = e1 != e2
    nxt = dict(zip(e1[keep].tolist(), e2[keep].tolist(), strict=True))
    has_prev = set(nxt.values())
    chains = []
    for s0 in nxt:
        if s0 in has_prev:
            continue
        ch = [s0]
        while ch[-1] in nxt:
            ch.append(nxt[ch[-1]])
        chains.append(ch)
    return chains


def _linear_chains(bld, sym, ps, e1, e2, dA, dB, prox) -> _Candidate | None:
    chains_e = _edge_chains(e1, e2)
    # Node-disjoint chains only (greedy, longest first).
    chains_e.sort(key=len, reverse=True)
    taken: set[int] = set()
    groups: dict[tuple, list] = {}
    for ch in chains_e:
        nodes = [int(ps.src[ch[0]])] + [int(ps.dst[e]) for e in ch]
        if taken.intersection(nodes) or len(set(nodes)) != len(nodes):
            continue
        taken.update(nodes)
        k = len(ch)
        al0 = float(ps.alpha[ch[0]])
        be0 = float(ps.beta[ch[0]])
        kq = (k, round(al0 / max(bld.tol.angle, 1e-6)), round(be0 / max(bld.tol.angle, 1e-6)))
        groups.setdefault(kq, []).append((nodes, ch))
    if not groups:
        return None
    # One candidate: the most populated (length, start) group; others follow in later levels.
    _, best = max(groups.items(), key=lambda kv: (len(kv[1]) * kv[0][0], kv[0][0]))
    if len(best) < 2 and len(best[0][1]) < 2:
        return None
    edges = np.array([e for _, ch in best for e in ch])
    step = np.array([t for _, ch in best for t in range(len(ch))])
    al = np.array([float(ps.alpha[ch[0]]) for _, ch in best])
    be = np.array([float(ps.beta[ch[0]]) for _, ch in best])
    k = len(best[0][1])
    # Least-squares fit of α0, β0 given the steps (angles unwrapped around the first chain).
    al_fit = float(np.mean(wrap_deg(ps.alpha[edges] - step * dA - al[0]))) + al[0]
    be_fit = float(np.mean(wrap_deg(ps.beta[edges] - step * dB - be[0]))) + be[0]
    d = float(np.mean(ps.d[edges]))
    s = float(np.exp(np.mean(np.log(ps.s[edges]))))
    si = int(sym[ps.src[edges[0]]])
    cand = _Candidate("lin", (si, si), [nodes for nodes, _ in best], (al_fit, d, s, be_fit, dA, dB, k))
    cand.covered = sum(len(n) for n, _ in best)
    cand.h = float(np.mean(prox[edges]))
    cand.phi = 1.0
    cand.l = float(k)
    return cand


def _select(cands: list[_Candidate], w: Weights) -> _Candidate:
    cov = max(c.covered for c in cands)
    lmax = max(c.l for c in cands)
    for c in cands:
        c.n = c.covered / cov
        c.score = w.wn * c.n + w.wh * min(c.h, 1.0) + w.wphi * c.phi + w.wl * (c.l / lmax)
    # Ties (e.g. a sequence read forwards or backwards) go to the order the art was drawn in.
    return max(cands, key=lambda c: (round(c.score, 9), c.covered, -c.extra.get("start", 0.0)))


# ---------------------------------------------------------------------------------------------
# Applying a candidate: emit its rule, replace its nodes


def _apply(bld: _Builder, c: _Candidate, sym, a, b, center, radius, members, node_rule):
    si, sj = c.space
    groups: list[np.ndarray] = []
    new_syms: list[int] = []
    rule_index = len(bld.rules)
    if c.kind == "pair":
        name = bld.new_name("X")
        A, B = c.T
        body = bld.draw(si) + _const_t(A, B) + bld.draw(sj, last=True)
        bld.rules.append(Rule(name, False, (Case(None, body),)))
        for ch in c.groups:
            groups.append(np.array(ch))
            new_syms.append(bld.sym_id(name, None, 0.0, name))
        bld.log.append(f"{name}: {len(c.groups)} pairs {bld.syms[si].name}-{bld.syms[sj].name}")
    elif c.kind == "seq":
        name = bld.new_name("P")
        A, B = c.T
        t = _const_t(A, B)
        gt = Case(COND_GT0, (*bld.draw(si), *t, Symbol(name, Count(-1, 1))))
        eq = Case(COND_EQ0, bld.draw(si, last=True))
        bld.rules.append(Rule(name, True, (gt, eq)))
        for ch in c.groups:
            groups.append(np.array(ch))
            new_syms.append(bld.sym_id(name, len(ch) - 1, 0.0, name))
        bld.log.append(
            f"{name}: {len(c.groups)} sequences of {bld.syms[si].name}, lengths "
            f"{sorted({len(ch) for ch in c.groups})}"
        )
    elif c.kind == "lin":
        name = bld.new_name("P")
        al0, d, s, be0, dA, dB, k = c.T
        t = _t_modules(Linear(al0 + k * dA, -dA), Linear(d), Linear(s), Linear(be0 + k * dB, -dB))
        gt = Case(COND_GT0, (*bld.draw(si), *t, Symbol(name, Count(-1, 1))))
        eq = Case(COND_EQ0, bld.draw(si, last=True))
        bld.rules.append(Rule(name, True, (gt, eq)))
        for ch in c.groups:
            groups.append(np.array(ch))
            new_syms.append(bld.sym_id(name, len(ch) - 1, 0.0, name))
        bld.log.append(f"{name}: {len(c.groups)} sequences with linear angles ({dA:.3g}°, {dB:.3g}°/step)")
    else:  # branch
        name = bld.new_name("R")
        (A1, B1), (A2, B2) = c.T
        rec = Symbol(name, Count(-1, 1))
        gt = Case(COND_GT0, (*bld.draw(si), Push(), *_const_t(A1, B1), rec, Pop(), *_const_t(A2, B2), rec))
        eq = Case(COND_EQ0, bld.draw(si, last=True))
        bld.rules.append(Rule(name, True, (gt, eq)))
        for root, depth, nodes in c.groups:
            groups.append(np.concatenate([[root], nodes[nodes != root]]))
            new_syms.append(bld.sym_id(name, depth, 0.0, name))
        bld.log.append(
            f"{name}: {len(c.groups)} branching structures, depths {sorted({g[1] for g in c.groups})}"
        )
    # Replace the covered nodes by one node each (pose of the first node).
    keep = np.ones(a.size, bool)
    add_a, add_b, add_c, add_r, add_s, add_m = [], [], [], [], [], []
    for g, ns in zip(groups, new_syms, strict=True):
        keep[g] = False
        first = int(g[0])
        cen = complex(np.mean(center[g]))
        rad = float(np.max(np.abs(center[g] - cen) + radius[g]))
        add_a.append(a[first])
        add_b.append(b[first])
        add_c.append(cen)
        add_r.append(rad)
        add_s.append(ns)
        mem = np.concatenate([members[i] for i in g])
        node_rule[mem[node_rule[mem] < 0]] = rule_index
        add_m.append(mem)
        if bld.syms[ns].size == 0.0:
            bld.syms[ns].size = rad / abs(a[first])
    kept = np.flatnonzero(keep)
    sym = np.concatenate([sym[kept], np.array(add_s, np.int64)])
    a = np.concatenate([a[kept], np.array(add_a, complex)])
    b = np.concatenate([b[kept], np.array(add_b, complex)])
    center = np.concatenate([center[kept], np.array(add_c, complex)])
    radius = np.concatenate([radius[kept], np.array(add_r, float)])
    members = [members[i] for i in kept] + add_m
    return sym, a, b, center, radius, members
