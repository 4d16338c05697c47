"""What each rule of a grammar draws, in a designer's words, and the controls that edit it.

A rule's text is a list of turtle commands; a designer thinks "a ring of 8", "a row of 12, 46
apart", "turn 11° and shrink to 0.99 per step".  :func:`describe` reads every rule (and the
axiom) as a :class:`Card`: its kind in words, the terminals and rules it draws, and its
*semantic* parameters (:class:`Control`): count, step distance and direction, turn per step,
scale per step, and how they change along a sequence.

A control writes every place its value occurs: the direction of a step written
``+(α) f(d) +(-α)`` is one control that sets both turns (the turn per step stays), a count is
the argument of every call of the rule with that count, and a step repeated in the
``m == 0`` case moves with the ``m > 0`` one.  :meth:`Control.values` returns the parameter keys
(see :mod:`lsys_core.grammar.params`) and values to set for a new value.
"""

from __future__ import annotations

import cmath
import math
from collections.abc import Iterator
from dataclasses import dataclass, field

from lsys_core.grammar.model import COND_EQ0, Grammar, Module, Rule, Symbol, Turtle

__all__ = ["Card", "Control", "Write", "describe", "rules_under"]

_FLAT_SCALE = 1e-3  # |scale - 1| below this: no growth or shrinking
_STRAIGHT = 0.5  # degrees of turn per step below which a sequence is straight


@dataclass(frozen=True)
class Write:
    """One parameter a control sets: ``key ← coef · value + offset``."""

    key: str
    coef: float = 1.0
    offset: float = 0.0


@dataclass(frozen=True)
class Control:
    """A semantic parameter of a rule.

    Attributes
    ----------
    name : str
        ``count``, ``levels``, ``distance``, ``direction``, ``turn``, ``scale`` or one of them
        with `` change`` (the change per step of a value linear in m).
    label : str
        Words for a user interface ("turn per step").
    value : float
        Current value (a count is the number of repetitions drawn, not the counter).
    kind : str
        The parameter kind of :mod:`lsys_core.grammar.params` (slider ranges, snapping).
    unit : str
        ``"°"`` for angles, ``"×"`` for scales, else ``""``.
    writes : tuple of Write
        Every parameter the control sets.
    """

    name: str
    label: str
    value: float
    kind: str
    unit: str
    writes: tuple[Write, ...]

    def values(self, value: float) -> dict[str, float]:
        """Return ``{key: new value}`` of every parameter this control writes for ``value``."""
        out = {}
        for w in self.writes:
            v = w.coef * value + w.offset
            out[w.key] = float(round(v)) if self.kind == "count" else v
        return out


@dataclass(frozen=True)
class Card:
    """A rule (or the axiom) as a designer reads it.

    Attributes
    ----------
    owner : str
        Rule name, or ``axiom``.
    kind : str
        ``ring``, ``row``, ``arc``, ``spiral``, ``branching``, ``group`` or ``start``.
    summary : str
        The kind in words: "ring of 8", "row of 12, 46 apart", "branching in 2, 4 levels".
    terminals : tuple of str
        Terminals the rule draws itself.
    calls : tuple of str
        Other rules it uses.
    controls : tuple of Control
        Its semantic parameters.
    count : int or None
        Repetitions (levels of a branching) when all its calls agree.
    """

    owner: str
    kind: str
    summary: str
    terminals: tuple[str, ...]
    calls: tuple[str, ...]
    controls: tuple[Control, ...] = field(default=())
    count: int | None = None


# -- turtle runs ----------------------------------------------------------------------------------
@dataclass(frozen=True)
class _Op:
    key: str  # the v key of this module
    op: str
    c0: float
    cd: float


def _runs(owner: str, ci: int, body: tuple[Module, ...]) -> Iterator[tuple[int, list[_Op]]]:
    """Yield ``(index after the run, ops)`` for every run of consecutive turtle commands."""
    run: list[_Op] = []
    for i, mod in enumerate(body):
        if isinstance(mod, Turtle) and mod.op == "z":
            continue  # paint order moves no geometry: the run goes on
        if isinstance(mod, Turtle):
            run.append(_Op(f"{owner}.{ci}.{i}.v", mod.op, float(mod.value.c0), float(mod.value.cd)))
            continue
        if run:
            yield i, run
        run = []
    if run:
        yield len(body), run


def _angle(op: _Op) -> float:
    return op.c0 if op.op == "+" else -op.c0


def _sign(op: _Op) -> float:
    return 1.0 if op.op == "+" else -1.0


def _net(run: list[_Op]) -> complex | None:
    """Return the translation of a run (heading 0, scale 1 at its start), or None."""
    a, b = 1 + 0j, 0j
    for op in run:
        if op.op == "f":
            b += a * op.c0
        elif op.op == "*":
            a *= op.c0
        else:
            a *= cmath.exp(1j * math.radians(_angle(op)))
    return b


def _step_controls(run: list[_Op], prefix: str) -> list[Control]:
    """Controls of one run ``[turns] [f] [scales] [turns]`` (none for other shapes of run)."""
    moves = [i for i, op in enumerate(run) if op.op == "f"]
    if len(moves) > 1:
        return []
    at = moves[0] if moves else len(run)
    before = [op for op in run[:at] if op.op in "+-"]
    after = [op for op in run[at:] if op.op in "+-"]
    scales = [op for op in run if op.op == "*"]
    out: list[Control] = []
    flip = 0.0
    if moves:
        f = run[at]
        flip = 180.0 if f.c0 < 0 else 0.0
        out.append(
            Control(
                "distance",
                f"{prefix}distance",
                abs(f.c0),
                "distance",
                "",
                (Write(f.key, -1.0 if flip else 1.0),),
            )
        )
    sum_before = sum(_angle(op) for op in before)
    sum_after = sum(_angle(op) for op in after)
    turn = sum_before + sum_after
    if moves and before:
        r = before[-1]
        others = sum_before - _angle(r)
        writes = [Write(r.key, _sign(r), -_sign(r) * (others + flip))]
        if after:  # keep the turn: the last turn after the move takes up the difference
            q = after[-1]
            rest = sum_after - _angle(q)
            writes.append(Write(q.key, -_sign(q), _sign(q) * (turn + flip - rest)))
        direction = _wrap(sum_before + flip)
        out.append(Control("direction", f"{prefix}direction", direction, "angle", "°", tuple(writes)))
    turns = after if (moves and before) else before + after
    if turns:
        q = turns[-1]
        rest = turn - _angle(q)
        out.append(
            Control("turn", f"{prefix}turn", turn, "angle", "°", (Write(q.key, _sign(q), -_sign(q) * rest),))
        )
    if scales:
        s1 = scales[0]
        others = math.prod(op.c0 for op in scales[1:])
        if others != 0:
            total = s1.c0 * others
            out.append(
                Control("scale", f"{prefix}scale", total, "scale", "×", (Write(s1.key, 1.0 / others),))
            )
    for i, op in enumerate(run):  # values linear in m: how much they change with m
        if op.cd:
            name = {"f": "distance", "*": "scale"}.get(op.op) or ("direction" if i < at else "turn")
            kind = {"distance": "distance_delta", "scale": "scale_delta"}.get(name, "angle_delta")
            sign = -1.0 if op.op == "-" else 1.0
            dkey = op.key[: -len(".v")] + ".dv"
            label = f"{prefix}{name} change with m"
            n = sum(c.label.startswith(label) for c in out)
            out.append(
                Control(
                    f"{name} change",
                    label + (f" #{n + 1}" if n else ""),
                    sign * op.cd,
                    kind,
                    "",
                    (Write(dkey, sign),),
                )
            )
    return out


def _wrap(deg: float) -> float:
    """Return ``deg`` in (-180, 180]."""
    x = math.fmod(deg + 180.0, 360.0)
    return (x + 360.0 if x <= 0 else x) - 180.0


def _merge(controls: list[Control]) -> list[Control]:
    """Merge controls of the same name and value (a step repeated in another case) into one."""
    out: list[Control] = []
    for c in controls:
        for i, d in enumerate(out):
            if (
                d.name == c.name
                and d.label == c.label
                and math.isclose(d.value, c.value, rel_tol=1e-9, abs_tol=1e-12)
            ):
                out[i] = Control(d.name, d.label, d.value, d.kind, d.unit, d.writes + c.writes)
                break
        else:
            out.append(c)
    return out


# -- rules ------------------------------------------------------------------------------------------
def _bodies(g: Grammar) -> Iterator[tuple[str, int, tuple[Module, ...]]]:
    yield "axiom", 0, g.axiom
    for r in g.rules:
        for ci, case in enumerate(r.cases):
            yield r.name, ci, case.body


def _call_sites(g: Grammar) -> dict[str, list[tuple[str, int]]]:
    """Return, per rule name, the ``(m key, constant counter)`` of every constant call."""
    sites: dict[str, list[tuple[str, int]]] = {}
    for owner, ci, body in _bodies(g):
        for i, mod in enumerate(body):
            if isinstance(mod, Symbol) and mod.arg is not None and mod.arg.k1 == 0:
                sites.setdefault(mod.name, []).append((f"{owner}.{ci}.{i}.m", mod.arg.k0))
    return sites


def _self_calls(rule: Rule) -> tuple[int, int]:
    """Return ``(self calls in the first case, decrement c of its tail call)``."""
    body = rule.cases[0].body if rule.cases else ()
    args = [m.arg for m in body if isinstance(m, Symbol) and m.name == rule.name and m.arg is not None]
    step = -args[-1].k0 if args and args[-1].k1 == 1 and args[-1].k0 < 0 else 1
    return len(args), max(1, step)


def _draws_at_zero(rule: Rule) -> bool:
    return any(c.cond in (COND_EQ0, None) and any(isinstance(m, Symbol) for m in c.body) for c in rule.cases)


def _count_controls(rule: Rule, sites: list[tuple[str, int]], name: str, label: str) -> list[Control]:
    """One control per distinct constant counter the rule is called with (all such calls move together)."""
    _, step = _self_calls(rule)
    extra = 1 if _draws_at_zero(rule) else 0
    by_value: dict[int, list[str]] = {}
    for key, k0 in sites:
        by_value.setdefault(k0, []).append(key)
    out = []
    for k0, keys in by_value.items():
        reps = k0 // step + extra
        writes = tuple(Write(k, float(step), -float(step * extra)) for k in keys)
        suffix = f" ({len(keys)} calls)" if len(by_value) > 1 and len(keys) > 1 else ""
        out.append(Control(name, label + suffix, float(reps), "count", "", writes))
    return out


def _fmt(x: float) -> str:
    return f"{x:.3g}" if abs(x) < 100 else f"{x:.0f}"


def _card(g: Grammar, rule: Rule, sites: list[tuple[str, int]]) -> Card:
    terms = {t.name for t in g.terminals}
    drawn = {m.name for c in rule.cases for m in c.body if isinstance(m, Symbol)}
    terminals = tuple(sorted(drawn & terms))
    calls = tuple(sorted(drawn - terms - {rule.name}))
    self_calls, _ = _self_calls(rule)
    controls: list[Control] = []
    step_run: list[_Op] | None = None
    first = rule.cases[0].body if rule.cases else ()
    for end, run in _runs(rule.name, 0, first):
        if end == len(first) - 1 and _is_self(first[-1], rule):
            step_run = run
    step_sig = _signature(step_run) if step_run is not None else None
    for ci, case in enumerate(rule.cases):
        seen: dict[str, int] = {}
        for end, run in _runs(rule.name, ci, case.body):
            is_step = _signature(run) == step_sig
            controls += _step_controls(run, "step " if is_step else _place_prefix(end, case.body, seen))
    controls = _merge(controls)
    counts = sorted({k0 for _, k0 in sites})
    if rule.parametric and self_calls >= 2:
        count_controls = _count_controls(rule, sites, "levels", "levels")
        reps = count_controls[0].value if len(count_controls) == 1 else None
        summary = f"branching in {self_calls}" + (f", {int(reps)} levels" if reps is not None else "")
        kind = "branching"
    elif rule.parametric and self_calls == 1:
        count_controls = _count_controls(rule, sites, "count", "count")
        reps = count_controls[0].value if len(count_controls) == 1 else None
        kind, summary = _sequence_words(step_run, reps, calls)
    else:
        count_controls = []
        reps = None
        shapes = sum(1 for c in rule.cases[:1] for m in c.body if isinstance(m, Symbol))
        kind, summary = "group", f"group of {shapes} shape{'s' if shapes != 1 else ''}"
    if len(counts) > 1 and kind != "group":
        summary += f" (counts {', '.join(str(c) for c in counts)})"
    count = int(reps) if reps is not None else None
    return Card(rule.name, kind, summary, terminals, calls, tuple(count_controls + controls), count)


def _signature(run: list[_Op]) -> tuple[tuple[str, float, float], ...]:
    return tuple((op.op, op.c0, op.cd) for op in run)


def _is_self(mod: Module, rule: Rule) -> bool:
    return isinstance(mod, Symbol) and mod.name == rule.name


def _place_prefix(end: int, body: tuple[Module, ...], seen: dict[str, int]) -> str:
    """Label prefix of a run that places something: what follows it, numbered if it recurs."""
    nxt = body[end] if end < len(body) else None
    name = f"to {nxt.name}" if isinstance(nxt, Symbol) else "move"
    seen[name] = seen.get(name, 0) + 1
    return f"{name} #{seen[name]}: " if seen[name] > 1 else f"{name}: "


def _sequence_words(run: list[_Op] | None, reps: float | None, calls: tuple[str, ...]) -> tuple[str, str]:
    """Return the kind and summary of a sequence rule from its step."""
    n = f" of {int(reps)}" if reps is not None else ""
    what = f" × {', '.join(calls)}" if calls else ""
    if run is None:
        return "row", f"sequence{n}{what}"
    b = _net(run) or 0j
    rotations = [(i, op) for i, op in enumerate(run) if op.op in "+-"]
    move_at = next((i for i, op in enumerate(run) if op.op == "f"), len(run))
    growing = sum(_sign(op) * op.cd for _, op in rotations)
    if growing:
        return (
            "sequence",
            f"sequence{n}{what}, {_fmt(abs(b))} apart, turning {_fmt(-growing)}° more each step",
        )
    # The direction of the move may change with m while the heading turns: the moves turn by
    # the heading's turn minus that change (``+(630 - 90*m) f(40) +(-720 + 90*m)`` is straight).
    heading = sum(_angle(op) for _, op in rotations)
    turn = heading - sum(_sign(op) * op.cd for i, op in rotations if i < move_at)
    each = f", each turned {_fmt(_wrap(heading))}°" if abs(_wrap(heading - turn)) >= _STRAIGHT else ""
    scale = math.prod(op.c0 for op in run if op.op == "*")
    straight = abs(_wrap(turn)) < _STRAIGHT
    flat = abs(scale - 1.0) < _FLAT_SCALE
    if flat and straight:
        return "row", f"row{n}{what}, {_fmt(abs(b))} apart{each}"
    closes = reps is not None and reps > 2 and abs(_wrap(reps * turn)) < max(1.0, 0.5 * abs(turn))
    if flat and closes and abs(turn) > _STRAIGHT:
        radius = abs(b) / (2 * math.sin(math.radians(abs(turn)) / 2)) if abs(b) else 0.0
        return "ring", f"ring{n}{what}" + (f", radius {_fmt(radius)}" if radius else "") + each
    if flat:
        return "arc", f"arc{n}{what}, turning {_fmt(turn)}° per step{each}"
    words = f"×{scale:.4g} per step"
    if straight:
        return "row", f"row{n}{what}, {_fmt(abs(b))} apart, {words}"
    return "spiral", f"spiral{n}{what}, {_fmt(turn)}° and {words}"


def describe(g: Grammar) -> tuple[Card, ...]:
    """Return a :class:`Card` for the axiom and for every rule, in text order.

    Parameters
    ----------
    g : Grammar
        A valid grammar.

    Returns
    -------
    tuple of Card
        The axiom's card ("start") first, its controls placing what it draws.
    """
    sites = _call_sites(g)
    terms = {t.name for t in g.terminals}
    drawn = [m.name for m in g.axiom if isinstance(m, Symbol)]
    axiom_controls: list[Control] = []
    seen: dict[str, int] = {}
    for end, run in _runs("axiom", 0, g.axiom):
        axiom_controls += _step_controls(run, _place_prefix(end, g.axiom, seen))
    start = Card(
        "axiom",
        "start",
        "start: " + (", ".join(dict.fromkeys(drawn)) or "nothing"),
        tuple(sorted(set(drawn) & terms)),
        tuple(sorted(set(drawn) - terms)),
        tuple(_merge(axiom_controls)),
    )
    return (start, *(_card(g, r, sites.get(r.name, [])) for r in g.rules))


def rules_under(g: Grammar, name: str) -> set[str]:
    """Return the rules whose instances belong to ``name``'s structure: itself and every rule it uses.

    ``name`` is a rule name or ``axiom`` (then every rule reachable from the start).
    """
    uses = {r.name: {m.name for c in r.cases for m in c.body if isinstance(m, Symbol)} for r in g.rules}
    todo = [m.name for m in g.axiom if isinstance(m, Symbol)] if name == "axiom" else [name]
    seen: set[str] = set()
    while todo:
        n = todo.pop()
        if n in uses and n not in seen:
            seen.add(n)
            todo.extend(uses[n])
    return seen
