"""Post-processing of generated rules (§5.7): fewer, simpler productions.

Identity commands (``+(0)``, ``f(0)``, ``*(1)``) are never emitted by the rule generator;
here non-parametric rules used exactly once inside another rule are inlined into it, and
rules no longer reachable from the axiom are dropped.  The axiom keeps its single symbol.
"""

from __future__ import annotations

from dataclasses import replace

from lsys_core.grammar.edit import drop_unreachable
from lsys_core.grammar.model import Case, Grammar, Module, Pop, Push, Rule, Symbol

__all__ = ["simplify"]


def _uses(g: Grammar) -> dict[str, int]:
    count: dict[str, int] = {}
    for r in g.rules:
        for c in r.cases:
            for mod in c.body:
                if isinstance(mod, Symbol):
                    count[mod.name] = count.get(mod.name, 0) + 1
    for mod in g.axiom:
        if isinstance(mod, Symbol):
            count[mod.name] = count.get(mod.name, 0) + 1
    return count


def _inline(body: tuple[Module, ...], name: str, sub: tuple[Module, ...]) -> tuple[Module, ...]:
    out: list[Module] = []
    for i, mod in enumerate(body):
        if isinstance(mod, Symbol) and mod.name == name:
            bracketed = (
                i > 0 and isinstance(body[i - 1], Push) and i + 1 < len(body) and isinstance(body[i + 1], Pop)
            )
            last = i == len(body) - 1
            out.extend(sub if (bracketed or last) else (Push(), *sub, Pop()))
        else:
            out.append(mod)
    return tuple(out)


def _strip_trailing_brackets(body: tuple[Module, ...]) -> tuple[Module, ...]:
    """Remove the brackets of a trailing ``[ … ]`` group.

    In generated grammars every non-terminal is either bracketed or the last module of
    its body, so the turtle state at the end of a body is never used again.
    """
    out = list(body)
    while len(out) >= 2 and isinstance(out[-1], Pop):
        depth = 0
        for i in range(len(out) - 1, -1, -1):
            depth += 1 if isinstance(out[i], Pop) else -1 if isinstance(out[i], Push) else 0
            if depth == 0:
                break
        del out[-1]
        del out[i]
    return tuple(out)


def simplify(g: Grammar) -> Grammar:
    """Inline single-use non-parametric rules and drop unreachable ones.

    Parameters
    ----------
    g : Grammar
        A generated grammar.

    Returns
    -------
    Grammar
        An equivalent grammar (it derives the same drawing) with fewer productions.
    """
    rules = list(g.rules)
    changed = True
    while changed:
        changed = False
        uses = _uses(replace(g, rules=tuple(rules)))
        axiom_names = {m.name for m in g.axiom if isinstance(m, Symbol)}
        for r in rules:
            if r.parametric or len(r.cases) != 1 or uses.get(r.name, 0) != 1 or r.name in axiom_names:
                continue
            sub = r.cases[0].body
            new_rules = []
            for q in rules:
                if q is r:
                    continue
                cases = tuple(
                    Case(c.cond, _strip_trailing_brackets(_inline(c.body, r.name, sub))) for c in q.cases
                )
                new_rules.append(Rule(q.name, q.parametric, cases))
            rules = new_rules
            changed = True
            break
    return drop_unreachable(replace(g, rules=tuple(rules)))
