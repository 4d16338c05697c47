"""Two copies of one shape in one pose, drawn once: a sequence of two (``P(1)``).

Two binding rings on a calendar, two eyes, two handles: identical copies at one heading and
scale that the rest of the drawing places in other poses.  No cluster of pairs finds them (a
single pair repeats no transform), so they are left to the last rule, which places them one by
one: each copy states its heading and scale there, as every placement of a shape does when the
shape's placements vary in them.  As a sequence of two they are stated once, with the offset
between the copies::

    P(m): m > 0 -> A f(d) P(m-1)
    P(m): m == 0 -> A

Like every repetition it is written only when it shortens the description
(:mod:`lsys_core.hierarchy.mdl`), with no allowance: copies in one pose at chance places do
not pay for the rule (placed one by one they state no pose either), nor do copies that would
need a turn or a scale between them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lsys_core.grammar.model import COND_EQ0, COND_GT0, Case, Count, Rule, Symbol
from lsys_core.hierarchy.describe import rule_bits
from lsys_core.hierarchy.emit import const_t
from lsys_core.hierarchy.mdl import Precision, placement_set_bits, pose_bits, token_bits
from lsys_core.hierarchy.nodes import Nodes
from lsys_core.hierarchy.symbols import SymbolTable

__all__ = ["Twins", "find_twins", "twins_rule", "twins_shorten"]

#: Symbols with more unexplained nodes than this are not searched (every two nodes are compared).
MAX_NODES = 48
#: Share of a copy's slack the pose between the two copies may differ by (the rest is rounding).
POSE_SHARE = 0.5


@dataclass(frozen=True)
class Twins:
    """Copies ``first`` and ``second`` of symbol ``sym``; ``turn`` is the second's pose relative to the first's.

    ``turn`` is 1 unless the shape's symmetry makes a turn draw it alike (a line turned 180°).
    """

    sym: int
    first: int
    second: int
    turn: complex

    def offset(self, nodes: Nodes) -> complex:
        """The second copy's place in the frame of the first."""
        return complex((nodes.b[self.second] - nodes.b[self.first]) / nodes.a[self.first])


def _turns(a: np.ndarray, period: float) -> np.ndarray:
    """For every two poses, the turn the shape's symmetry allows that brings the first nearest the second."""
    rel = a[None, :] / a[:, None]
    if period < 0:  # round: any turn draws it
        return np.exp(1j * np.angle(rel))
    if period <= 0:
        return np.ones_like(rel)
    k = np.round(np.angle(rel) / period)
    return np.exp(1j * k * period)


def find_twins(
    table: SymbolTable, nodes: Nodes, period: np.ndarray, idx: np.ndarray, prec: Precision
) -> list[Twins]:
    """Disjoint pairs of nodes ``idx`` (all of one symbol) in one pose, nearest first.

    Two nodes are in one pose when the second, drawn at the first's heading and scale (turned
    as its symmetry allows), moves by less than :data:`POSE_SHARE` of either's slack.
    """
    if idx.size < 2 or idx.size > MAX_NODES:
        return []
    sym = int(nodes.sym[idx[0]])
    size = float(table.sizes[sym])
    per = float(period[sym]) if sym < period.size else 0.0
    a, b = nodes.a[idx], nodes.b[idx]
    turn = _turns(a, per)
    moved = size * np.abs(a[None, :] - a[:, None] * turn)
    slack = nodes.slack[idx]
    room = POSE_SHARE * np.minimum(slack[:, None], slack[None, :])
    dist = np.abs(b[None, :] - b[:, None])
    ok = (moved <= room) & (dist > 2 * prec.eps)
    ok &= np.triu(np.ones(ok.shape, bool), 1)
    i, j = np.nonzero(ok)
    out: list[Twins] = []
    used = np.zeros(idx.size, bool)
    for k in np.argsort(dist[i, j], kind="stable"):
        p, q = int(i[k]), int(j[k])
        if used[p] or used[q]:
            continue
        used[p] = used[q] = True
        out.append(Twins(sym, int(idx[p]), int(idx[q]), complex(turn[p, q])))
    return out


def twins_rule(table: SymbolTable, twins: Twins, nodes: Nodes, name: str) -> Rule:
    """The rule ``name(m)`` drawing ``twins`` when called with ``m = 1`` at the first copy's pose."""
    step = const_t(twins.turn, twins.offset(nodes))
    gt = Case(COND_GT0, (*table.draw(twins.sym), *step, Symbol(name, Count(-1, 1))))
    return Rule(name, True, (gt, Case(COND_EQ0, table.draw(twins.sym, last=True))))


def twins_shorten(
    prec: Precision, table: SymbolTable, twins: Twins, rule: Rule, nodes: Nodes, live: np.ndarray
) -> bool:
    """Whether the sequence codes the two copies in fewer bits than placing them one by one.

    One by one, the copies cost what they add to the set of the ``live`` nodes of their symbol
    (set code with the headings and scales of that set,
    :func:`~lsys_core.hierarchy.mdl.placement_set_bits`); the sequence costs its rule and its
    call: a place, and the first copy's heading and scale where they are not the identity's.
    """
    token = token_bits(len(table) + 1)
    size = float(table.sizes[twins.sym])

    def set_bits(members: np.ndarray) -> float:
        if members.size == 0:
            return 0.0
        a = nodes.a[members]
        _, stacks = np.unique(prec.cell_ids(nodes.b[members]), return_counts=True)
        pose = pose_bits(*prec.pose_model(a, size * np.abs(a)), stacks)
        return float(placement_set_bits(prec, members.size, pose=pose, token=token))

    rest = live[(live != twins.first) & (live != twins.second)]
    alone = set_bits(live) - set_bits(rest)
    a0 = complex(nodes.a[twins.first])
    lever = size * abs(a0)
    call = float(placement_set_bits(prec, 1, token=token))
    if abs(np.angle(a0)) * lever > 0.5 * prec.eps:
        call += prec.angle_bits(lever)
    if abs(np.log(abs(a0))) * lever > 0.5 * prec.eps:
        call += prec.scale_bits(lever)
    return bool(rule_bits(prec, token, rule) + call < alone)
