"""Derive a grammar into a :class:`~lsys_core.derive.model.Drawing`: rewriting and turtle interpretation.

The derivation is level-batched and vectorised: all pending calls of one non-terminal are
expanded at once, each as numpy arrays of counters ``m`` and turtle frames ``(a, b)``
(complex, see :mod:`lsys_core.geometry.transforms`).  A case that ends with a call to its own symbol
with ``m - c`` (a *sequence*, the paper's r1) is unrolled in one step: the frames of all
``m`` repetitions are a segmented cumulative product, so a 10⁶-element sequence costs a
few numpy calls, not 10⁶ Python iterations.  Branching rules (r3) take one batch per level.

Semantics: a parametric symbol with ``m < 0`` draws nothing; a case without a condition
applies for ``m >= 0``; a symbol with no matching case draws nothing (the paper's implicit
identity rule ``r0`` leaves it in the string, and a non-terminal has no interpretation).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, replace

import numpy as np

from lsys_core.cancel import CancelToken, check
from lsys_core.derive.model import Drawing
from lsys_core.errors import GrammarError, LimitError
from lsys_core.geometry.transforms import DEG
from lsys_core.grammar.model import COND_EQ0, COND_GT0, Case, Grammar, Pop, Push, Randomize, Symbol, Turtle

__all__ = ["DEFAULT_LIMIT", "Randomize", "derive"]

DEFAULT_LIMIT = 1_000_000


# Compiled body ops: ("t", op, c0, cd) turtle, ("[",) push, ("]",) pop,
# ("draw", terminal index), ("call", rule index, k0, k1).
_Op = tuple


@dataclass
class _Compiled:
    ops: list[_Op]
    tail: tuple[int, int] | None  # (step c, index where the tail call starts) for a self sequence


class _Emitter:
    """Collect terminal instances in batches and enforce the element limit."""

    def __init__(self, limit: int) -> None:
        self.limit = limit
        self.count = 0
        self.parts: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = []

    def reserve(self, n: int, where: str) -> None:
        if self.count + n > self.limit:
            raise LimitError(
                f"derivation exceeds the element limit ({self.limit:,} elements) in {where}; "
                "lower its counter m or raise the limit"
            )

    def add(self, term: int, a: np.ndarray, b: np.ndarray, rule: int) -> None:
        n = a.size
        self.count += n
        self.parts.append((np.full(n, term, np.int32), a, b, np.full(n, rule, np.int32)))


def _compile(grammar: Grammar) -> tuple[list[list[_Compiled]], dict[str, int], dict[str, int]]:
    terms = {t.name: i for i, t in enumerate(grammar.terminals)}
    rules = {r.name: i for i, r in enumerate(grammar.rules)}

    def body_ops(body, owner: str) -> list[_Op]:
        ops: list[_Op] = []
        for mod in body:
            if isinstance(mod, Turtle):
                ops.append(("t", mod.op, float(mod.value.c0), float(mod.value.cd)))
            elif isinstance(mod, Push):
                ops.append(("[",))
            elif isinstance(mod, Pop):
                ops.append(("]",))
            elif isinstance(mod, Symbol):
                if mod.name in terms:
                    ops.append(("draw", terms[mod.name]))
                elif mod.name in rules:
                    arg = mod.arg
                    ops.append(("call", rules[mod.name], arg.k0 if arg else 0, arg.k1 if arg else 0))
                else:
                    raise GrammarError(f"undefined symbol {mod.name} in {owner}")
        return ops

    compiled = []
    for ri, rule in enumerate(grammar.rules):
        cases = []
        for case in rule.cases:
            ops = body_ops(case.body, f"rule {rule.name}")
            tail = None
            if rule.parametric and ops and ops[-1][0] == "call" and ops[-1][1] == ri:
                _, _, k0, k1 = ops[-1]
                depth = sum(1 if o[0] == "[" else -1 if o[0] == "]" else 0 for o in ops)
                if k1 == 1 and k0 <= -1 and depth == 0:
                    tail = (-k0, len(ops) - 1)
            cases.append(_Compiled(ops, tail))
        compiled.append(cases)
    return compiled, terms, rules


def _case_masks(rule_cases: tuple[Case, ...], m: np.ndarray) -> list[np.ndarray]:
    """Return, per case, the mask of counters for which it is the first applicable case."""
    taken = m < 0
    masks = []
    for case in rule_cases:
        if case.cond == COND_GT0:
            ok = m > 0
        elif case.cond == COND_EQ0:
            ok = m == 0
        else:
            ok = m >= 0
        mask = ok & ~taken
        taken |= mask
        masks.append(mask)
    return masks


class _Interpreter:
    """Interpret compiled bodies for a batch of items, starting at identity frames."""

    def __init__(self, randomize: Randomize | None, emitter: _Emitter, pending, limit: int) -> None:
        self.rand = randomize if randomize is not None and randomize.active else None
        self.rng = np.random.default_rng(randomize.seed if randomize is not None else 0)
        self.emitter = emitter
        self.pending = pending
        self.limit = limit

    def run(self, ops, m, rule: int, where: str, a0=None, b0=None, perturb: bool = True):
        """Run ``ops`` for counters ``m``; frames start at ``(a0, b0)`` (identity if None).

        Returns the frames after the last op and the emitted terminal instances as a list of
        ``(terminal, a, b)``; calls are pushed to the pending queue with their frames.
        """
        n = m.size
        a = np.ones(n, complex) if a0 is None else a0
        b = np.zeros(n, complex) if b0 is None else b0
        stack = []
        draws: list[tuple[int, np.ndarray, np.ndarray]] = []
        calls = []
        rand = self.rand if perturb else None
        for op in ops:
            kind = op[0]
            if kind == "t":
                _, sym, c0, cd = op
                v = c0 + cd * m if cd else np.full(n, c0)
                if sym == "f":
                    if rand is not None and rand.distance:
                        v = v * (1.0 + self.rng.uniform(-rand.distance, rand.distance, n))
                    b = b + a * v
                elif sym == "*":
                    if rand is not None and rand.scale:
                        v = v * (1.0 + self.rng.uniform(-rand.scale, rand.scale, n))
                    a = a * v
                else:
                    ang = v if sym == "+" else -v
                    if rand is not None and rand.angle:
                        ang = ang + self.rng.uniform(-rand.angle, rand.angle, n)
                    a = a * np.exp(1j * DEG * ang)
            elif kind == "[":
                stack.append((a, b))
            elif kind == "]":
                a, b = stack.pop()
            elif kind == "draw":
                draws.append((op[1], a, b))
            else:
                _, target, k0, k1 = op
                calls.append((target, k0 + k1 * m, a, b))
        return a, b, draws, calls


def _segmented_exclusive_cumsum(x: np.ndarray, starts: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    """Exclusive cumulative sum of ``x`` restarted at every segment start."""
    cs = np.cumsum(x)
    excl = cs - x
    return excl - np.repeat(excl[starts], lengths)


def _chain_frames(A: np.ndarray, B: np.ndarray, starts, lengths) -> tuple[np.ndarray, np.ndarray]:
    """Frames of a chain of steps relative to the chain start: ``F_{k+1} = F_k ∘ (A_k, B_k)``."""
    with np.errstate(divide="ignore", invalid="ignore"):
        logs = np.log(A)
    if np.all(np.isfinite(logs)):
        rel_a = np.exp(_segmented_exclusive_cumsum(logs, starts, lengths))
    else:  # a zero scale somewhere: fall back to a loop over step index (vectorised over chains)
        rel_a = np.empty_like(A)
        k = np.arange(A.size) - np.repeat(starts, lengths)
        cur = np.ones(starts.size, complex)
        owner = np.repeat(np.arange(starts.size), lengths)
        for j in range(int(lengths.max(initial=0))):
            sel = k == j
            rel_a[sel] = cur[owner[sel]]
            cur[owner[sel]] = cur[owner[sel]] * A[sel]
    rel_b = _segmented_exclusive_cumsum(rel_a * B, starts, lengths)
    return rel_a, rel_b


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
        The L-system; the turtle starts at the origin, heading +x, scale 1.
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
        Terminal instances with their poses, in a deterministic order.
    """
    with np.errstate(all="ignore"):
        return _derive(grammar, limit, randomize, cancel)


def _derive(grammar: Grammar, limit: int, randomize: Randomize | None, cancel: CancelToken | None) -> Drawing:
    if randomize is None:
        randomize = grammar.randomize
    if randomize is not None and not randomize.active:
        randomize = None
    per_instance = randomize is not None and randomize.jitter == "instance"
    compiled, _, _ = _compile(grammar)
    emitter = _Emitter(limit)
    work_budget = 4 * max(limit, 1000)
    work = 0
    pending: dict[int, list] = {}
    order: deque[int] = deque()

    def push(target: int, m: np.ndarray, a: np.ndarray, b: np.ndarray) -> None:
        if m.size == 0:
            return
        if grammar.rules[target].parametric:
            keep = m >= 0
            if not keep.all():
                m, a, b = m[keep], a[keep], b[keep]
                if m.size == 0:
                    return
        if target not in pending:
            pending[target] = []
            order.append(target)
        pending[target].append((m, a, b))

    interp = _Interpreter(None if per_instance else randomize, emitter, pending, limit)

    def emit(draws, rule: int, where: str, a_base=None, b_base=None) -> None:
        for term, a, b in draws:
            if a_base is not None:
                a, b = a_base * a, a_base * b + b_base
            emitter.reserve(a.size, where)
            _check_finite(a, b, where)
            emitter.add(term, a, b, rule)

    # The axiom: one item, no counter, not perturbed.
    one = np.zeros(1, np.int64)
    axiom_ops = _compile_axiom(grammar)
    _, _, draws, calls = interp.run(axiom_ops, one, -1, "the axiom", perturb=False)
    emit(draws, -1, "the axiom")
    for target, m, a, b in calls:
        push(target, m.astype(np.int64), a, b)

    while order:
        check(cancel)
        r = order.popleft()
        batches = pending.pop(r)
        rule = grammar.rules[r]
        where = f"rule {rule.name}"
        m = np.concatenate([x[0] for x in batches]).astype(np.int64)
        a = np.concatenate([x[1] for x in batches])
        b = np.concatenate([x[2] for x in batches])
        work += m.size
        if m.size > limit or work > work_budget:
            raise LimitError(f"derivation exceeds the element limit ({limit:,} elements) in {where}")
        masks = (
            _case_masks(rule.cases, m)
            if rule.parametric
            else [np.ones(m.size, bool)] + [np.zeros(m.size, bool)] * (len(rule.cases) - 1)
        )
        for ci, case in enumerate(compiled[r]):
            sel = masks[ci]
            if not sel.any():
                continue
            ms, as_, bs = m[sel], a[sel], b[sel]
            if case.tail is None:
                _, _, draws, calls = interp.run(case.ops, ms, r, where, as_, bs)
                emit(draws, r, where)
                for target, mm, ca, cb in calls:
                    push(target, np.asarray(mm, np.int64), ca, cb)
                continue
            _unroll(interp, emit, push, rule, r, ci, case, ms, as_, bs, where, work_budget - work)
    drawing = _collect(grammar, emitter)
    if per_instance and randomize is not None:
        return _jitter_instances(drawing, randomize)
    return drawing


def _check_finite(a: np.ndarray, b: np.ndarray, where: str) -> None:
    """Raise :class:`LimitError` when poses left the floating-point range (or became NaN)."""
    if not (np.isfinite(a).all() and np.isfinite(b).all()):
        raise LimitError(
            f"derivation overflows in {where}: its scales or distances grow beyond floating-point range"
        )


def _compile_axiom(grammar: Grammar) -> list[_Op]:
    rule_idx = {r.name: i for i, r in enumerate(grammar.rules)}
    term_idx = {t.name: i for i, t in enumerate(grammar.terminals)}
    ops: list[_Op] = []
    for mod in grammar.axiom:
        if isinstance(mod, Turtle):
            ops.append(("t", mod.op, float(mod.value.c0), 0.0))
        elif isinstance(mod, Push):
            ops.append(("[",))
        elif isinstance(mod, Pop):
            ops.append(("]",))
        elif mod.name in term_idx:
            ops.append(("draw", term_idx[mod.name]))
        elif mod.name in rule_idx:
            ops.append(("call", rule_idx[mod.name], mod.arg.k0 if mod.arg else 0, 0))
        else:
            raise GrammarError(f"undefined symbol {mod.name} in the axiom")
    return ops


def _unroll(interp, emit, push, rule, r, ci, case, m, a, b, where, budget) -> None:
    """Expand a self-sequence case for all items at once (see the module docstring)."""
    c, tail_at = case.tail
    conds = [k.cond for k in rule.cases]
    first_pos = next((i for i, k in enumerate(conds) if k in (COND_GT0, None)), None)
    first_zero = next((i for i, k in enumerate(conds) if k in (COND_EQ0, None)), None)
    lengths = np.zeros(m.size, np.int64)
    if first_pos == ci:
        lengths = np.where(m > 0, -(-m // c), 0)
    if first_zero == ci:
        lengths = lengths + ((m - lengths * c) == 0)
    total = int(lengths.sum())
    if total > budget:
        raise LimitError(
            f"derivation exceeds the element limit in {where}: {total:,} repetitions requested; "
            "lower its counter m or raise the limit"
        )
    draws_per_step = sum(1 for op in case.ops if op[0] == "draw")
    interp.emitter.reserve(total * draws_per_step, where)
    starts = np.concatenate(([0], np.cumsum(lengths)[:-1])).astype(np.int64)
    owner = np.repeat(np.arange(m.size), lengths)
    k = np.arange(total) - np.repeat(starts, lengths)
    m_step = m[owner] - k * c
    a_net, b_net, draws, calls = interp.run(case.ops[:tail_at], m_step, r, where)
    rel_a, rel_b = _chain_frames(a_net, b_net, starts, lengths)
    step_a = a[owner] * rel_a
    step_b = a[owner] * rel_b + b[owner]
    emit(draws, r, where, step_a, step_b)
    for target, mm, ca, cb in calls:
        push(target, np.asarray(mm, np.int64), step_a * ca, step_a * cb + step_b)
    # Continue after the last step of every chain (another case, e.g. m == 0, takes over).
    last = starts + lengths - 1
    has = lengths > 0
    end_a = np.where(has, a, 0j)
    end_b = np.where(has, b, 0j)
    if has.any():
        li = last[has]
        end_a[has] = step_a[li] * a_net[li]
        end_b[has] = step_a[li] * b_net[li] + step_b[li]
    m_end = m - lengths * c
    keep = has & (m_end >= 0)
    push(r, m_end[keep], end_a[keep], end_b[keep])


def _collect(grammar: Grammar, emitter: _Emitter) -> Drawing:
    parts = emitter.parts
    if parts:
        sym = np.concatenate([p[0] for p in parts])
        a = np.concatenate([p[1] for p in parts]).astype(complex)
        b = np.concatenate([p[2] for p in parts]).astype(complex)
        rule = np.concatenate([p[3] for p in parts])
    else:
        sym = np.zeros(0, np.int32)
        a = np.zeros(0, complex)
        b = np.zeros(0, complex)
        rule = np.zeros(0, np.int32)
    return Drawing(grammar.terminals, sym, a, b, rule, grammar.viewbox, grammar.size)


def _jitter_instances(drawing: Drawing, rnd: Randomize) -> Drawing:
    """Perturb every instance drawn by a rule on its own (``jitter="instance"``, see ``Randomize``)."""
    sel = np.flatnonzero(drawing.rule >= 0)
    if sel.size == 0:
        return drawing
    rng = np.random.default_rng(rnd.seed)
    a, b = drawing.a.copy(), drawing.b.copy()
    n = sel.size
    turn = np.exp(1j * DEG * rng.uniform(-rnd.angle, rnd.angle, n)) if rnd.angle else 1.0
    grow = 1.0 + rng.uniform(-rnd.scale, rnd.scale, n) if rnd.scale else 1.0
    if rnd.distance:
        gap = _nearest_gap(b)[sel]
        heading = a[sel] / np.where(np.abs(a[sel]) > 0, np.abs(a[sel]), 1.0)
        offset = rng.uniform(-1.0, 1.0, n) + 1j * rng.uniform(-1.0, 1.0, n)
        b[sel] = b[sel] + rnd.distance * gap * heading * offset
    a[sel] = a[sel] * turn * grow
    return replace(drawing, a=a, b=b)


def _nearest_gap(points: np.ndarray) -> np.ndarray:
    """Return each point's distance to its nearest other point (0 when it is alone)."""
    if points.size < 2:
        return np.zeros(points.size)
    from scipy.spatial import cKDTree

    xy = np.column_stack([points.real, points.imag])
    dist, _ = cKDTree(xy).query(xy, k=2)
    gap = dist[:, 1]
    return np.where(np.isfinite(gap), gap, 0.0)
