"""Grammar edits: replace a terminal's shape, a non-terminal by a terminal, grow/shrink."""

from __future__ import annotations

import numpy as np
import pytest

from lsys_core.derive.derivation import derive
from lsys_core.errors import GrammarError
from lsys_core.grammar import parse_grammar
from lsys_core.grammar.edit import replace_terminal, replace_with_terminal, set_axiom_count

GRID = """lsys 1
terminal A "M0 0 L10 0 L10 10 Z" style "fill:#000"
terminal B "M0 0 L4 0" style "stroke:#f00"
axiom: Q(2)
P(m): m > 0 -> A f(20) P(m-1)
P(m): m == 0 -> A
Q(m): m > 0 -> [ P(3) ] +(90) f(20) -(90) Q(m-1)
Q(m): m == 0 -> P(3)
"""


def test_replace_terminal_fits_the_old_size_and_keeps_style() -> None:
    g = parse_grammar(GRID)
    far_away_big = "M1000 1000 L1100 1000 L1100 1100 Z"
    g2 = replace_terminal(g, "A", far_away_big)
    assert g2.terminal("A").style == "fill:#000"
    d1, d2 = derive(g), derive(g2)
    assert len(d1) == len(d2) == 12
    assert np.allclose(d1.b, d2.b)  # poses unchanged
    with pytest.raises(GrammarError):
        replace_terminal(g, "Nope", far_away_big)
    with pytest.raises(GrammarError):
        replace_terminal(g, "A", "not path data")


def test_replace_nonterminal_by_terminal() -> None:
    g = replace_with_terminal(parse_grammar(GRID), "P", "B")
    assert g.rule("P") is None
    d = derive(g)
    assert len(d) == 3  # one B per row instead of a row of A
    assert set(d.symbol.tolist()) == {1}


def test_grow_and_shrink() -> None:
    g = parse_grammar(GRID)
    assert len(derive(set_axiom_count(g, 5))) == 6 * 4
    assert len(derive(set_axiom_count(g, 0))) == 4
    with pytest.raises(GrammarError):
        set_axiom_count(g, -1)
