"""Which candidate rules a level applies: importance (§5.4) among those that shorten the description.

The paper's importance ``w = wn·n + wh·h + wφ·φ + wl·l`` orders the candidates; a candidate is
applied only when it is *worthwhile*: its numbers rounded (:mod:`lsys_core.hierarchy.snap`),
it derives every node it explains within the tolerance left to that node, and it shortens the
description (:mod:`lsys_core.hierarchy.gain`, minimum description length).
"""

from __future__ import annotations

import cmath
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from lsys_core.hierarchy.candidates import BranchCandidate, Candidate, PairCandidate, SeqCandidate
from lsys_core.hierarchy.gain import Ledger, group_reach, placement_error
from lsys_core.hierarchy.nodes import Nodes
from lsys_core.hierarchy.rivals import Rivals
from lsys_core.hierarchy.snap import SHARE, plainer, snapped
from lsys_core.settings import setting

__all__ = [
    "WEAK_COVER",
    "Measure",
    "Weights",
    "choose",
    "importance_order",
    "importance_terms",
    "scores",
    "worthwhile",
]

#: ``measure(elements, a, b)``: how far input elements would be from their terminals drawn at poses ``a, b``.
Measure = Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]
#: A best candidate covering less than this share of the nodes is applied together with all
#: other candidates on disjoint nodes (see :func:`choose`).
WEAK_COVER = 0.05


@dataclass(frozen=True)
class Weights:
    """User weights of the cluster importance ``w = wn·n + wh·h + wφ·φ + wl·l``, each in [0, 1]."""

    wn: float = setting("wn").default
    wh: float = setting("wh").default
    wphi: float = setting("wphi").default
    wl: float = setting("wl").default


def _invertible(c: Candidate) -> bool:
    """Whether every transform of ``c`` is finite with a non-zero scale."""
    if isinstance(c, (SeqCandidate, PairCandidate)):
        transforms = [(c.A, c.B)]
    elif isinstance(c, BranchCandidate):
        transforms = [c.first, c.second]
    else:
        transforms = []
    return all(cmath.isfinite(a) and cmath.isfinite(b) and abs(a) > 0.0 for a, b in transforms)


def worthwhile(
    c: Candidate,
    ledger: Ledger,
    nodes: Nodes,
    sizes: np.ndarray,
    period: np.ndarray,
    snap: float,
    measure: Measure | None = None,
    n_terminals: int = 0,
    limit: float = np.inf,
    ceiling: Callable[[Candidate], float] | None = None,
) -> Candidate | None:
    """The candidate with its numbers rounded, if it shortens the description within the tolerance.

    This is the minimum description length test (:mod:`lsys_core.hierarchy.mdl`): a transform
    that repeats by chance among unrelated elements does not pay for its rule.  Its numbers
    are rounded first (:func:`~lsys_core.hierarchy.snap.snapped`), and the rule, derived from
    each application's first node, must put every node within its slack (what is left of the
    tolerance once its shapes and earlier rules have used their part).  Where that bound is
    too coarse for single elements (hand-drawn copies: shape and pose noise add up on paper,
    not on the page), ``measure`` tells how far the derived element really is.  The plainer
    variant (:func:`~lsys_core.hierarchy.snap.plainer`) is taken first when it fits; between
    exact copies (which stray from ``c`` and from their shape by less than rounding at the
    user's precision may, :data:`~lsys_core.hierarchy.snap.SHARE` of the tolerance) only when
    it moves no node more than ``snap`` of the tolerance farther than ``c`` does: exact copies
    100 along and 1 across keep their 1, however much tolerance is left.
    ``ceiling`` gives :meth:`~lsys_core.hierarchy.gain.Ledger.ceiling` (a level's view has
    those of all its candidates: :class:`~lsys_core.hierarchy.reuse.LevelView`).
    """
    if (ledger.ceiling if ceiling is None else ceiling)(c) <= 0.0:
        return None  # whatever its numbers, it cannot pay (most candidates: rounding them costs more)
    c = snapped(c, nodes, limit, snap)
    if not _invertible(c):
        return None  # a transform that collapses its copies to a point places nothing
    plain = plainer(c)  # a transform without its small turn and scale, if it fits
    if plain is not None:
        cap = None
        if np.isfinite(limit) and snap <= SHARE:  # at the user's precision, not symmetrizing
            idx, err, _, _ = placement_error(c, nodes, sizes, period)
            owner = c.groups.owner()
            noise = np.zeros(len(c.groups))  # how far copies stray from the measured rule, or in shape
            np.maximum.at(noise, owner, np.maximum(err, limit - nodes.slack[idx]))
            cap = np.where(noise[owner] > SHARE * limit, np.inf, err + snap * limit)
        accepted = _admitted(plain, ledger, nodes, sizes, period, measure, n_terminals, limit, cap)
        if accepted is not None:
            return accepted
    return _admitted(c, ledger, nodes, sizes, period, measure, n_terminals, limit)


def _admitted(
    c: Candidate,
    ledger: Ledger,
    nodes: Nodes,
    sizes: np.ndarray,
    period: np.ndarray,
    measure: Measure | None,
    n_terminals: int,
    limit: float,
    cap: np.ndarray | None = None,
) -> Candidate | None:
    """``c`` with its slack, starts and gain set, if it places its nodes within their slack and pays.

    With ``cap``, every node must also lie within its entry of ``cap`` (node by node, in the
    order of ``c``'s groups) of where it is, and later rules may move it only within what the
    cap leaves.

    A sequence or pair whose best start differs from its first node's scale by rounding only
    (what :data:`~lsys_core.hierarchy.snap.SHARE` of the tolerance allows at its reach) starts
    at that node's scale when every node still fits.
    """

    def fit(own_scale: float):
        idx, err, starts, (pa, pb) = placement_error(c, nodes, sizes, period, own_scale=own_scale)
        left = nodes.slack[idx] - err
        over = np.flatnonzero(left < 0.0)
        if over.size and measure is not None:
            single = np.array([nodes.members[i].size == 1 for i in idx[over]]) & (
                nodes.sym[idx[over]] < n_terminals
            )
            if single.all():
                elements = np.array([int(nodes.members[i][0]) for i in idx[over]])
                left[over] = limit - measure(elements, pa[over], pb[over])
        if cap is not None:  # what the cap leaves is also all later rules may spend
            left = np.minimum(left, cap - err)
        return left, starts, not (left < 0.0).any()

    gain = ledger.gain(c)  # it does not depend on the fit: most candidates fail here, before fitting
    if gain <= 0.0:
        return None
    left, starts, fits = fit(0.0)
    if starts is not None and fits and np.isfinite(limit):
        own = np.abs(nodes.a[c.groups.firsts])
        off = np.abs(np.abs(starts[0]) - own) / np.maximum(own, 1e-300)
        snap = SHARE * limit / max(float(group_reach(nodes, c.groups).max()), 1e-12)
        if ((off > 0.0) & (off <= snap)).any():
            plain, plain_starts, plain_fits = fit(snap)
            if plain_fits:
                left, starts = plain, plain_starts
    if not fits:
        return None
    owner = c.groups.owner()
    slack = np.full(len(c.groups), np.inf)
    np.minimum.at(slack, owner, left)
    poses = () if starts is None else tuple(zip(starts[0].tolist(), starts[1].tolist(), strict=True))
    return replace(c, slack=tuple(float(v) for v in slack), starts=poses, gain=gain)


def importance_terms(cands: list[Candidate]) -> np.ndarray:
    """The terms the importance order reads, one row per candidate: ``covered, h, φ, l, start``.

    They do not depend on the weights: a level's rows are kept with its candidates
    (:mod:`lsys_core.hierarchy.reuse`) and every weight change only combines them.
    """
    rows = [(c.covered, c.h, c.phi, c.l, c.start[0], c.start[1]) for c in cands]
    return np.array(rows, np.float64).reshape(len(rows), 6)


def scores(cands: list[Candidate], w: Weights, terms: np.ndarray | None = None) -> np.ndarray:
    """The importance ``w = wn·n + wh·h + wφ·φ + wl·l`` of every candidate (§5.4, eq. 5).

    ``terms`` (:func:`importance_terms` of ``cands``) saves reading them again; the sums are
    taken in the same order as term by term, so the values are the same to the last bit.
    """
    t = importance_terms(cands) if terms is None else terms
    covered, h, phi, l = t[:, 0], t[:, 1], t[:, 2], t[:, 3]
    return w.wn * covered / covered.max() + w.wh * np.minimum(h, 1.0) + w.wphi * phi + w.wl * (l / l.max())


def importance_order(
    cands: list[Candidate], weights: Weights, terms: np.ndarray | None = None
) -> tuple[np.ndarray, list[int]]:
    """Rounded importance of every candidate, and the candidates most important first.

    Ties go to the candidate that covers more, then to the one that comes first in the drawing
    (then to the one found first).  ``terms`` as in :func:`scores`.
    """
    t = importance_terms(cands) if terms is None else terms
    score = np.round(scores(cands, weights, t), 9)
    if np.isfinite(score).all() and np.isfinite(t[:, 4:]).all():
        # a stable sort on the keys negated: what ``sorted(..., reverse=True)`` gives
        return score, np.lexsort((t[:, 5], t[:, 4], -t[:, 0], -score)).tolist()
    key = [(score[i], t[i, 0], -t[i, 4], -t[i, 5]) for i in range(len(cands))]
    return score, sorted(range(len(cands)), key=key.__getitem__, reverse=True)


def choose(
    cands: list[Candidate],
    weights: Weights,
    n_nodes: int,
    worthwhile: Callable[[Candidate], Candidate | None],
    ceiling: Callable[[Candidate], float] | None = None,
    *,
    order: tuple[np.ndarray, list[int]] | None = None,
    index: Callable[[], Rivals] | None = None,
) -> list[Candidate]:
    """The candidates to apply at this level, most important first (§5.4–§5.5).

    Candidates are taken in order of importance; among equally important ones the one that
    shortens the description most (then covers most, then comes first in the drawing: a
    sequence read forwards or backwards) is applied.
    When it covers only a small part of the scene (weak structure among clutter), every other
    worthwhile candidate on disjoint nodes is applied in the same level, so the number of
    levels stays small.  Only the candidates looked at are tested.

    With ``ceiling`` (a bound of a candidate's gain, :meth:`~lsys_core.hierarchy.gain.Ledger.ceiling`),
    a candidate yields to candidates on some of its nodes that shorten the description far more
    (:func:`_dominant`): importance orders repetitions of similar worth, but a branching of two
    pairs that saves 0.1 bit does not take the leaves of three rings that save 111, nor does a
    branching of a grid line, its neighbour and the tick below it (51 bits) cut the row of grid
    lines (133) and the row of ticks (167).

    ``order`` (:func:`importance_order` of ``cands`` and ``weights``) and ``index`` (giving
    the :class:`~lsys_core.hierarchy.rivals.Rivals` of ``cands``) save computing them again.
    """
    score, order_ = importance_order(cands, weights) if order is None else order
    rivals: Rivals | None = None
    taken = np.zeros(n_nodes, bool)
    out: list[Candidate] = []
    k = 0
    while k < len(order_):
        # candidates of equal importance (consecutive in ``order_``): the one that shortens the
        # description most goes first
        end = k + 1
        while end < len(order_) and score[order_[end]] == score[order_[k]]:
            end += 1
        tied = order_[k:end]
        k = end
        found = []
        for i in tied:
            if not taken[cands[i].nodes()].any() and (c := worthwhile(cands[i])) is not None:
                found.append(c)
        for c in sorted(found, key=lambda c: (c.gain, c.covered, -c.start[0], -c.start[1]), reverse=True):
            nodes = c.nodes()
            if taken[nodes].any():
                continue
            if ceiling is not None:
                if rivals is None:
                    rivals = Rivals(cands, n_nodes) if index is None else index()
                c = _dominant(c, cands, rivals, taken, worthwhile, ceiling)
                nodes = c.nodes()
            taken[nodes] = True
            out.append(c)
            if out[0].covered >= WEAK_COVER * n_nodes:
                return out
    return out


#: A candidate yields to candidates on some of its nodes that together save this many times its
#: bits, and :data:`DOMINANT_BITS` more, each saving more than it and than :data:`DOMINANT_BITS`
#: (see :func:`choose`).  Elsewhere the paper's importance decides as before.
DOMINANT = 4.0
DOMINANT_BITS = 32.0


def _dominant(
    c: Candidate,
    cands: list[Candidate],
    rivals_of: Rivals,
    taken: np.ndarray,
    worthwhile: Callable[[Candidate], Candidate | None],
    ceiling: Callable[[Candidate], float],
) -> Candidate:
    """``c``, or the best of the candidates on its nodes that together save far more (:data:`DOMINANT`).

    Every rival counted saves more than ``c`` and more than :data:`DOMINANT_BITS` on its own;
    rivals are taken on disjoint nodes, most promising (highest ceiling) first.
    """
    floor = max(c.gain, DOMINANT_BITS)
    need = max(DOMINANT * c.gain, c.gain + DOMINANT_BITS)
    bounds = [(ceiling(cands[i]), i) for i in rivals_of.on(c.nodes()).tolist()]
    found: list[Candidate] = []
    used = np.zeros(0, np.int64)
    for bound, i in sorted(bounds, reverse=True):
        if bound <= floor:
            break
        nodes = cands[i].nodes()
        if taken[nodes].any() or np.isin(nodes, used).any():
            continue
        better = worthwhile(cands[i])
        if better is None or better.gain <= floor:
            continue
        found.append(better)
        if sum(r.gain for r in found) > need:
            return max(found, key=lambda r: r.gain)
        used = np.concatenate([used, nodes])
    return c
