"""Rings and arcs of copies that vary a little from copy to copy, coded with table values.

A designer draws five petals by turning one petal 72° about the flower's centre; drawn or
placed by hand, every copy ends up a little off: a few degrees off its place on the ring, a
little nearer or farther, turned a little, a little larger.  The paper's sequences (§5.5)
repeat one transformation exactly, so such a ring is left to the last rule, which places the
copies one by one.  Here it is one rule: the turn between copies is constant and every copy's
own deviation is a table value indexed by ``m``::

    P(m) -> [ +([δ…]) f([r…]) *([s…]) +([ψ…]) A ] +(φ) P(m-1)

called at the ring's centre, headed at its first copy.  Numbers that are the same for every
copy within the tolerance are written once instead of as a table.  Arcs (rings with copies
missing, or a fan of copies) are the same rule with fewer steps.

A ring is looked for among the nodes of one symbol that no exact repetition explained: the
centre is the fixed point of the turn between two copies (every pair votes), the copies are
those at about one distance from it and turned alike relative to it, and every copy must stay
within a quarter step of its place on the ring.  Like every repetition it is written only when
it shortens the description (:mod:`lsys_core.hierarchy.mdl`, see :func:`ring_shortens`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from lsys_core.grammar.model import Case, Count, Linear, Module, Pop, Push, Rule, Symbol, Turtle, TurtleOp
from lsys_core.hierarchy.describe import rule_bits
from lsys_core.hierarchy.emit import ANGLE_SNAP, nice, nice_array
from lsys_core.hierarchy.mdl import (
    OP_BITS,
    Precision,
    angle_value_bits,
    placement_set_bits,
    pose_bits,
    table_bits,
    token_bits,
)
from lsys_core.hierarchy.nodes import Nodes
from lsys_core.hierarchy.symbols import SymbolTable

__all__ = ["Ring", "find_rings", "ring_rule", "ring_shortens"]

#: Fewest copies on a ring or an arc.
MIN_COPIES = 3
#: Symbols with more unexplained nodes than this are not searched (pairs of nodes vote).
MAX_NODES = 48
#: How far a copy's distance from the centre may differ from the ring's (share of it), and how
#: much its turn relative to the centre may differ (degrees): copies beyond are not on the ring.
RADIUS_SHARE = 0.2
TURN_DEG = 20.0
#: Copies whose scale differs from the first's by more than this factor are not on its ring.
SCALE_RATIO = 1.5
#: Most of a step (share) a copy may be off its place on the ring.
OFF_STEP = 0.25
#: A ring states in its rules what placing the copies one by one says only implicitly, as
#: concentric copies do (:data:`lsys_core.hierarchy.tabulated.RULE_BITS`): it is written when
#: it is longer by at most this much.  Chance cannot make rings: the copies must be turned
#: alike relative to one centre, at one distance, evenly spaced (see the tests).
RULE_BITS = 32.0
#: Share of a copy's slack each of its four numbers may be rounded by (the rest is for numbers
#: written once for all copies).
ROUNDING = 0.05
#: Columns of :attr:`Ring.values`.
_ALPHA, _D, _S, _BETA = range(4)


@dataclass(frozen=True)
class Ring:
    """Copies of symbol ``sym`` on a ring or an arc, each a little off its place.

    Attributes
    ----------
    nodes : ndarray of int
        The nodes in the order the rule draws them (around the ring).
    center : complex
        The ring's centre (document coordinates).
    frame : complex
        The rule's frame at the centre: heading towards the first copy, scale of the first copy.
    step : float
        Turn between consecutive copies (degrees).
    values : ndarray, shape (n, 4)
        Every copy in the frame turned ``k·step``: ``+(α) f(d) *(s) +(β)`` (degrees, frame units).
    constant : ndarray of bool, shape (4,)
        Which of the four numbers are written once (their mid value) rather than as a table.
    snap : ndarray of float, shape (4,)
        How far each number may be rounded (its units) keeping every copy within its slack.
    """

    sym: int
    nodes: np.ndarray
    center: complex
    frame: complex
    step: float
    values: np.ndarray
    constant: np.ndarray
    snap: np.ndarray

    @property
    def steps(self) -> int:
        """Number of copies."""
        return int(self.nodes.size)


def _fixed_points(b: np.ndarray, th: np.ndarray, period: float, diag: float, eps: float) -> np.ndarray:
    """Centres of the turns between every two nodes (every turn the shapes' symmetry allows)."""
    n = b.size
    i, j = np.triu_indices(n, 1)
    k = round(2 * math.pi / period) if period > 0 else 1
    turns = np.arange(k) * (period if period > 0 else 0.0)
    ui = np.exp(1j * th[i])[:, None]
    uj = np.exp(1j * (th[j][:, None] + turns[None, :]))
    du = uj - ui
    ok = np.abs(du) > 2 * math.sin(math.radians(2.5))  # nearly parallel copies turn about no near point
    rho = np.where(ok, (b[j] - b[i])[:, None] / np.where(ok, du, 1.0), 0.0)
    c = b[i][:, None] - rho * ui
    far = np.abs(rho)
    keep = ok & (far > 2 * eps) & (far < diag)
    return c[keep]


def _members(
    b: np.ndarray, th: np.ndarray, scale: np.ndarray, period: float, c: np.ndarray, ref: np.ndarray
) -> np.ndarray:
    """Nodes on the ring about every centre ``c[i]`` through node ``ref[i]``: one distance, one turn, a like scale.

    Returns a boolean array of shape ``(len(c), len(b))``.
    """
    rows = np.arange(c.size)
    z = b[None, :] - c[:, None]
    r = np.abs(z)
    per = period if period > 0 else 2 * math.pi
    psi = np.mod(th[None, :] - np.angle(z), per)
    dpsi = np.abs((psi - psi[rows, ref][:, None] + per / 2) % per - per / 2)
    turned = dpsi <= math.radians(TURN_DEG) if period >= 0 else np.ones(r.shape, bool)
    ratio = scale[None, :] / scale[ref][:, None]
    r0 = r[rows, ref][:, None]
    return (
        (np.abs(r - r0) <= RADIUS_SHARE * r0) & turned & (ratio <= SCALE_RATIO) & (ratio >= 1 / SCALE_RATIO)
    )


def _reference(c: np.ndarray, b: np.ndarray) -> np.ndarray:
    """For every centre, the node whose distance from it is nearest the median distance."""
    r = np.abs(b[None, :] - c[:, None])
    return np.argmin(np.abs(r - np.median(r, axis=1)[:, None]), axis=1)


def _best_center(
    b: np.ndarray, th: np.ndarray, scale: np.ndarray, period: float, prec: Precision
) -> complex | None:
    """The centre about which most nodes lie on one ring (pairs of nodes vote), refined by least squares."""
    cands = _fixed_points(b, th, period, prec.diagonal, prec.eps)
    if cands.size == 0:
        return None
    ref = _reference(cands, b)
    mem = _members(b, th, scale, period, cands, ref)
    count = np.count_nonzero(mem, axis=1)
    r = np.abs(b[None, :] - cands[:, None])
    big = np.where(mem, r, -np.inf).max(1)
    small = np.where(mem, r, np.inf).min(1)
    spread = (big - small) / np.maximum(r[np.arange(cands.size), ref], 1e-300)
    best = int(np.lexsort((spread, -count))[0])
    if count[best] < MIN_COPIES:
        return None
    c, members = complex(cands[best]), mem[best]
    if period < 0:
        return c
    # least squares: b_k = c + ρ·u_k, the headings unwrapped to the reference's turn
    per = period if period > 0 else 2 * math.pi
    pos = np.angle(b - c)
    psi = th - pos
    k = int(ref[best])
    turn = pos + psi[k] + (psi - psi[k] + per / 2) % per - per / 2  # headings as the ring turns them
    u = np.exp(1j * turn)[members]
    m = np.column_stack([np.ones(u.size, complex), u])
    sol = np.linalg.lstsq(m, b[members], rcond=None)[0]
    return complex(sol[0])


def _ring_of(
    sym: int, idx: np.ndarray, nodes: Nodes, size: float, period: float, c: complex, prec: Precision
) -> Ring | None:
    """The ring about ``c`` among nodes ``idx``, or None when no ring of enough copies lies there."""
    b, a = nodes.b[idx], nodes.a[idx]
    cc = np.array([c])
    mem = np.flatnonzero(_members(b, np.angle(a), np.abs(a), period, cc, _reference(cc, b))[0])
    if mem.size < MIN_COPIES or np.min(np.abs(b[mem] - c)) <= 2 * prec.eps or not np.isfinite(c):
        return None  # copies at the centre: turned in place, not on a ring (concentric copies)
    ang = np.degrees(np.angle(b[mem] - c))
    order = np.argsort(ang, kind="stable")
    mem, ang = mem[order], ang[order]
    gaps = np.diff(np.append(ang, ang[0] + 360.0))
    start = (int(np.argmax(gaps)) + 1) % mem.size  # after the widest gap: an arc's open end
    mem = np.roll(mem, -start)
    ang = np.roll(ang, -start)
    inner = np.mod(np.diff(ang), 360.0)
    if inner.size == 0 or np.min(inner) <= 0:
        return None
    best: Ring | None = None
    best_bits = math.inf
    for step in _steps(inner, mem.size):
        ring = _values(sym, idx[mem], nodes, size, period, c, step)
        if ring is None:
            continue
        bits = _table_cost(prec, ring, size)
        if bits < best_bits:
            best, best_bits = ring, bits
    return best


def _steps(inner: np.ndarray, n: int) -> list[float]:
    """Turns between copies to try: the even division of the circle nearest, and the mean gap."""
    mean = float(np.mean(inner))
    k = max(round(360.0 / mean), n)
    out = [360.0 / k]
    if abs(out[0] - mean) > 1e-9:
        out.append(mean)
    return out


def _values(
    sym: int, idx: np.ndarray, nodes: Nodes, size: float, period: float, c: complex, step: float
) -> Ring | None:
    """Every copy's ``+(α) f(d) *(s) +(β)`` in the ring's frame turned by ``k·step``; None if one strays."""
    b, a = nodes.b[idx], nodes.a[idx]
    u0 = (b[0] - c) / abs(b[0] - c)
    frame = u0 * abs(a[0])
    k = np.arange(idx.size)
    fk = frame * np.exp(1j * np.radians(step * k))
    B = (b - c) / fk
    R = a / fk
    alpha = np.degrees(np.angle(B))
    if np.max(np.abs(alpha)) > OFF_STEP * abs(step):
        return None
    d = np.abs(B)
    s = np.abs(R)
    beta = np.degrees(np.angle(R)) - alpha
    if period > 0:  # turns the shape's symmetry hides: the one nearest the first copy's
        per = math.degrees(period)
        beta = beta[0] + (beta - beta[0] + per / 2) % per - per / 2
    elif period < 0:  # round: any turn draws it
        beta = np.full(idx.size, 0.0)
    else:
        beta = beta[0] + (beta - beta[0] + 180.0) % 360.0 - 180.0
    values = np.column_stack([alpha, d, s, beta])
    sigma = abs(a[0])
    lever = size * sigma * s

    def errors(at: np.ndarray) -> np.ndarray:
        """How far every copy moves when each number is written once as ``at``."""
        return np.column_stack(
            [
                sigma * d * np.radians(np.abs(alpha - at[_ALPHA])),
                sigma * np.abs(d - at[_D]),
                lever * np.abs(np.log(s / at[_S])),
                lever * np.radians(np.abs(beta - at[_BETA])),
            ]
        )

    # a number written once is the value most copies have (the median: the copies it moves
    # move least in all), or the mid value (the farthest copy moves least) when only that fits
    mid = (values.max(0) + values.min(0)) / 2
    median = np.median(values, axis=0)
    err_mid, err_median = errors(mid), errors(median)
    budget = (1.0 - 4 * ROUNDING) * float(np.min(nodes.slack[idx]))
    constant = np.zeros(4, bool)
    used = np.zeros(idx.size)
    for col in np.argsort(err_mid.max(0), kind="stable"):
        for at, err in ((median, err_median), (mid, err_mid)):
            if np.max(used + err[:, col]) <= budget:
                constant[col] = True
                used += err[:, col]
                mid[col] = at[col]
                break
    values = np.where(constant[None, :], mid[None, :], values)
    room = ROUNDING * float(np.min(nodes.slack[idx]))
    reach = sigma * float(np.max(d))
    rim = float(np.max(lever))
    snap = np.array([np.degrees(room / max(reach, 1e-300)), room / sigma, room / max(rim, 1e-300), 0.0])
    snap[_BETA] = np.degrees(room / max(rim, 1e-300))
    return Ring(sym, idx, c, frame, float(step), values, constant, snap)


def _table_cost(prec: Precision, ring: Ring, size: float) -> float:
    """Bits of the ring's tables, each number at the precision of what it moves."""
    sigma = abs(ring.frame)
    reach = sigma * float(np.median(ring.values[:, _D]))
    lever = size * sigma * float(np.median(ring.values[:, _S]))
    bits = angle_value_bits(prec, ring.step)
    for col, op, at in ((_ALPHA, "+", reach), (_D, "f", None), (_S, "*", lever), (_BETA, "+", lever)):
        v = ring.values[:, col] * (sigma if col == _D else 1.0)
        if not ring.constant[col]:
            bits += table_bits(prec, v, op, at)
        elif col == _D or abs(v[0] - (1.0 if col == _S else 0.0)) > 1e-9:
            bits += (
                prec.length_bits if col == _D else (prec.scale_bits(at) if col == _S else prec.angle_bits(at))
            )
    return bits


def find_rings(
    table: SymbolTable, nodes: Nodes, period: np.ndarray, idx: np.ndarray, prec: Precision
) -> list[Ring]:
    """Rings and arcs among nodes ``idx`` (all of one symbol), largest first, disjoint.

    Parameters
    ----------
    table : SymbolTable
        The hierarchy's symbols (their sizes).
    nodes : Nodes
        The live nodes.
    period : ndarray of float
        Rotational symmetry of every symbol: ``2π/k`` for k-fold, -1 for round, 0 for none.
    idx : ndarray of int
        Nodes of one symbol that no repetition explained yet.
    prec : Precision
        The tolerance and the drawing's size.
    """
    if idx.size < MIN_COPIES or idx.size > MAX_NODES:
        return []
    sym = int(nodes.sym[idx[0]])
    size = float(table.sizes[sym])
    per = float(period[sym]) if sym < period.size else 0.0
    free = idx.copy()
    out: list[Ring] = []
    while free.size >= MIN_COPIES:
        c = _best_center(nodes.b[free], np.angle(nodes.a[free]), np.abs(nodes.a[free]), per, prec)
        ring = None if c is None else _ring_of(sym, free, nodes, size, per, c, prec)
        if ring is None:
            break
        out.append(ring)
        free = free[~np.isin(free, ring.nodes)]
    return out


def ring_rule(table: SymbolTable, ring: Ring, name: str) -> Rule:
    """The rule ``name(m)`` drawing ``ring`` when called with ``m = steps - 1`` at its centre."""
    values = ring.values[::-1]  # entry m is drawn by the step with counter m: the last copy is entry 0
    mods: list[Module] = [Push()]
    ops: tuple[tuple[int, TurtleOp], ...] = ((_ALPHA, "+"), (_D, "f"), (_S, "*"), (_BETA, "+"))
    for col, op in ops:
        v = values[:, col]
        tol = float(ring.snap[col]) * (float(np.min(v)) if op == "*" else 1.0)
        if ring.constant[col]:
            c0 = nice(float(v[0]), abs_tol=tol)
            if (op == "*" and abs(c0 - 1.0) <= 1e-9) or (op != "*" and abs(c0) <= 1e-9):
                continue
            mods.append(Turtle(op, Linear(c0)))
        else:
            mods.append(Turtle(op, Linear.of_table(nice_array(v, abs_tol=tol))))
    mods += [*table.draw(ring.sym, last=True), Pop()]
    # the step's rounding adds up over the copies: a share of one copy's turn tolerance over their count
    mods += [
        Turtle("+", Linear(nice(ring.step, abs_tol=max(float(ring.snap[_ALPHA]) / ring.steps, ANGLE_SNAP))))
    ]
    return Rule(name, True, (Case(None, (*mods, Symbol(name, Count(-1, 1)))),))


def ring_shortens(prec: Precision, table: SymbolTable, ring: Ring, rule: Rule, nodes: Nodes) -> bool:
    """Whether the ring codes its copies in fewer bits (up to :data:`RULE_BITS`) than placing them one by one.

    One by one, the copies cost what they add to the set of all live nodes of their symbol (set
    code, :func:`~lsys_core.hierarchy.mdl.placement_set_bits`); the ring costs its rule's tokens
    with every table at the precision of what its numbers move (a turn about the centre at the
    ring's radius, a copy's own turn and scale at its rim), and its call: a place and a heading.
    """
    token = token_bits(len(table) + 1)
    n = ring.nodes.size
    a = nodes.a[ring.nodes]
    lever = table.sizes[ring.sym] * np.abs(a)
    _, stacks = np.unique(prec.cell_ids(nodes.b[ring.nodes]), return_counts=True)
    pose = pose_bits(*prec.pose_model(a, lever), stacks)
    total = int(np.count_nonzero(nodes.sym == ring.sym))
    alone = placement_set_bits(prec, total, pose=pose, token=token) - placement_set_bits(
        prec, total - n, token=token
    )
    plain = Rule(
        rule.name,
        True,
        tuple(
            Case(cs.cond, tuple(m for m in cs.body if not (isinstance(m, Turtle) and m.op != "z")))
            for cs in rule.cases
        ),
    )
    size = float(table.sizes[ring.sym])
    reach = abs(ring.frame) * float(np.median(ring.values[:, _D]))
    call = placement_set_bits(prec, 1, token=token) + prec.angle_bits(reach)
    ops = sum(isinstance(m, Turtle) and m.op != "z" for cs in rule.cases for m in cs.body)
    coded = rule_bits(prec, token, plain) + _table_cost(prec, ring, size) + OP_BITS * ops
    return bool(coded + call <= alone + RULE_BITS)
