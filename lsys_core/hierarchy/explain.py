"""Which rules of a grammar explain repetition, and how much of a drawing they place.

A rule *repeats* when it takes a counter (a sequence or a branching), or is called at least
twice, or is reached from a rule that repeats.  An element is explained by repetition when
the production that places it belongs to such a rule; what the axiom or a rule called once
places (the catch-all rule that lists the leftovers) is placed one by one.
"""

from __future__ import annotations

import numpy as np

from lsys_core.grammar.model import Grammar, Symbol

__all__ = ["explained_share", "placed_by_repetition", "repeating_rules"]


def repeating_rules(g: Grammar) -> set[str]:
    """Names of the rules that repeat (see the module docstring)."""
    calls: dict[str, int] = {}
    bodies = [g.axiom] + [c.body for r in g.rules for c in r.cases]
    for body in bodies:
        for m in body:
            if isinstance(m, Symbol):
                calls[m.name] = calls.get(m.name, 0) + 1
    by_name = {r.name: r for r in g.rules}
    out = {r.name for r in g.rules if r.parametric or calls.get(r.name, 0) >= 2}
    todo = list(out)
    while todo:
        for c in by_name[todo.pop()].cases:
            for m in c.body:
                if isinstance(m, Symbol) and m.name in by_name and m.name not in out:
                    out.add(m.name)
                    todo.append(m.name)
    return out


def placed_by_repetition(g: Grammar, emitted_by: np.ndarray) -> np.ndarray:
    """For every derived instance, whether a repeating rule placed it.

    Parameters
    ----------
    g : Grammar
        The grammar.
    emitted_by : ndarray of int
        For every derived instance, the index of the rule whose production placed it (-1: the
        axiom), as :attr:`lsys_core.derive.model.Drawing.rule` gives it.
    """
    names = repeating_rules(g)
    mask = np.array([r.name in names for r in g.rules] + [False], bool)  # index -1: the axiom
    return mask[np.asarray(emitted_by, np.int64)]


def explained_share(g: Grammar, emitted_by: np.ndarray) -> float:
    """Share of the derived instances placed by a repeating rule (:func:`placed_by_repetition`)."""
    if emitted_by.size == 0:
        return 0.0
    return float(np.mean(placed_by_repetition(g, emitted_by)))
