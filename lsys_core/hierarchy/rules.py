"""Cluster selection, rule generation and the hierarchy of levels (paper §5.4–§5.6).

The scene is a set of *live nodes* (:class:`~lsys_core.hierarchy.nodes.Nodes`): at first the
input elements (terminal instances with their poses), later non-terminal instances covering
groups of elements.  Each level:

1. pair every node with its nearest neighbours and measure the relative transforms
   (:mod:`lsys_core.hierarchy.spaces`);
2. cluster them and turn the clusters into candidate rules: sequences, branchings and pairs
   (:mod:`lsys_core.hierarchy.analysis`), scored by the importance ``w = wn·n + wh·h + wφ·φ + wl·l``;
3. apply the most important candidate: write its rule (:mod:`lsys_core.hierarchy.emit`),
   replace its nodes by one node of the new non-terminal (pose of the first element), and
   repeat until one node is left, which becomes the axiom.  When nothing repeats any more,
   a last rule places the remaining nodes, so no element is ever lost.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from functools import partial

import numpy as np

from lsys_core.cancel import CancelToken, Progress, check, report
from lsys_core.grammar.model import Case, Module, Pop, Push, Rule, Symbol
from lsys_core.hierarchy.analysis import find_candidates
from lsys_core.hierarchy.cache import LevelCache
from lsys_core.hierarchy.candidates import Candidate, SeqCandidate
from lsys_core.hierarchy.emit import const_t, const_t_many, emit
from lsys_core.hierarchy.flat import Groups
from lsys_core.hierarchy.gain import Ledger
from lsys_core.hierarchy.mdl import Precision
from lsys_core.hierarchy.nodes import Nodes
from lsys_core.hierarchy.reuse import Level, context_key
from lsys_core.hierarchy.rings import find_rings, ring_rule, ring_shortens
from lsys_core.hierarchy.select import Measure, Weights, choose, worthwhile
from lsys_core.hierarchy.snap import SHARE
from lsys_core.hierarchy.spaces import pair_space
from lsys_core.hierarchy.symbols import SymbolTable
from lsys_core.hierarchy.tabulated import find_tabulated, shortens, tabulated_rule
from lsys_core.hierarchy.twins import find_twins, twins_rule, twins_shorten
from lsys_core.parallel import submit

__all__ = ["Hierarchy", "Tolerance", "Weights", "build_hierarchy"]

#: Levels of the hierarchy at most (each level codes at least one repetition).
MAX_LEVELS = 100
#: Default tolerance, as a share of the drawing's diagonal, when none is given.
DEFAULT_TOLERANCE = 0.005
#: Live nodes from which a level's description length (:class:`~lsys_core.hierarchy.gain.Ledger`)
#: is measured on another worker beside its pairs.  For fewer, a thread costs more than it saves
#: (small numpy calls that hold the interpreter): with this and
#: :data:`~lsys_core.hierarchy.analysis.BESIDE_MIN_PAIRS`, the published real-art files of up to
#: a few hundred elements infer in the time of 1 job with 2 jobs, where they took 3-10 % longer.
LEDGER_BESIDE = 1_000


@dataclass(frozen=True)
class Tolerance:
    """Clustering bandwidths: translation relative to the symbol's size, angle (degrees), log-scale.

    ``length`` is a floor of all three, as a share of the tolerance ``eps`` (a length in the
    drawing): transforms that move a node's outline by less than ``length·eps`` are not told
    apart, however small the shape (see :func:`~lsys_core.hierarchy.analysis.find_candidates`).
    Off by default (0): at 0.5 it makes rings of hand-drawn dots of ±10 % sizes one rule, but a
    chart of 4,817 arrows at many angles got a description 4 times longer (56,700 -> 243,300 bits).
    The pipeline tries it beside the plain bandwidths and keeps the shorter grammar (minimum
    description length), so it applies only where it shortens the description.
    """

    xy: float = 0.02
    angle: float = 1.0
    scale: float = 0.01
    length: float = 0.0

    def scaled(self, factor: float) -> Tolerance:
        """Return the bandwidths multiplied by ``factor``."""
        return Tolerance(self.xy * factor, self.angle * factor, self.scale * factor, self.length * factor)


@dataclass(frozen=True, eq=False)
class Hierarchy:
    """Result of :func:`build_hierarchy`: rules, the axiom and statistics.

    ``closed`` is False when a last rule had to place nodes that no repetition explains.
    """

    rules: tuple[Rule, ...]
    axiom: tuple[Module, ...]
    levels: int
    log: tuple[str, ...] = ()
    closed: bool = True


@dataclass(frozen=True)
class _Context:
    """What candidate finding reads from the hierarchy (see :class:`~lsys_core.hierarchy.candidates.Context`)."""

    table: SymbolTable
    tol: Tolerance

    @property
    def n_terminals(self) -> int:
        return self.table.n_terminals

    def sizes(self) -> np.ndarray:
        return self.table.sizes

    def phi(self, si: int, sj: int) -> float:
        return self.table.phi(si, sj)


class _Book:
    """The rules written so far and the log."""

    def __init__(self) -> None:
        self.rules: list[Rule] = []
        self.log: list[str] = []

    def add(self, rule: Rule, log: str) -> None:
        self.rules.append(rule)
        self.log.append(log)


def build_hierarchy(
    terminal_names: list[str],
    terminal_sizes: np.ndarray,
    group: np.ndarray,
    a: np.ndarray,
    b: np.ndarray,
    center: np.ndarray,
    radius: np.ndarray,
    *,
    weights: Weights | None = None,
    tol: Tolerance = Tolerance(),
    similarity: np.ndarray | None = None,
    precision: Precision | None = None,
    tolerance: float | None = None,
    slack: np.ndarray | None = None,
    snap: float = SHARE,
    measure: Measure | None = None,
    symmetry: np.ndarray | None = None,
    neighbours: int = 24,
    cancel: CancelToken | None = None,
    progress: Progress | None = None,
    timer: dict[str, float] | None = None,
    cache: LevelCache | None = None,
    stretch_base: np.ndarray | None = None,
    stretch: np.ndarray | None = None,
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
    precision
        The tolerance and the drawing's size: a rule is written only when it shortens the
        description (:mod:`lsys_core.hierarchy.mdl`) and derives every node it explains within
        the tolerance.  Default: :data:`DEFAULT_TOLERANCE` of the drawing's diagonal.
    tolerance
        How far (document units) the derived drawing may deviate from the input (default:
        the precision's ``eps``; :func:`~lsys_core.pipeline.symmetrize` allows more, while the
        description length stays measured at the user's precision).
    slack
        How far every element may be moved by the rules (default: the tolerance); the
        pipeline passes the tolerance less each element's shape deviation.
    snap
        Share of the tolerance the rounding of a rule's numbers may spend.
    measure
        ``measure(elements, a, b)``: the deviation of input elements from their terminals
        drawn at poses ``a, b`` (document units), to check single elements exactly.
    symmetry
        Rotational symmetry order of every terminal (1: none, k: k-fold, 0: continuous), so
        rotations that do not show are not counted as deviations.
    timer
        If given, seconds spent are added under ``transforms``, ``clustering`` and ``rules``.
    cache
        If given, every level's candidates are looked up in it first and stored in it
        (they do not depend on ``weights``: re-weighting reuses them), with what choosing
        among them reads besides the weights (:mod:`.reuse`).  One cache serves one set of
        input elements and one ``measure``.
    stretch_base, stretch
        Per terminal, the terminal it is a stretched copy of (-1: none) and the stretch
        (:mod:`lsys_core.instancing.stretch`): such a terminal is written as its base drawn with
        ``~(t)``, and rows of one base at several stretches are found with the partly regular
        repetitions (:mod:`.tabulated`).

    Returns
    -------
    Hierarchy
    """
    weights = weights if weights is not None else Weights()
    nt = len(terminal_names)
    sim = similarity if similarity is not None else np.full((nt, nt), 0.5) + 0.5 * np.eye(nt)
    table = SymbolTable(terminal_names, terminal_sizes, sim)
    if stretch_base is not None and stretch is not None:
        table.set_stretch(stretch_base, stretch)
    ctx = _Context(table, tol)
    book = _Book()
    prec = precision
    if prec is None:
        prec = Precision.of_circles(np.asarray(center), np.asarray(radius), 0.0)
        prec = Precision.of_circles(np.asarray(center), np.asarray(radius), DEFAULT_TOLERANCE * prec.diagonal)
    limit = prec.eps if tolerance is None else float(tolerance)
    nodes = Nodes.of_elements(group, a, b, center, radius, limit if slack is None else slack)
    order = np.ones(nt, int) if symmetry is None else np.asarray(symmetry, int)
    term_period = np.where(order == 0, -1.0, np.where(order >= 2, 2 * np.pi / np.maximum(order, 1), 0.0))
    n0 = len(nodes)
    level = 0
    clock = timer if timer is not None else {}
    for k in ("transforms", "clustering", "rules"):
        clock.setdefault(k, 0.0)
    dup = _duplicates(table, nodes)
    if dup:
        level += 1
        nodes = _apply_all(table, book, dup, nodes)
    while len(nodes) > 1:
        check(cancel)
        report(progress, "rules", 1.0 - (len(nodes) - 1) / max(n0 - 1, 1))
        t0 = time.perf_counter()
        period = np.concatenate([term_period, np.zeros(len(table) - nt)])
        key = _level_key(table, nodes, tol, neighbours, prec) if cache is not None else b""
        found = cache.get(key) if cache is not None else None
        ledger: Ledger | None = None
        t1 = time.perf_counter()
        if found is None:
            # the level's description length, beside its pairs (each reads only the nodes)
            measured = submit(Ledger, prec, nodes, table) if len(nodes) >= LEDGER_BESIDE else None
            ps = pair_space(nodes.a, nodes.b, nodes.center, nodes.radius, k=neighbours)
            ledger = Ledger(prec, nodes, table) if measured is None else measured.result()
            t1 = time.perf_counter()
            found = Level(find_candidates(ctx, nodes.sym, ps, nodes.radius, ledger))
            if cache is not None:
                cache.put(key, found, found.nbytes)
        t2 = time.perf_counter()
        chosen: list[Candidate] = []
        if found.cands and level < MAX_LEVELS:
            context = context_key(nodes, table, period, limit, snap) if cache is not None else b""
            view = found.view(
                context,
                partial(Ledger, prec, nodes, table) if ledger is None else partial(_same, ledger),
                nodes.first_members,
            )
            test = partial(
                worthwhile,
                ledger=view.ledger,
                nodes=nodes,
                sizes=table.sizes,
                period=period,
                snap=snap,
                measure=measure,
                n_terminals=nt,
                limit=limit,
                ceiling=view.ceiling,
            )
            chosen = choose(
                view.cands,
                weights,
                len(nodes),
                view.tested(test),
                view.ceiling,
                order=view.order(weights),
                index=view.index,
            )
        if chosen:
            level += 1
            nodes = _apply_all(table, book, chosen, nodes)
        clock["transforms"] += t1 - t0
        clock["clustering"] += t2 - t1
        clock["rules"] += time.perf_counter() - t2
        if not chosen:
            break
    if len(nodes) > 1:
        period = np.concatenate([term_period, np.zeros(len(table) - nt)])
        nodes, tabulated = _tabulate(table, book, nodes, period, prec)
        level += tabulated
    axiom = _axiom(table, book, nodes)
    report(progress, "rules", 1.0)
    return Hierarchy(tuple(book.rules), axiom, level, tuple(book.log), closed=len(nodes) == 1)


def _level_key(table: SymbolTable, nodes: Nodes, tol: Tolerance, neighbours: int, prec: Precision) -> bytes:
    """What a level's candidates depend on: nodes, symbols (sizes, families, kinds, counters), bandwidths, precision."""
    terminal = np.arange(len(table)) < table.n_terminals
    counters = np.array([-1 if s.m is None else s.m for s in table.infos], np.int64)
    arrays = [
        nodes.sym,
        nodes.a,
        nodes.b,
        nodes.center,
        nodes.radius,
        table.sizes,
        table.families(),
        terminal,
        counters,
    ]
    return LevelCache.key(arrays, (tol, neighbours, repr(prec)))


def _axiom(table: SymbolTable, book: _Book, nodes: Nodes) -> tuple[Module, ...]:
    """The axiom: the last node, or a last rule placing the remaining nodes one by one."""
    if len(nodes) == 1:
        return const_t(nodes.a[0], nodes.b[0]) + table.draw(int(nodes.sym[0]), last=True)
    name = table.new_name("Z")
    body: list[Module] = []
    a0, b0 = nodes.a[0], nodes.b[0]
    moves = const_t_many(nodes.a / a0, (nodes.b - b0) / a0)
    for i in range(len(nodes)):
        body += [Push(), *(moves[i] if i else ()), *table.draw(int(nodes.sym[i]), last=True), Pop()]
    book.add(
        Rule(name, False, (Case(None, tuple(body)),)), f"{name}: places the {len(nodes)} remaining nodes"
    )
    return (*const_t(a0, b0), Symbol(name))


def _tabulate(
    table: SymbolTable, book: _Book, nodes: Nodes, period: np.ndarray, prec: Precision
) -> tuple[Nodes, int]:
    """Code the partly regular repetitions left (:mod:`.tabulated`, :mod:`.rings`, :mod:`.twins`) that shorten the description."""
    groups: list[np.ndarray] = []
    syms: list[int] = []
    starts: list[tuple[complex, complex]] = []
    for t in find_tabulated(table, nodes, period):
        if not shortens(prec, table, t, tabulated_rule(table, t, "T", nodes), nodes):
            continue
        name = table.new_name("P")
        what = "concentric copies" if t.kind == "scale" else "a row with offsets"
        book.add(tabulated_rule(table, t, name, nodes), f"{name}: {what} of {t.nodes.size} nodes (table)")
        groups.append(t.nodes)
        syms.append(table.symbol(name, t.steps - 1))
        starts.append((complex(nodes.a[t.nodes[0]]), complex(nodes.b[t.nodes[0]])))
    left = np.ones(len(nodes), bool)
    left[np.concatenate(groups) if groups else np.zeros(0, int)] = False
    for s in np.unique(nodes.sym[left]):
        for ring in find_rings(table, nodes, period, np.flatnonzero(left & (nodes.sym == s)), prec):
            if not ring_shortens(prec, table, ring, ring_rule(table, ring, "T"), nodes):
                continue
            name = table.new_name("P")
            tabled = " (table)" if not ring.constant.all() else ""
            book.add(ring_rule(table, ring, name), f"{name}: a ring of {ring.steps} nodes{tabled}")
            groups.append(ring.nodes)
            syms.append(table.symbol(name, ring.steps - 1))
            starts.append((ring.frame, ring.center))
    left[np.concatenate(groups) if groups else np.zeros(0, int)] = False
    for s in np.unique(nodes.sym[left]):
        live = np.flatnonzero(nodes.sym == s)
        for tw in find_twins(table, nodes, period, np.flatnonzero(left & (nodes.sym == s)), prec):
            if not twins_shorten(prec, table, tw, twins_rule(table, tw, nodes, "T"), nodes, live):
                continue
            name = table.new_name("P")
            book.add(twins_rule(table, tw, nodes, name), f"{name}: two copies in one pose")
            live = live[(live != tw.first) & (live != tw.second)]
            groups.append(np.array([tw.first, tw.second]))
            syms.append(table.symbol(name, 1))
            starts.append((complex(nodes.a[tw.first]), complex(nodes.b[tw.first])))
    if not groups:
        return nodes, 0
    nodes, _ = nodes.merge(groups, syms, starts=tuple(starts))
    for sid, i in zip(syms, range(len(nodes) - len(groups), len(nodes)), strict=True):
        table.set_size(sid, float(nodes.radius[i] / abs(nodes.a[i])))
    return nodes, 1


def _duplicates(table: SymbolTable, nodes: Nodes) -> list[Candidate]:
    """Sequences with the identity transform for elements drawn several times at one pose.

    Stacked copies would otherwise pair with each other in arbitrary ways; coding each
    stack as ``P(m) -> A P(m-1)`` first keeps them (nothing is lost) and out of the way.
    """
    sym, a, b = nodes.sym, nodes.a, nodes.b
    q = np.maximum(table.sizes[sym] * 1e-6, 1e-9)
    x, y = np.round(b.real / q), np.round(b.imag / q)
    if not _shared_places(x, y):
        return []  # no two nodes at one place: no stacks (the usual case)
    key = np.column_stack([sym, x, y, np.round(a.real / 1e-6), np.round(a.imag / 1e-6)])
    _, inv, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    inv = inv.ravel()
    stacks: dict[int, list[np.ndarray]] = {}
    for g in np.flatnonzero(counts >= 2):
        members = np.flatnonzero(inv == g)
        stacks.setdefault(int(sym[members[0]]), []).append(members)
    return [
        SeqCandidate(space=(s, s), groups=Groups.of(groups), h=1.0, phi=1.0, l=1.0, A=1 + 0j, B=0j)
        for s, groups in stacks.items()
    ]


def _shared_places(x: np.ndarray, y: np.ndarray) -> bool:
    """Whether two entries have equal ``x`` and equal ``y``: a sort of both, neighbours compared.

    :func:`_duplicates` asks it before grouping whole poses (``np.unique`` of the five columns
    by rows took 51 ms of a 50,052-leaf grid, this 7 ms).
    """
    order = np.lexsort((y, x))
    xs, ys = x[order], y[order]
    return bool(np.any((xs[1:] == xs[:-1]) & (ys[1:] == ys[:-1])))


def _same(ledger: Ledger) -> Ledger:
    return ledger


def _apply_all(table: SymbolTable, book: _Book, chosen: list[Candidate], nodes: Nodes) -> Nodes:
    """Apply candidates on disjoint nodes one after another, renumbering the later ones' nodes."""
    for k, cand in enumerate(chosen):
        out = emit(table, cand)
        book.add(out.rule, out.log)
        nodes, mapping = nodes.merge(
            out.groups, list(out.syms), list(cand.slack) or None, cand.starts or None
        )
        new = np.arange(len(nodes) - len(out.groups), len(nodes))
        for sid, i in zip(out.syms, new, strict=True):
            table.set_size(sid, float(nodes.radius[i] / abs(nodes.a[i])))
        chosen[k + 1 :] = [later.remapped(mapping) for later in chosen[k + 1 :]]
    return nodes
