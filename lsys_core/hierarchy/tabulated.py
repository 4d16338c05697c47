"""Partly regular repetitions: one shape and one step repeated while one number varies freely.

The paper's sequences (§5.5) repeat one transformation exactly, so every number of the step is
the same from copy to copy.  Real drawings often repeat a shape in a pattern that is regular in
all but one number:

* *concentric copies*: one shape drawn several times about one centre, at sizes that follow no
  progression (the rings of a wheel, a target), coded ``P(m) -> [ *([s…]) A ] P(m-1)``;
* *rows at data positions*: copies evenly spaced along an axis (rows of a dot plot, bars of a
  chart) but each moved across it by its own amount, coded
  ``P(m) -> [ +(φ) f([o…]) +(-φ) A ] +(ψ) f(d) +(-ψ) P(m-1)``; the copies may be stretched
  copies of one shape (:mod:`lsys_core.instancing.stretch`: the bars of a bar chart, of one
  width and free heights), each drawn with its stretch, ``[ +(φ) f([o…]) +(-φ) ~([t…]) A ]``.
  In such a row, offsets and stretches that change by one amount per step (bars growing by
  16, their centres rising by 8) are written linear in ``m`` instead of as tables.
  A row steps over stray copies of its shape among its levels (a chart's legend drawn with
  the same dots), each of its copies within the tolerance of the row's place.

The free number is written as a table value (``[v0, v1, …]``, entry ``m``), the rest as one
rule.  These are looked for among the nodes that no exact repetition explained, just before the
last rule places the rest one by one.  A row is written only when it shortens the description
(:mod:`lsys_core.hierarchy.mdl`): its table entries cost ``log2(range/eps + 1)`` bits each, while
placing the copies one by one costs what they add to the set of all placements of their shape;
rows of a handful of copies, or copies spread over the drawing, stay placed one by one.
Concentric copies cost as many bits either way and are written as a rule (see :data:`RULE_BITS`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from lsys_core.grammar.model import Case, Count, Linear, Module, Pop, Push, Rule, Symbol, Turtle
from lsys_core.hierarchy.describe import rule_bits, run_bits
from lsys_core.hierarchy.emit import ANGLE_SNAP, const_t, nice, nice_array
from lsys_core.hierarchy.mdl import (
    KIND_BITS,
    OP_BITS,
    Precision,
    angle_value_bits,
    count_bits,
    placement_set_bits,
    pose_bits,
    table_bits,
    token_bits,
    transform_bits,
)
from lsys_core.hierarchy.nodes import Nodes
from lsys_core.hierarchy.symbols import SymbolTable

__all__ = ["Tabulated", "find_tabulated", "shortens", "tabulated_rule"]

#: Fewest copies a partly regular repetition must have.
MIN_COPIES = 3
#: Concentric copies are coded by the set code of placements (:mod:`.mdl`) as copies stacked at
#: one place, with one scale each: the same numbers the rule writes.  The rule is written when it
#: is longer by at most this much, its fixed cost (kind, name, count, brackets, call), since it
#: then states in the rules what the set code says implicitly.  (Copies at random places never
#: share a centre, so this cannot turn chance into rules.)
RULE_BITS = 32.0
#: Share of its nodes' slack a row of stretched copies may spend writing an offset or a stretch
#: that grows by one amount per step as a value linear in ``m`` instead of a table.
LINEAR_SHARE = 0.25
#: Axes rows are looked for along: the canvas's (charts and designers' grids are aligned to them).
AXES = (1 + 0j, 1j)
#: Stray levels a row may step over to find its second level (between later levels, any number).
STRAYS = 2


@dataclass(frozen=True)
class Tabulated:
    """One partly regular repetition of symbol ``sym``.

    Attributes
    ----------
    nodes : ndarray of int
        The nodes it covers, in the order it draws them (its first node first).
    kind : str
        ``"scale"`` (concentric copies, the scale varies) or ``"offset"`` (a row along ``axis``
        whose copies move across it).
    axis : complex
        Unit direction of the row in document coordinates (1 for concentric copies).
    step : float
        Distance between consecutive copies along the axis (0 for concentric copies).
    values : ndarray of float
        The free number of every copy, one row per step of the rule in drawing order: its
        scale relative to the first copy (one column), or its offset across the axis from the
        first copy (document units; one column per copy at each level of the row).
    stretch : ndarray of float, optional
        For a row of stretched copies of ``sym``, every copy's stretch (shaped like ``values``).
    """

    sym: int
    nodes: np.ndarray
    kind: str
    axis: complex
    step: float
    values: np.ndarray
    stretch: np.ndarray | None = None

    @property
    def steps(self) -> int:
        """Applications of the rule's step: the levels of a row, the copies of a concentric set."""
        return int(self.values.shape[0])


def _turn_error(a: np.ndarray, a0: complex, lever: np.ndarray, period: float) -> np.ndarray:
    """How far turning from ``a0`` to every ``a`` moves a shape's rim (0 for round shapes)."""
    if period < 0:
        return np.zeros(a.size)
    turn = np.angle(a / a0)
    if period > 0:
        turn = (turn + period / 2) % period - period / 2
    return np.abs(turn) * lever


def _concentric(sym: int, idx: np.ndarray, nodes: Nodes, size: float, period: float) -> list[Tabulated]:
    """Sets of at least :data:`MIN_COPIES` nodes about one centre, in document order."""
    out: list[Tabulated] = []
    b = nodes.b[idx]
    slack = nodes.slack[idx]
    q = max(float(np.min(slack)), 1e-12)
    keys = np.column_stack([np.round(b.real / q), np.round(b.imag / q)])
    _, inv, counts = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
    inv = inv.ravel()
    by_place = np.argsort(inv, kind="stable")  # document order within each place
    bounds = np.concatenate(([0], np.cumsum(counts)))
    for g in np.flatnonzero(counts >= MIN_COPIES):
        members = idx[by_place[bounds[g] : bounds[g + 1]]]
        a = nodes.a[members]
        lever = size * np.abs(a)
        moved = np.abs(nodes.b[members] - nodes.b[members[0]])
        moved = moved + _turn_error(a, a[0], lever, period)
        if np.any(moved > nodes.slack[members]):
            continue
        scales = np.abs(a) / abs(a[0])
        if np.ptp(np.log(scales)) * size * abs(a[0]) <= q:
            continue  # stacked copies of one size: the duplicates' rule codes them
        out.append(Tabulated(sym, members, "scale", 1 + 0j, 0.0, scales[:, None]))
    return out


def _pose_groups(idx: np.ndarray, nodes: Nodes, size: float, period: float, q: float) -> list[np.ndarray]:
    """Split ``idx`` into groups of one pose: scale and heading alike within ``q`` at the shape's rim."""
    a = nodes.a[idx]
    lever = max(size * float(np.max(np.abs(a))), 1e-300)
    turn = np.zeros(a.size) if period < 0 else np.angle(a)
    if period > 0:
        turn = turn % period
    key = np.column_stack([np.round(np.log(np.abs(a)) * lever / q), np.round(turn * lever / q)])
    _, inv = np.unique(key, axis=0, return_inverse=True)
    inv = inv.ravel()
    return [idx[inv == g] for g in range(int(inv.max(initial=-1)) + 1)]


def _level_runs(
    along: np.ndarray, q: float, merge: float | None = None
) -> list[tuple[np.ndarray, int, float]]:
    """Runs of evenly spaced levels holding equally many values each.

    ``along`` is sorted; values within ``merge`` (default ``q``) of the previous one share a
    level.  Returns ``(indices into along, count per level, step)`` of every run of at least
    :data:`MIN_COPIES` levels whose places fit ``start + i·step`` within ``q``, ``count``
    indices per level in level order.  A run steps over stray values between its levels (a
    legend's dot beside the rows of a chart), and a level holding strays besides its ``count``
    values gives the run the values nearest its place.
    """
    gap = q if merge is None else merge
    starts = np.flatnonzero(np.concatenate(([True], np.diff(along) > gap)))
    counts = np.diff(np.append(starts, along.size))
    level = np.add.reduceat(along, starts) / counts
    runs = []
    i = 0
    while i + MIN_COPIES <= level.size:
        path, step = _walk(level, counts, i, q, gap)
        span = level[path] - level[i]
        if path.size >= 2 and np.max(np.abs(span - np.arange(path.size) * step)) > q:
            step = float(span[1])  # the gaps drift: keep what the first gap fits
            bad = np.flatnonzero(np.abs(span - np.arange(path.size) * step) > q)
            path = path[: int(bad[0])] if bad.size else path
        k = int(counts[i])
        at: list[np.ndarray] = []
        for n, c in enumerate(path if step > 2 * gap else ()):
            near = _nearest(along, starts[c], counts[c], level[i] + n * step, k)
            if np.max(np.abs(along[near] - level[i] - n * step)) > q:
                break  # a level spread wider than the tolerance (values chained within ``merge``)
            at.append(near)
        if len(at) >= MIN_COPIES:
            runs.append((np.concatenate(at), k, float(step)))
            i = int(path[len(at) - 1]) + 1
        else:
            i += 1
    return runs


def _walk(level: np.ndarray, counts: np.ndarray, i: int, q: float, gap: float) -> tuple[np.ndarray, float]:
    """Levels evenly spaced from level ``i`` holding at least its count, and their mean step.

    The step is the gap to the next such level at most :data:`STRAYS` levels on; each next level
    is the one nearest the place the step predicts, within ``q``; levels between are strays.
    """
    k = counts[i]
    ahead = np.flatnonzero(counts[i + 1 : i + 2 + STRAYS] >= k)
    if not ahead.size:
        return np.array([i]), 0.0
    path = [i, i + 1 + int(ahead[0])]
    step = float(level[path[1]] - level[i])
    if step <= 2 * gap:
        return np.array(path), step
    while True:
        want = level[path[-1]] + step
        c = int(np.searchsorted(level, want))
        c = c - 1 if c == level.size or (c > 0 and want - level[c - 1] < level[c] - want) else c
        if c <= path[-1] or abs(level[c] - want) > q or counts[c] < k:
            break
        path.append(c)
        step = float(level[c] - level[i]) / (len(path) - 1)
    return np.array(path), step


def _nearest(along: np.ndarray, start: int, count: int, place: float, k: int) -> np.ndarray:
    """Indices of the ``k`` values of the level ``along[start:start+count]`` nearest ``place``, in order."""
    if count == k:
        return np.arange(start, start + k)
    near = np.argsort(np.abs(along[start : start + count] - place), kind="stable")[:k]
    return start + np.sort(near)


def _merge(along: np.ndarray) -> float:
    """How close copies of a row of stretched copies must be along it to share a level.

    Bars of a chart stand apart by their spacing, which may be less than the tolerance in a
    wide chart: a quarter of the median gap between distinct places keeps them apart.
    """
    gaps = np.diff(np.unique(along))
    return 0.25 * float(np.median(gaps)) if gaps.size else 0.0


def _rows(
    sym: int, idx: np.ndarray, nodes: Nodes, size: float, period: float, stretch: np.ndarray | None = None
) -> list[Tabulated]:
    """Rows along a canvas axis: evenly spaced levels with as many copies each, moved across freely.

    ``stretch`` (per node, None: none) is the stretch every node is drawn with.
    """
    out: list[Tabulated] = []
    q = max(float(np.min(nodes.slack[idx])), 1e-12)
    first = nodes.first_members()
    for group in _pose_groups(idx, nodes, size, period, q):
        free = np.ones(group.size, bool)
        while np.count_nonzero(free) >= MIN_COPIES:  # the longest row first, along either axis
            members = group[free]
            best = None
            for axis in AXES:
                along = (nodes.b[members] / axis).real
                order = np.lexsort((first[members], along))
                for at, k, step in _level_runs(
                    along[order], q, _merge(along) if stretch is not None else None
                ):
                    if best is None or at.size > best[1].size:
                        best = (axis, members[order[at]], k, step)
            if best is None:
                break
            axis, run, k, step = best
            # level by level, each level's copies in document order
            run = run.reshape(-1, k)
            run = np.take_along_axis(run, np.argsort(first[run], axis=1, kind="stable"), axis=1)
            across = (nodes.b[run] / axis).imag
            st = None if stretch is None else stretch[run]
            out.append(Tabulated(sym, run.ravel(), "offset", axis, step, across - across[0, 0], st))
            free[np.isin(group, run)] = False
    return out


def find_tabulated(table: SymbolTable, nodes: Nodes, period: np.ndarray) -> list[Tabulated]:
    """Partly regular repetitions among ``nodes`` (disjoint), concentric copies first.

    Parameters
    ----------
    table : SymbolTable
        The hierarchy's symbols (their sizes).
    nodes : Nodes
        The live nodes; their slack bounds how far a repetition may move each.
    period : ndarray of float
        Rotational symmetry of every symbol: ``2π/k`` for k-fold, -1 for round, 0 for none.
    """
    first = nodes.first_members()
    sizes = table.sizes
    found: list[Tabulated] = []
    taken = np.zeros(len(nodes), bool)
    family = table.stretch_family(nodes.sym)
    drawn = table.stretch_of(nodes.sym)
    for key in np.unique(family):
        idx = np.flatnonzero(family == key)
        if idx.size < MIN_COPIES:
            continue
        idx = idx[np.argsort(first[idx], kind="stable")]
        size = float(np.max(sizes[np.unique(nodes.sym[idx])]))
        per = float(period[key]) if key < period.size else 0.0
        stretched = bool(np.any(drawn[idx] != 0))
        for find in (_concentric, _rows):
            free = idx[~taken[idx]]
            if free.size < MIN_COPIES:
                break
            if find is _concentric:
                if stretched:
                    continue  # concentric copies at one stretch each: not looked for
                parts = find(int(key), free, nodes, size, per)
            else:
                parts = _rows(int(key), free, nodes, size, per, drawn if stretched else None)
            for t in parts:
                found.append(t)
                taken[t.nodes] = True
    return found


def tabulated_rule(table: SymbolTable, t: Tabulated, name: str, nodes: Nodes) -> Rule:
    """The rule ``name(m)`` drawing repetition ``t`` when called with ``m = steps - 1`` at its first node."""
    a0 = nodes.a[t.nodes[0]]
    values = t.values[::-1]  # entry m is drawn by the step with counter m: the last level is entry 0
    draws: list[Module] = []
    if t.kind == "scale":
        scales = Linear.of_table(nice_array(values[:, 0], rel_tol=1e-6))
        draws += [Push(), Turtle("*", scales), *table.draw(t.sym, last=True), Pop()]
        step: tuple[Module, ...] = ()
    else:
        turn = nice(float(np.degrees(np.angle(t.axis * 1j / a0))), abs_tol=ANGLE_SNAP)
        tiny = 1e-6 * (float(np.max(np.abs(values))) + 1e-12)
        # a row of stretched copies writes offsets and stretches that grow by one step as linear
        close = LINEAR_SHARE * float(np.min(nodes.slack[t.nodes])) / abs(a0) if t.stretch is not None else 0.0
        stretch = None if t.stretch is None else t.stretch[::-1]
        across = 0.0  # offsets that grow by one amount per step: moved by the step instead
        for c, track in enumerate(values.T / abs(a0)):
            free: tuple[Module, ...] = ()
            offsets = _free_value(track, tiny, close) if np.max(np.abs(track)) > tiny else None
            if offsets is not None and not offsets.table and values.shape[1] == 1:
                across, offsets = -offsets.cd, None  # entry m - 1 is the next step's: 0 at the first
            if offsets is not None:
                free = (Turtle("+", Linear(turn)), Turtle("f", offsets), Turtle("+", Linear(-turn)))
            if stretch is not None and np.any(stretch[:, c] != 0):
                free += (
                    Turtle("~", _free_value(stretch[:, c], 1e-9 * float(np.max(np.abs(stretch))), close)),
                )
            draws += [Push(), *free, *table.draw(t.sym, last=True), Pop()]
        step = const_t(1 + 0j, (t.step * t.axis + across * abs(a0) * t.axis * 1j) / a0)
    # one case for every m >= 0: each table is written once; P(-1) draws nothing and ends it
    return Rule(name, True, (Case(None, (*draws, *step, Symbol(name, Count(-1, 1)))),))


def _free_value(track: np.ndarray, tiny: float, close: float) -> Linear:
    """The value of entry ``m`` of ``track``: linear in ``m`` when it fits within ``close``, else a table."""
    if close > 0 and track.size >= 2:
        m = np.arange(track.size)
        cd = nice(float(track[-1] - track[0]) / (track.size - 1), abs_tol=0.1 * close / track.size)
        c0 = nice(float(np.mean(track - cd * m)), abs_tol=0.1 * close)
        if np.max(np.abs(c0 + cd * m - track)) <= close:
            return Linear(c0, cd)
    return Linear.of_table(nice_array(track, abs_tol=tiny))


def shortens(prec: Precision, table: SymbolTable, t: Tabulated, rule: Rule, nodes: Nodes) -> bool:
    """Whether the rule codes the repetition in fewer bits than placing its nodes one by one.

    One by one, the nodes cost what they add to the set of all live nodes of their symbol (set
    code, :func:`~lsys_core.hierarchy.mdl.placement_set_bits`).  A row is coded by its kind, symbol,
    count, step, the direction of its offsets, their range and every offset at that range;
    concentric copies by the rule's tokens with scales at the precision of the shape's rim.
    """
    token = token_bits(len(table) + 1)
    n = t.nodes.size
    a = nodes.a[t.nodes]
    lever = table.sizes[t.sym] * np.abs(a)
    _, stacks = np.unique(prec.cell_ids(nodes.b[t.nodes]), return_counts=True)
    pose = pose_bits(*prec.pose_model(a, lever), stacks)
    total = int(np.count_nonzero(table.stretch_family(nodes.sym) == t.sym))
    alone = placement_set_bits(prec, total, pose=pose, token=token) - placement_set_bits(
        prec, total - n, token=token
    )
    call = placement_set_bits(prec, 1, token=token)
    if t.kind == "scale":  # scales are worth the bits that move the shape's rim by eps, as in the set code
        scales = next(m.value for m in rule.cases[0].body if isinstance(m, Turtle) and m.value.table)
        plain = replace(rule, cases=(Case(None, tuple(m for m in rule.cases[0].body if m != scales)),))
        lever_bits = table_bits(prec, scales.table, "*", float(np.median(lever)))
        return bool(rule_bits(prec, token, plain) + lever_bits + call <= alone + RULE_BITS)
    a0 = nodes.a[t.nodes[0]]
    if t.stretch is not None:  # as written: step, offsets and stretches (tables or linear in m)
        body = rule.cases[0].body
        moves = [m for m in body[body.index(Pop()) + 1 : -1] if isinstance(m, Turtle)]
        written = [m.value for m in body[: body.index(Pop())] if isinstance(m, Turtle) and m.op in ("f", "~")]
        turns = any(isinstance(m, Turtle) and m.op == "f" for m in body[: body.index(Pop())])
        coded = (
            KIND_BITS
            + token
            + float(count_bits(t.steps) + count_bits(t.values.shape[1]))
            + run_bits(prec, moves)
            + (angle_value_bits(prec, float(np.degrees(np.angle(t.axis * 1j / a0)))) if turns else 0.0)
            + sum(_value_bits(prec, v) for v in written)
        )
        alone += np.count_nonzero(t.stretch) * (OP_BITS + prec.length_bits)
        return bool(coded + call < alone)
    coded = (
        KIND_BITS
        + token
        + float(count_bits(t.steps) + count_bits(t.values.shape[1]))
        + transform_bits(prec, 1 + 0j, t.step * t.axis / a0 * abs(a0))
        + angle_value_bits(prec, float(np.degrees(np.angle(t.axis * 1j / a0))))
        + sum(table_bits(prec, track, "f") for track in t.values.T)
    )
    return bool(coded + call < alone)


def _value_bits(prec: Precision, v: Linear) -> float:
    """Bits of a distance written as a table or as ``c0 + cd*m``."""
    if v.table:
        return table_bits(prec, v.table, "f")
    return OP_BITS + prec.length_bits * ((v.c0 != 0) + (v.cd != 0))
