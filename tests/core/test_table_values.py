"""Table values ``[v0, v1, ...]`` of the ``.lsys`` format (version 3): reading, writing, checking, deriving."""

from __future__ import annotations

import numpy as np
import pytest

from lsys_core.derive.derivation import derive
from lsys_core.errors import GrammarError
from lsys_core.grammar import format_grammar, list_params, parse_grammar, set_param
from lsys_core.grammar.model import Linear

RINGS = """lsys 3
terminal A "M 1 0 A 1 1 0 0 1 -1 0 A 1 1 0 0 1 1 0 Z" style "fill:#000"
axiom: f(18) P(3)
P(m): m > 0 -> [ *([1, 2, 3.5, 7]) A ] +(90) f(2) +(-90) P(m-1)
P(m): m == 0 -> [ *([1, 2, 3.5, 7]) A ]
"""


def test_a_table_value_is_read_written_and_derived_by_the_counter() -> None:
    g = parse_grammar(RINGS)
    assert format_grammar(g) == RINGS
    d = derive(g)
    # P(3) draws first with m = 3: entry 3, then 2, 1, 0
    np.testing.assert_allclose(np.abs(d.a), [7, 3.5, 2, 1])
    np.testing.assert_allclose(d.b, [18, 18 + 2j, 18 + 4j, 18 + 6j])


def test_a_table_cycles_when_the_counter_passes_its_end() -> None:
    text = RINGS.replace("*([1, 2, 3.5, 7])", "*([1, 2])").replace("P(3)", "P(4)")
    np.testing.assert_allclose(np.abs(derive(parse_grammar(text)).a), [1, 2, 1, 2, 1])


def test_grammars_without_tables_keep_their_version() -> None:
    text = RINGS.replace("lsys 3", "lsys 2").replace("*([1, 2, 3.5, 7])", "*(2)")
    assert format_grammar(parse_grammar(text)).startswith("lsys 2\n")


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (("lsys 3", "lsys 2"), "needs format version 3"),
        (("f(18) P(3)", "f([18]) P(3)"), "cannot be used in the axiom"),
        (("*([1, 2, 3.5, 7]) A ] +", "*([1, -2]) A ] +"), "scale must be positive"),
        (("[1, 2, 3.5, 7]) A ] +", "[1 2]) A ] +"), "expected ',' or ']'"),
        (("[1, 2, 3.5, 7]) A ] +", "[]) A ] +"), "expected a number"),
    ],
)
def test_bad_tables_are_one_line_errors(change: tuple[str, str], message: str) -> None:
    with pytest.raises(GrammarError, match=message):
        parse_grammar(RINGS.replace(*change, 1))


def test_every_table_entry_is_a_parameter() -> None:
    g = parse_grammar(RINGS)
    keys = {p.key: p.value for p in list_params(g) if p.key.startswith("P.0.1.")}
    assert keys == {"P.0.1.t0": 1, "P.0.1.t1": 2, "P.0.1.t2": 3.5, "P.0.1.t3": 7}
    g2 = set_param(g, "P.0.1.t2", 5)
    body = g2.rule("P").cases[0].body  # type: ignore[union-attr]
    assert body[1].value == Linear.of_table([1, 2, 5, 7])  # type: ignore[union-attr]
    with pytest.raises(GrammarError, match="positive"):
        set_param(g, "P.0.1.t0", 0)
    with pytest.raises(GrammarError, match="unknown parameter"):
        set_param(g, "P.0.1.t4", 1)


def test_the_rule_card_says_the_rule_holds_a_table() -> None:
    from lsys_core.grammar.semantics import describe

    card = next(c for c in describe(parse_grammar(RINGS)) if c.owner == "P")
    assert card.summary.endswith("a table of values")
