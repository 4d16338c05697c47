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

from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field

from lsys_core.grammar.model import COND_EQ0, Grammar, Module, Pop, Push, Rule, Symbol, Turtle
from lsys_core.grammar.runs import Control, Op, Write, merge, runs, sequence_words, signature, step_controls

__all__ = ["Card", "Control", "Write", "describe", "describe_iter", "rule_closures", "rules_under"]


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


def _card(g: Grammar, rule: Rule, sites: list[tuple[str, int]]) -> Card:
    terms = {t.name for t in g.terminals}
    drawn = {m.name for c in rule.cases for m in c.body if isinstance(m, Symbol)}
    terminals = tuple(sorted(drawn & terms))
    calls = tuple(sorted(drawn - terms - {rule.name}))
    self_calls, _ = _self_calls(rule)
    controls: list[Control] = []
    step_run: list[Op] | None = None
    first = rule.cases[0].body if rule.cases else ()
    for end, run in runs(rule.name, 0, first):
        if end == len(first) - 1 and _is_self(first[-1], rule):
            step_run = run
    step_sig = signature(step_run) if step_run is not None else None
    for ci, case in enumerate(rule.cases):
        seen: dict[str, int] = {}
        for end, run in runs(rule.name, ci, case.body):
            is_step = signature(run) == step_sig
            controls += step_controls(run, "step " if is_step else _place_prefix(end, case.body, seen))
    controls += _stretch_controls(rule)
    controls = merge(controls)
    counts = sorted({k0 for _, k0 in sites})
    if rule.parametric and self_calls >= 2:
        count_controls = _count_controls(rule, sites, "levels", "levels")
        reps = count_controls[0].value if len(count_controls) == 1 else None
        summary = f"branching in {self_calls}" + (f", {int(reps)} levels" if reps is not None else "")
        kind = "branching"
    elif rule.parametric and self_calls == 1:
        count_controls = _count_controls(rule, sites, "count", "count")
        reps = count_controls[0].value if len(count_controls) == 1 else None
        kind, summary = sequence_words(step_run, reps, calls)
    else:
        count_controls = []
        reps = None
        shapes = sum(1 for c in rule.cases[:1] for m in c.body if isinstance(m, Symbol))
        kind, summary = "group", f"group of {shapes} shape{'s' if shapes != 1 else ''}"
    if len(counts) > 1 and kind != "group":
        summary += f" (counts {', '.join(str(c) for c in counts)})"
    tables = sum(1 for c in rule.cases[:1] for m in c.body if isinstance(m, Turtle) and m.value.table)
    if tables:
        summary += f", {'a table' if tables == 1 else f'{tables} tables'} of values"
    count = int(reps) if reps is not None else None
    return Card(rule.name, kind, summary, terminals, calls, tuple(count_controls + controls), count)


def _stretch_controls(rule: Rule) -> list[Control]:
    """Controls of the stretch commands ``~(t)`` of a rule: "stretch per step" in a sequence's step."""
    out: list[Control] = []
    for ci, case in enumerate(rule.cases):
        depth = 0
        for i, mod in enumerate(case.body):
            depth += 1 if isinstance(mod, Push) else -1 if isinstance(mod, Pop) else 0
            if not (isinstance(mod, Turtle) and mod.op == "~") or mod.value.table:
                continue
            step = rule.parametric and depth == 0 and any(_is_self(m, rule) for m in case.body[i:])
            label = "stretch per step" if step else "stretch"
            key = f"{rule.name}.{ci}.{i}"
            out.append(Control("stretch", label, float(mod.value.c0), "distance", "", (Write(f"{key}.v"),)))
            if mod.value.cd:
                out.append(
                    Control(
                        "stretch change",
                        f"{label} change with m",
                        float(mod.value.cd),
                        "distance_delta",
                        "",
                        (Write(f"{key}.dv"),),
                    )
                )
    return out


def _is_self(mod: Module, rule: Rule) -> bool:
    return isinstance(mod, Symbol) and mod.name == rule.name


def _place_prefix(end: int, body: tuple[Module, ...], seen: dict[str, int]) -> str:
    """Label prefix of a run that places something: what follows it, numbered if it recurs."""
    nxt = body[end] if end < len(body) else None
    name = f"to {nxt.name}" if isinstance(nxt, Symbol) else "move"
    seen[name] = seen.get(name, 0) + 1
    return f"{name} #{seen[name]}: " if seen[name] > 1 else f"{name}: "


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
    return tuple(describe_iter(g))


def describe_iter(g: Grammar) -> Iterator[Card]:
    """Yield the cards of :func:`describe` one by one (an editor can interleave other work)."""
    sites = _call_sites(g)
    terms = {t.name for t in g.terminals}
    drawn = [m.name for m in g.axiom if isinstance(m, Symbol)]
    axiom_controls: list[Control] = []
    seen: dict[str, int] = {}
    for end, run in runs("axiom", 0, g.axiom):
        axiom_controls += step_controls(run, _place_prefix(end, g.axiom, seen))
    yield Card(
        "axiom",
        "start",
        "start: " + (", ".join(dict.fromkeys(drawn)) or "nothing"),
        tuple(sorted(set(drawn) & terms)),
        tuple(sorted(set(drawn) - terms)),
        tuple(merge(axiom_controls)),
    )
    for r in g.rules:
        yield _card(g, r, sites.get(r.name, []))


def rules_under(g: Grammar, name: str) -> set[str]:
    """Return the rules whose instances belong to ``name``'s structure: itself and every rule it uses.

    ``name`` is a rule name or ``axiom`` (then every rule reachable from the start).
    """
    return set(rule_closures(g, (name,))[name])


def rule_closures(g: Grammar, names: Iterable[str] | None = None) -> dict[str, frozenset[str]]:
    """Return :func:`rules_under` for every name of ``names`` (default: ``axiom`` and every rule).

    The call graph is read once for all of them (asking :func:`rules_under` name by name
    re-reads it each time: quadratic in the number of rules).
    """
    uses = {r.name: {m.name for c in r.cases for m in c.body if isinstance(m, Symbol)} for r in g.rules}
    start = [m.name for m in g.axiom if isinstance(m, Symbol)]
    out: dict[str, frozenset[str]] = {}
    for name in ("axiom", *uses) if names is None else names:
        todo = list(start) if name == "axiom" else [name]
        seen: set[str] = set()
        while todo:
            n = todo.pop()
            if n in uses and n not in seen:
                seen.add(n)
                todo.extend(uses[n])
        out[name] = frozenset(seen)
    return out
