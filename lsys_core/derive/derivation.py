"""Derive a grammar into a :class:`~lsys_core.derive.model.Drawing`: rewriting and turtle interpretation.

The derivation is level-batched and vectorised: all pending calls of one non-terminal are
expanded at once, each as numpy arrays of counters ``m``, turtle frames ``(a, b)``
(complex, see :mod:`lsys_core.geometry.transforms`) and paint-order values ``z``.  A case
that ends with a call to its own symbol with ``m - c`` (a *sequence*, the paper's r1) is
unrolled in one step: the frames of all ``m`` repetitions are a segmented cumulative product,
so a 10⁶-element sequence costs a few numpy calls, not 10⁶ Python iterations.  Branching
rules (r3) take one batch per level.

Semantics: a parametric symbol with ``m < 0`` draws nothing; a case without a condition
applies for ``m >= 0``; a symbol with no matching case draws nothing (the paper's implicit
identity rule ``r0`` leaves it in the string, and a non-terminal has no interpretation).

Paint order: the instances are returned sorted by ``z`` (the turtle's paint-order value,
moved by ``z(Δ)`` and offset by the grammar's ``order:`` table), ties in the order the
terminals stand in the derived string (see :mod:`.order`).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import numpy as np

from lsys_core.cancel import CancelToken, check
from lsys_core.derive.compile import Compiled, Program, compile_grammar
from lsys_core.derive.jitter import jitter_instances
from lsys_core.derive.model import Calls, Drawing
from lsys_core.derive.order import Items, string_positions
from lsys_core.derive.paint import paint_z, resolve_styles
from lsys_core.derive.stretched import stretched
from lsys_core.derive.turtle import (
    Interpreter,
    case_masks,
    chain_frames,
    segmented_exclusive_cumsum,
    spread,
)
from lsys_core.errors import LimitError
from lsys_core.grammar.model import COND_EQ0, COND_GT0, Grammar, Randomize

__all__ = ["DEFAULT_LIMIT", "Randomize", "Trace", "derive", "derive_traced"]

DEFAULT_LIMIT = 1_000_000


@dataclass(frozen=True, eq=False)
class Trace:
    """Where each instance of a :class:`Drawing` came from (same order as the drawing).

    Attributes
    ----------
    position : ndarray of int64
        Position in the derived string (derivation order).
    slot : ndarray of int64
        Terminal occurrence that drew it: an index into ``slots``.
    m : ndarray of int64
        Counter of the rule application that drew it (0 in the axiom).
    z : ndarray of float
        Paint-order value (``z`` modules plus the ``order:`` table).
    slots : tuple of (str, int, int)
        ``(owner, case, module index)`` of every terminal occurrence.
    """

    position: np.ndarray
    slot: np.ndarray
    m: np.ndarray
    z: np.ndarray
    slots: tuple[tuple[str, int, int], ...]


class _Emitter:
    """Collect terminal instances in batches and enforce the element limit."""

    def __init__(self, limit: int) -> None:
        self.limit = limit
        self.count = 0
        self.parts: list[tuple[np.ndarray, ...]] = []

    def reserve(self, n: int, where: str) -> None:
        if self.count + n > self.limit:
            raise LimitError(
                f"derivation exceeds the element limit ({self.limit:,} elements) in {where}; "
                "lower its counter m or raise the limit"
            )

    def add(self, op: tuple, rule: int, a, b, z, m, parent, rank) -> None:
        n = a.size
        self.count += n
        _, term, paint, slot = op
        self.parts.append(
            (
                np.full(n, term, np.int32),
                a,
                b,
                spread(z, complex, (n,)),
                np.full(n, rule, np.int32),
                spread(m, np.int64, (n,)),
                np.full(n, slot, np.int64),
                np.full(n, paint, np.int32),
                spread(parent, np.int64, (n,)),
                spread(rank, np.int64, (n,)),
            )
        )

    def add_many(self, term, paint, slot, rule: int, a, b, z, m, parent, rank) -> None:
        """Like :meth:`add` for instances of several draw ops (per-instance term, paint, slot)."""
        n = a.size
        self.count += n
        self.parts.append(
            (
                term.astype(np.int32),
                a,
                b,
                z,
                np.full(n, rule, np.int32),
                m,
                slot,
                paint.astype(np.int32),
                parent,
                rank,
            )
        )


def derive(
    grammar: Grammar,
    *,
    limit: int = DEFAULT_LIMIT,
    randomize: Randomize | None = None,
    cancel: CancelToken | None = None,
) -> Drawing:
    """Derive ``grammar`` and interpret it with the turtle into a :class:`Drawing`.

    Parameters
    ----------
    grammar : Grammar
        The L-system; the turtle starts at the origin, heading +x, scale 1, ``z`` 0.
    limit : int
        Maximum number of terminal instances; exceeding it raises :class:`LimitError`
        naming the rule, before the arrays are allocated.
    randomize : Randomize, optional
        Seeded random perturbation (see :class:`~lsys_core.grammar.model.Randomize`); None
        uses the grammar's own (its ``randomize`` line), an inactive one draws without noise.
    cancel : CancelToken, optional
        Checked between batches.

    Returns
    -------
    Drawing
        Terminal instances with their poses and styles, in paint order: by ``z``, then in
        the order of the derived string.
    """
    return derive_traced(grammar, limit=limit, randomize=randomize, cancel=cancel)[0]


def derive_traced(
    grammar: Grammar,
    *,
    limit: int = DEFAULT_LIMIT,
    randomize: Randomize | None = None,
    cancel: CancelToken | None = None,
) -> tuple[Drawing, Trace]:
    """Like :func:`derive`, and also return the :class:`Trace` of every instance."""
    if randomize is None:
        randomize = grammar.randomize
    if randomize is not None and not randomize.active:
        randomize = None
    per_instance = randomize is not None and randomize.jitter == "instance"
    with np.errstate(all="ignore"):
        drawing, trace = _Derivation(grammar, limit, None if per_instance else randomize, cancel).run()
    if per_instance and randomize is not None:
        drawing = jitter_instances(drawing, randomize)
    return drawing, trace


class _Derivation:
    """One derivation: the queue of pending calls, the emitted instances and the item tree."""

    def __init__(self, grammar: Grammar, limit: int, randomize, cancel) -> None:
        self.grammar = grammar
        self.program: Program = compile_grammar(grammar)
        self.limit = limit
        self.cancel = cancel
        self.emitter = _Emitter(limit)
        self.interp = Interpreter(randomize)
        self.items = Items()
        self.call_info: list[tuple[int, np.ndarray, bool]] = []  # (rule, counters, continues) per chunk
        self.work_budget = 4 * max(limit, 1000)
        self.work = 0
        self.pending: dict[int, list] = {}
        self.queue: deque[int] = deque()

    def push(self, target: int, m, a, b, z, parent, rank, continues: bool = False) -> None:
        """Queue calls of rule ``target`` (dropping parametric ones with a negative counter)."""
        m = np.asarray(m, np.int64)
        if m.size == 0:
            return
        parent = spread(parent, np.int64, m.shape)
        rank = spread(rank, np.int64, m.shape)
        z = spread(z, complex, m.shape)
        if self.grammar.rules[target].parametric:
            keep = m >= 0
            if not keep.all():
                m, a, b, z, parent, rank = m[keep], a[keep], b[keep], z[keep], parent[keep], rank[keep]
                if m.size == 0:
                    return
        ids = self.items.add(parent, rank)
        self.call_info.append((target, m, continues))  # item ids are consecutive: entry i - 1 is item i's
        if target not in self.pending:
            self.pending[target] = []
            self.queue.append(target)
        self.pending[target].append((m, a, b, z, ids))

    def emit(self, draws, rule: int, where: str, m, parent, rank, base=None) -> None:
        """Record drawn instances; ``base`` ``(a, b, z)`` maps step-relative states to absolute."""
        for _, op, a, b, z in draws:
            if base is not None:
                a, b, z = base[0] * a, base[0] * b + base[1], base[2] + z
            self.emitter.reserve(a.size, where)
            if not (np.isfinite(a).all() and np.isfinite(b).all()):
                raise LimitError(
                    f"derivation overflows in {where}: its scales or distances grow beyond floating-point range"
                )
            self.emitter.add(op, rule, a, b, z, m, parent, rank)

    def emit_all(self, draws, rule: int, where: str, m, parent) -> None:
        """Record the draws of one body run at once (each ranked by its op index in the body).

        The same instances as :meth:`emit` draw by draw, in the same order, with one check and
        one batch: a body placing 3,000 elements one by one made 3,000 batches of a dozen
        numpy calls each.
        """
        if len(draws) <= 1:
            for i, op, a, b, z in draws:
                self.emit([(i, op, a, b, z)], rule, where, m, parent, i)
            return
        n = m.size
        a = np.concatenate([d[2] for d in draws])
        b = np.concatenate([d[3] for d in draws])
        z = np.concatenate([d[4] for d in draws])
        self.emitter.reserve(a.size, where)
        if not (np.isfinite(a).all() and np.isfinite(b).all()):
            raise LimitError(
                f"derivation overflows in {where}: its scales or distances grow beyond floating-point range"
            )
        ops = np.array([d[1][1:] for d in draws], np.int64).reshape(len(draws), 3)  # term, paint, slot
        self.emitter.add_many(
            np.repeat(ops[:, 0], n),
            np.repeat(ops[:, 1], n),
            np.repeat(ops[:, 2], n),
            rule,
            a,
            b,
            z,
            np.tile(spread(m, np.int64, (n,)), len(draws)),
            np.tile(spread(parent, np.int64, (n,)), len(draws)),
            np.repeat(np.array([d[0] for d in draws], np.int64), n),
        )

    def run(self) -> tuple[Drawing, Trace]:
        one = np.zeros(1, np.int64)
        root = np.zeros(1, np.int64)
        _, _, _, draws, calls = self.interp.run(self.program.axiom, one, perturb=False)
        self.emit_all(draws, -1, "the axiom", one, root)
        for i, target, m, a, b, z in calls:
            self.push(target, m, a, b, z, root, i)
        while self.queue:
            check(self.cancel)
            self.expand(self.queue.popleft())
        return self.collect()

    def expand(self, r: int) -> None:
        """Expand every pending call of rule ``r``."""
        batches = self.pending.pop(r)
        rule = self.grammar.rules[r]
        where = f"rule {rule.name}"
        m, a, b, z, ids = (np.concatenate([x[k] for x in batches]) for k in range(5))
        self.work += m.size
        if m.size > self.limit or self.work > self.work_budget:
            raise LimitError(f"derivation exceeds the element limit ({self.limit:,} elements) in {where}")
        masks = (
            case_masks(rule.cases, m)
            if rule.parametric
            else [np.ones(m.size, bool)] + [np.zeros(m.size, bool)] * (len(rule.cases) - 1)
        )
        for ci, case in enumerate(self.program.rules[r]):
            sel = masks[ci]
            if not sel.any():
                continue
            ms, as_, bs, zs, ids_ = m[sel], a[sel], b[sel], z[sel], ids[sel]
            if case.tail is None:
                _, _, _, draws, calls = self.interp.run(case.ops, ms, as_, bs, zs)
                self.emit_all(draws, r, where, ms, ids_)
                for i, target, mm, ca, cb, cz in calls:
                    self.push(target, mm, ca, cb, cz, ids_, i)
            else:
                self.unroll(r, ci, case, ms, as_, bs, zs, ids_, where)

    def unroll(self, r, ci, case: Compiled, m, a, b, z, ids, where) -> None:
        """Expand a self-sequence case for all items at once (see the module docstring)."""
        rule = self.grammar.rules[r]
        assert case.tail is not None
        c, tail_at = case.tail
        stride = tail_at + 1  # ranks: step k's op j is k * stride + j; the continuation comes last
        conds = [k.cond for k in rule.cases]
        first_pos = next((i for i, k in enumerate(conds) if k in (COND_GT0, None)), None)
        first_zero = next((i for i, k in enumerate(conds) if k in (COND_EQ0, None)), None)
        lengths = np.zeros(m.size, np.int64)
        if first_pos == ci:
            lengths = np.where(m > 0, -(-m // c), 0)
        if first_zero == ci:
            lengths = lengths + ((m - lengths * c) == 0)
        total = int(lengths.sum())
        if total > self.work_budget - self.work:
            raise LimitError(
                f"derivation exceeds the element limit in {where}: {total:,} repetitions requested; "
                "lower its counter m or raise the limit"
            )
        draws_per_step = sum(1 for op in case.ops if op[0] == "draw")
        self.emitter.reserve(total * draws_per_step, where)
        starts = np.concatenate(([0], np.cumsum(lengths)[:-1])).astype(np.int64)
        owner = np.repeat(np.arange(m.size), lengths)
        k = np.arange(total) - np.repeat(starts, lengths)
        m_step = m[owner] - k * c
        a_net, b_net, z_net, draws, calls = self.interp.run(case.ops[:tail_at], m_step)
        rel_a, rel_b = chain_frames(a_net, b_net, starts, lengths)
        step_a = a[owner] * rel_a
        step_b = a[owner] * rel_b + b[owner]
        step_z = z[owner] + segmented_exclusive_cumsum(z_net, starts, lengths)
        parent = ids[owner]
        for i, op, da, db, dz in draws:
            self.emit(
                [(i, op, da, db, dz)], r, where, m_step, parent, k * stride + i, (step_a, step_b, step_z)
            )
        for i, target, mm, ca, cb, cz in calls:
            self.push(target, mm, step_a * ca, step_a * cb + step_b, step_z + cz, parent, k * stride + i)
        # Continue after the last step of every chain (another case, e.g. m == 0, takes over).
        last = starts + lengths - 1
        has = lengths > 0
        end_a = np.where(has, a, 0j)
        end_b = np.where(has, b, 0j)
        end_z = np.where(has, z, 0j)
        if has.any():
            li = last[has]
            end_a[has] = step_a[li] * a_net[li]
            end_b[has] = step_a[li] * b_net[li] + step_b[li]
            end_z[has] = step_z[li] + z_net[li]
        m_end = m - lengths * c
        keep = has & (m_end >= 0)
        self.push(
            r, m_end[keep], end_a[keep], end_b[keep], end_z[keep], ids[keep], lengths[keep] * stride, True
        )

    def calls(self, call: np.ndarray) -> Calls:
        """Return the call tree (the derivation's items) and the call of every instance."""
        parent = np.full(self.items.count, -1, np.int64)
        for first, par, _ in self.items.chunks:
            parent[first : first + par.size] = par
        info = self.call_info
        rule_of = np.concatenate([[-1], *(np.full(ms.size, r) for r, ms, _ in info)]).astype(np.int64)
        m = np.concatenate([[0], *(ms for _, ms, _ in info)]).astype(np.int64)
        continues = np.concatenate([[False], *(np.full(ms.size, c) for _, ms, c in info)]).astype(bool)
        names = ("", *(r.name for r in self.grammar.rules))
        rules = tuple(names[r + 1] for r in rule_of.tolist())
        return Calls(np.asarray(call, np.int64), parent, rules, m, continues)

    def collect(self) -> tuple[Drawing, Trace]:
        """Sort the instances into paint order and build the drawing and its trace."""
        g = self.grammar
        parts = self.emitter.parts
        if parts:
            cols = [np.concatenate([p[k] for p in parts]) for k in range(10)]
        else:
            cols = [np.zeros(0, t) for t in (np.int32, complex, complex, complex, np.int32)]
            cols += [np.zeros(0, t) for t in (np.int64, np.int64, np.int32, np.int64, np.int64)]
        sym, a, b, z, rule, m, slot, paint, parent, rank = cols
        pos = string_positions(self.items, parent, rank)
        z = np.asarray(z, complex)
        stretch = z.imag.copy()
        z = z.real + paint_z(self.program.paints, paint, m)
        if g.order:
            table = np.asarray(g.order, float)
            listed = pos < table.size
            z[listed] += table[pos[listed]]
        order = np.lexsort((pos, z))
        sym, a, b, z, rule, m, slot, paint, pos, stretch = (
            x[order] for x in (sym, a, b, z, rule, m, slot, paint, pos, stretch)
        )
        styles, style = resolve_styles(g, self.program.paints, sym, paint, m, pos)
        calls = self.calls(parent[order])
        drawing = Drawing(
            g.terminals,
            sym,
            a.astype(complex),
            b.astype(complex),
            rule,
            g.viewbox,
            g.size,
            styles=styles,
            style=style,
            defs=g.defs,
            verbatim=g.verbatim,
            calls=calls,
        )
        drawing = stretched(drawing, stretch)
        return drawing, Trace(pos, slot, m, z, tuple(self.program.slots))
