"""Description length of written grammars, in bits (the code of :mod:`lsys_core.hierarchy.mdl`).

A rule of one of the paper's kinds (a pair ``X -> A T B``, a sequence r1/r2, a branching
r3/r4) is recognised in its productions and coded by its kind, the symbols it repeats and its
transforms' numbers; any other rule token by token.  A body that only places symbols (the
catch-all rule ``Z -> [T A] [T B] …``) is coded as sets of placements when that is shorter.
The hierarchy's decisions (:mod:`lsys_core.hierarchy.gain`) use the same code, so a rule it
accepts makes :func:`grammar_bits` smaller.
"""

from __future__ import annotations

import numpy as np

from lsys_core.grammar.model import Case, Count, Grammar, Module, Pop, Push, Rule, Symbol, Turtle
from lsys_core.hierarchy.mdl import (
    KIND_BITS,
    OP_BITS,
    Precision,
    angle_value_bits,
    count_bits,
    log2_binom,
    placement_set_bits,
    pose_bits,
    shape_bits,
    table_bits,
    token_bits,
    transform_bits,
)

__all__ = ["compose", "flat_bits", "grammar_bits", "rule_bits", "run_bits", "structured_bits", "symbol_bits"]


def _turtle_bits(prec: Precision, t: Turtle) -> float:
    def number(v: float) -> float:
        if t.op in ("f", "~"):
            return prec.length_bits
        return prec.scale_bits() if t.op == "*" else angle_value_bits(prec, v)

    if t.value.table:
        return OP_BITS + table_bits(prec, t.value.table, t.op)
    return (
        OP_BITS
        + (number(t.value.c0) if t.value.c0 != 0 else 0.0)
        + (number(t.value.cd) if t.value.cd != 0 else 0.0)
    )


def run_bits(prec: Precision, turtles: list[Turtle]) -> float:
    """Bits of the turtle commands between two symbols: as one transform when constant."""
    frame = compose(turtles)
    if frame is None:
        return sum(_turtle_bits(prec, t) for t in turtles)
    extra = sum(_turtle_bits(prec, t) for t in turtles if t.op in ("z", "~"))
    return transform_bits(prec, *frame) + extra


def compose(turtles: list[Turtle]) -> tuple[complex, complex] | None:
    """The relative frame ``(A, B)`` of constant turtle commands (None if one depends on ``m``)."""
    a, b = 1 + 0j, 0j
    for t in turtles:
        if t.op in ("z", "~"):
            continue  # paint order and stretch do not move the turtle
        if t.value.cd != 0 or t.value.table:
            return None
        v = t.value.c0
        if t.op == "f":
            b += a * v
        elif t.op == "*":
            a *= v
        else:
            a *= complex(np.exp(1j * np.deg2rad(v if t.op == "+" else -v)))
    return a, b


def _symbol_bits(token: float, s: Symbol, name: str) -> float:
    if s.arg is None:
        return token
    if s.arg.k1 != 0:
        return (
            OP_BITS
            if s.name == name and s.arg == Count(-1, 1)
            else token + OP_BITS + float(count_bits(abs(s.arg.k0)))
        )
    return token + float(count_bits(max(s.arg.k0, 0)))


def _token_code(prec: Precision, token: float, rule: Rule) -> float:
    bits = 0.0  # rules are numbered: a rule's own name costs nothing
    for c in rule.cases:
        bits += OP_BITS if c.cond is not None else 0.0
        for m in c.body:
            if isinstance(m, Turtle):
                bits += _turtle_bits(prec, m)
            elif isinstance(m, Symbol):
                bits += _symbol_bits(token, m, rule.name)
            else:
                bits += OP_BITS
    return bits


def _drawn(body: tuple[Module, ...], i: int) -> tuple[Symbol, int] | None:
    """The symbol drawn at ``body[i]`` (``A`` or ``[ A ]``) and the index after it."""
    if i < len(body) and isinstance(body[i], Symbol):
        s = body[i]
        assert isinstance(s, Symbol)
        return s, i + 1
    if i + 2 < len(body) and isinstance(body[i], Push) and isinstance(body[i + 2], Pop):
        s = body[i + 1]
        return (s, i + 3) if isinstance(s, Symbol) else None
    return None


def _turtles(body: tuple[Module, ...], i: int) -> tuple[list[Turtle], int]:
    out = []
    while i < len(body) and isinstance(body[i], Turtle):
        t = body[i]
        assert isinstance(t, Turtle)
        out.append(t)
        i += 1
    return out, i


def _structure(rule: Rule) -> tuple[list[Symbol], list[list[Turtle]]] | None:
    """The symbols and the turtle runs of a rule of one of the paper's kinds, or None."""
    body = rule.cases[0].body
    head = _drawn(body, 0)
    if head is None:
        return None
    first, i = head
    if not rule.parametric and len(rule.cases) == 1:
        ts, i = _turtles(body, i)
        tail = _drawn(body, i)
        return ([first, tail[0]], [ts]) if tail is not None and tail[1] == len(body) else None
    if not rule.parametric or len(rule.cases) != 2:
        return None
    end = _drawn(rule.cases[1].body, 0)
    if end is None or end[0] != first or end[1] != len(rule.cases[1].body):
        return None
    me = Symbol(rule.name, Count(-1, 1))
    if i < len(body) and isinstance(body[i], Push):  # branching: [A] [T1 R(m-1)] T2 R(m-1)
        t1, j = _turtles(body, i + 1)
        if j + 1 >= len(body) or body[j] != me or not isinstance(body[j + 1], Pop):
            return None
        t2, k = _turtles(body, j + 2)
        return ([first], [t1, t2]) if k + 1 == len(body) and body[k] == me else None
    ts, j = _turtles(body, i)
    return ([first], [ts]) if j + 1 == len(body) and body[j] == me else None


def structured_bits(prec: Precision, token: float, refs: list[float], runs: list[float]) -> float:
    """Bits of a rule of one of the paper's kinds: kind, symbols repeated and transforms."""
    return KIND_BITS + sum(refs) + sum(runs)


def symbol_bits(token: float, s: Symbol) -> float:
    """Bits of a reference to symbol ``s`` with its counter."""
    return _symbol_bits(token, s, "")


def rule_bits(prec: Precision, token: float, rule: Rule) -> float:
    """Bits of one rule: by kind, symbols and numbers for the paper's kinds, else token by token."""
    bits = _token_code(prec, token, rule)
    found = _structure(rule)
    if found is not None:
        syms, runs = found
        refs = [_symbol_bits(token, s, rule.name) for s in syms]
        bits = min(bits, structured_bits(prec, token, refs, [run_bits(prec, r) for r in runs]))
    return bits


def _placements(body: tuple[Module, ...]) -> list[tuple[Symbol, complex, complex, list[Turtle]]] | None:
    """The body as placements ``[ turtle… Symbol ]`` with their relative frames, or None if it is not one.

    Each placement comes with its turtle commands that are not moves (stretches, paint order),
    which the set code charges one by one.
    """
    out = []
    i = 0
    while i < len(body):
        if not isinstance(body[i], Push):
            return None
        ts, i = _turtles(body, i + 1)
        frame = compose(ts)
        if (
            frame is None
            or i + 1 >= len(body)
            or not isinstance(body[i], Symbol)
            or not isinstance(body[i + 1], Pop)
        ):
            return None
        sym = body[i]
        assert isinstance(sym, Symbol)
        out.append((sym, frame[0], frame[1], [t for t in ts if t.op in ("z", "~")]))
        i += 2
    return out if len(out) >= 2 else None


def _set_code(
    prec: Precision,
    token: float,
    items: list[tuple[Symbol, complex, complex, list[Turtle]]],
    radius: dict[str, float],
) -> float:
    by_name: dict[str, list[tuple[Symbol, complex, complex, list[Turtle]]]] = {}
    for it in items:
        by_name.setdefault(it[0].name, []).append(it)
    bits = OP_BITS + sum(_turtle_bits(prec, t) for it in items for t in it[3])
    for name, group in by_name.items():
        a = np.array([g[1] for g in group])
        lever = radius.get(name, prec.diagonal) * np.abs(a)
        counts = sum(float(count_bits(max(g[0].arg.k0, 0))) for g in group if g[0].arg is not None)
        _, stacks = np.unique(prec.cell_ids(np.array([g[2] for g in group])), return_counts=True)
        pose = pose_bits(*prec.pose_model(a, lever), stacks)
        bits += placement_set_bits(
            prec, len(group), occupied=stacks.size, pose=pose, counts=counts, token=token
        )
    return bits


def flat_bits(prec: Precision, n_segments: np.ndarray, radius: np.ndarray) -> float:
    """Bits of a drawing as given: every element its own shape, placed one by one.

    The reference the inferred grammar is measured against: each element's shape
    (:func:`shape_bits`) and its place, as one placement set per shape.
    """
    n = int(np.size(n_segments))
    token = token_bits(n + 1)
    per = token + float(log2_binom(prec.cells, 1.0))
    return float(np.sum(shape_bits(prec, n_segments, radius))) + n * per + OP_BITS


def grammar_bits(g: Grammar, prec: Precision, *, shapes: bool = True) -> float:
    """Description length of a grammar, in bits, at precision ``prec`` (see the module docstring).

    A body that only places symbols (``[T A] [T B] …``) is charged the cheaper of the token
    code and the set code.  With ``shapes``, the terminals' path data counts too.
    """
    from lsys_core.geometry.shapes import shape_arrays

    token = token_bits(len(g.terminals) + len(g.rules))
    radius: dict[str, float] = {}
    bits = 0.0
    for t in g.terminals:
        cubics, _, _ = shape_arrays(t.path)  # parsed once for all stages (10^6 segments: 61 MiB)
        if cubics.size:
            radius[t.name] = float(np.max(np.abs(cubics - cubics.mean())))
            if shapes:
                bits += float(shape_bits(prec, cubics.shape[0], radius[t.name]))
    bits += _token_code(prec, token, Rule("", False, (Case(None, g.axiom),)))
    for r in g.rules:
        rule = rule_bits(prec, token, r)
        if len(r.cases) == 1:
            items = _placements(r.cases[0].body)
            if items is not None:
                rule = min(rule, _set_code(prec, token, items, radius))
        bits += rule
    return float(bits)
