"""Cluster analysis, importance, rule generation and hierarchy (paper §5.3–§5.6).

The scene is a set of *live nodes*: at first the input elements (terminal instances with
their poses), later non-terminal instances covering groups of elements.  Each level:

1. pair every node with its nearest neighbours and measure the relative transforms
   (:mod:`lsys_core.hierarchy.spaces`);
2. cluster them by mean shift (:mod:`lsys_core.hierarchy.clustering`) in each space of a pair of
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

from lsys_core.cancel import CancelToken, Progress, check, report
from lsys_core.geometry.transforms import t4_from_rel, wrap_deg
from lsys_core.grammar.model import (
    COND_EQ0,
    COND_GT0,
    Case,
    Count,
    Linear,
    Module,
    Pop,
    Push,
    Rule,
    Symbol,
    Turtle,
)
from lsys_core.hierarchy.candidates import Candidate, find_candidates
from lsys_core.hierarchy.spaces import pair_space

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


#: Levels of the hierarchy at most (each level codes at least one repetition).
MAX_LEVELS = 100
#: Scenes with more live nodes than this ignore candidates that repeat only twice (see :func:`_chance`).
CHANCE_SCENE = 100
#: A best candidate covering less than this share of the nodes is applied together with all
#: other candidates on disjoint nodes (see :func:`_batch`).
WEAK_COVER = 0.05

#: Written values are the shortest decimals within these tolerances of the measured ones
#: (degrees; relative for distances and scales, which compound along a sequence).
ANGLE_SNAP = 1e-5
DISTANCE_SNAP = 1e-6
SCALE_SNAP = 5e-8


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


class _Builder:
    """Mutable state of the hierarchy construction (symbols, rules, weights, bandwidths)."""

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
    neighbours: int = 24,
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
    dup = _duplicates(bld, sym, a, b)
    if dup:
        level += 1
        sym, a, b, center, radius, members = _apply_all(
            bld, dup, sym, a, b, center, radius, members, node_rule
        )
    while a.size > 1:
        check(cancel)
        report(progress, "rules", 1.0 - (a.size - 1) / max(n0 - 1, 1))
        t0 = time.perf_counter()
        ps = pair_space(a, b, center, radius, k=neighbours)
        t1 = time.perf_counter()
        cands = find_candidates(bld, sym, a, b, ps, radius)
        t2 = time.perf_counter()
        if cands and level < MAX_LEVELS:
            first = np.array([m.min() for m in members])
            for c in cands:
                c.extra["start"] = float(np.mean([first[g[0]] for g in c.groups]))
            best = _select(cands, bld.weights)
            if _chance(best, a.size):
                cands = []  # only coincidences left: place the remaining nodes as they are
            else:
                chosen = _batch(best, cands, a.size)
                level += 1
                sym, a, b, center, radius, members = _apply_all(
                    bld, chosen, sym, a, b, center, radius, members, node_rule
                )
        else:
            cands = []
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


def _duplicates(bld: _Builder, sym: np.ndarray, a: np.ndarray, b: np.ndarray) -> list[Candidate]:
    """Sequences with the identity transform for elements drawn several times at one pose.

    Stacked copies would otherwise pair with each other in arbitrary ways; coding each
    stack as ``P(m) -> A P(m-1)`` first keeps them (nothing is lost) and out of the way.
    """
    sizes = np.array([s.size for s in bld.syms])[sym]
    q = np.maximum(sizes * 1e-6, 1e-9)
    key = np.column_stack(
        [sym, np.round(b.real / q), np.round(b.imag / q), np.round(a.real / 1e-6), np.round(a.imag / 1e-6)]
    )
    _, inv, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    inv = inv.ravel()
    out: dict[int, Candidate] = {}
    for g in np.flatnonzero(counts >= 2):
        nodes = np.flatnonzero(inv == g).tolist()
        s = int(sym[nodes[0]])
        cand = out.setdefault(s, Candidate("seq", (s, s), [], (1 + 0j, 0j)))
        cand.groups.append(nodes)
    return list(out.values())


def _chance(best: Candidate, n_nodes: int) -> bool:
    """Whether the best candidate looks like a coincidence in a large scene.

    Two repetitions of a transform among hundreds of unrelated elements happen by chance;
    coding them would add rules without describing any structure.
    """
    repeats = len(best.groups) if best.kind != "seq" else sum(len(g) - 1 for g in best.groups)
    return n_nodes > CHANCE_SCENE and repeats < 3 and best.covered < WEAK_COVER * n_nodes


def _batch(best: Candidate, cands: list[Candidate], n_nodes: int) -> list[Candidate]:
    """Return the candidates to apply at this level: the best one, or many weak ones at once.

    When the most important candidate covers only a small part of the scene (chance
    coincidences among clutter or duplicates), every other candidate on disjoint nodes is
    applied in the same level, in order of importance, so the number of levels stays small.
    """
    if best.covered >= WEAK_COVER * n_nodes:
        return [best]
    taken = np.zeros(n_nodes, bool)
    out = []
    for c in sorted(cands, key=lambda c: -c.score):
        nodes = _nodes_of(c)
        if taken[nodes].any():
            continue
        taken[nodes] = True
        out.append(c)
    return out


def _nodes_of(c: Candidate) -> np.ndarray:
    if c.kind == "branch":
        return np.concatenate([t[2] for t in c.groups])
    return np.concatenate([np.asarray(g) for g in c.groups])


def _apply_all(bld: _Builder, chosen: list[Candidate], sym, a, b, center, radius, members, node_rule):
    """Apply candidates on disjoint nodes one after another, renumbering the later ones' nodes."""
    for k, cand in enumerate(chosen):
        sym, a, b, center, radius, members, mapping = _apply(
            bld, cand, sym, a, b, center, radius, members, node_rule
        )
        for later in chosen[k + 1 :]:
            _remap(later, mapping)
    return sym, a, b, center, radius, members


def _remap(c: Candidate, mapping: np.ndarray) -> None:
    """Rewrite a candidate's node indices after another candidate was applied."""
    if c.kind == "branch":
        c.groups = [(int(mapping[r]), d, mapping[nodes]) for r, d, nodes in c.groups]
    else:
        c.groups = [[int(mapping[i]) for i in g] for g in c.groups]


def _select(cands: list[Candidate], w: Weights) -> Candidate:
    cov = max(c.covered for c in cands)
    lmax = max(c.l for c in cands)
    for c in cands:
        c.n = c.covered / cov
        c.score = w.wn * c.n + w.wh * min(c.h, 1.0) + w.wphi * c.phi + w.wl * (c.l / lmax)
    # Ties (e.g. a sequence read forwards or backwards) go to the order the art was drawn in.
    return max(cands, key=lambda c: (round(c.score, 9), c.covered, -c.extra.get("start", 0.0)))


# ---------------------------------------------------------------------------------------------
# Applying a candidate: emit its rule, replace its nodes


def _apply(bld: _Builder, c: Candidate, sym, a, b, center, radius, members, node_rule):
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
    mapping = np.full(keep.size, -1)
    mapping[kept] = np.arange(kept.size)
    return sym, a, b, center, radius, members, mapping
