"""Editing operations on grammars (paper §6): replace symbols, grow or shrink a structure.

Every function returns a new :class:`~lsys_core.grammar.model.Grammar` and raises
:class:`~lsys_core.errors.GrammarError` with a one-line message for a bad request.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from lsys_core.errors import GrammarError
from lsys_core.grammar.model import Count, Grammar, Module, Rule, Symbol, Terminal
from lsys_core.grammar.validate import validate

__all__ = ["drop_unreachable", "replace_terminal", "replace_with_terminal", "set_axiom_count"]


def _shape_circle(path: str) -> tuple[complex, float]:
    """Centre and radius of the control polygon of SVG path data."""
    from lsys_core.geometry.shapes import shape_arrays

    cubics, _, _ = shape_arrays(path)
    if cubics.size == 0:
        raise GrammarError("the new shape has no drawable segments")
    pts = cubics.reshape(-1)
    centre = complex(pts.mean())
    return centre, float(np.abs(pts - centre).max())


def replace_terminal(
    grammar: Grammar, name: str, path: str, style: str | None = None, *, fit: bool = True
) -> Grammar:
    """Give terminal ``name`` another shape (and optionally style).

    Parameters
    ----------
    grammar : Grammar
    name : str
        The terminal to change.
    path : str
        SVG path data of the new shape.
    style : str, optional
        New CSS style; the old one is kept when None.
    fit : bool
        Centre the new shape where the old one was centred in the local frame and scale it
        to the old one's size, so a shape picked anywhere in a document drops into place.
    """
    from lsys_core.geometry.paths import cubics_from_d, d_from_cubics

    old = grammar.terminal(name)
    if old is None:
        raise GrammarError(f"no terminal named {name}")
    try:
        cubics, subpaths, closed = cubics_from_d(path)
    except Exception as e:  # SvgError and friends: one readable line
        raise GrammarError(f"the new shape of {name} is not valid path data: {e}") from None
    if cubics.size == 0:
        raise GrammarError(f"the new shape of {name} has no drawable segments")
    if fit:
        c_old, r_old = _shape_circle(old.path)
        c_new, r_new = _shape_circle(path)
        k = r_old / r_new if r_new > 0 else 1.0
        cubics = (cubics - c_new) * k + c_old
    new = Terminal(name, d_from_cubics(cubics, subpaths, closed), old.style if style is None else style)
    terminals = tuple(new if t.name == name else t for t in grammar.terminals)
    return replace(grammar, terminals=terminals)


def _swap(body: tuple[Module, ...], old: str, new: str) -> tuple[Module, ...]:
    return tuple(Symbol(new) if isinstance(m, Symbol) and m.name == old else m for m in body)


def replace_with_terminal(grammar: Grammar, nonterminal: str, terminal: str) -> Grammar:
    """Draw terminal ``terminal`` wherever non-terminal ``nonterminal`` was used (paper Fig. 11).

    The non-terminal's rule, and rules no longer reachable from the axiom, are removed.
    """
    if grammar.rule(nonterminal) is None:
        raise GrammarError(f"no rule for non-terminal {nonterminal}")
    if grammar.terminal(terminal) is None:
        raise GrammarError(f"no terminal named {terminal}")
    rules = tuple(
        replace(r, cases=tuple(replace(c, body=_swap(c.body, nonterminal, terminal)) for c in r.cases))
        for r in grammar.rules
        if r.name != nonterminal
    )
    g = replace(grammar, rules=rules, axiom=_swap(grammar.axiom, nonterminal, terminal))

    g = drop_unreachable(g)
    validate(g)
    return g


def set_axiom_count(grammar: Grammar, m: int) -> Grammar:
    """Set the counter of the axiom's (first) parametric symbol: grow or shrink the structure."""
    if not isinstance(m, (int, np.integer)) or isinstance(m, bool) or m < 0:
        raise GrammarError(f"the counter m must be a whole number >= 0, got {m!r}")
    axiom = list(grammar.axiom)
    for i, mod in enumerate(axiom):
        if isinstance(mod, Symbol) and mod.arg is not None:
            axiom[i] = Symbol(mod.name, Count(int(m)))
            return replace(grammar, axiom=tuple(axiom))
    raise GrammarError("the axiom has no symbol with a counter m")


def drop_unreachable(g: Grammar) -> Grammar:
    """Return ``g`` without the rules that the axiom can never reach."""
    reachable = _reachable(list(g.rules), g.axiom)
    return replace(g, rules=tuple(r for r in g.rules if r.name in reachable))


def _reachable(rules: list[Rule], axiom: tuple[Module, ...]) -> set[str]:
    by_name = {r.name: r for r in rules}
    todo = [m.name for m in axiom if isinstance(m, Symbol)]
    seen: set[str] = set()
    while todo:
        n = todo.pop()
        if n in seen:
            continue
        seen.add(n)
        for c in by_name[n].cases if n in by_name else ():
            todo.extend(m.name for m in c.body if isinstance(m, Symbol))
    return seen


def rename_symbols(g: Grammar, names: dict[str, str]) -> Grammar:
    """Return ``g`` with terminals and rules renamed by ``names`` (old -> new), uses included."""
    if not names:
        return g

    def body(mods: tuple[Module, ...]) -> tuple[Module, ...]:
        return tuple(
            replace(m, name=names[m.name]) if isinstance(m, Symbol) and m.name in names else m for m in mods
        )

    terminals = tuple(
        replace(
            t,
            name=names.get(t.name, t.name),
            mirror_of=None if t.mirror_of is None else names.get(t.mirror_of, t.mirror_of),
        )
        for t in g.terminals
    )
    rules = tuple(
        replace(
            r, name=names.get(r.name, r.name), cases=tuple(replace(c, body=body(c.body)) for c in r.cases)
        )
        for r in g.rules
    )
    return replace(g, terminals=terminals, rules=rules, axiom=body(g.axiom))
