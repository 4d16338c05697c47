"""Rules in a designer's words: kinds, and semantic controls that keep coupled values coupled."""

from __future__ import annotations

import cmath
import math
from pathlib import Path

import numpy as np
import pytest

from lsys_core.derive.derivation import derive
from lsys_core.grammar import parse_grammar, set_params
from lsys_core.grammar.semantics import describe

EXAMPLES = Path(__file__).resolve().parents[2] / "resources" / "examples"
HEAD = 'lsys 1\nterminal A "M 0 0 L 4 0 L 4 4 Z"\n'


def cards(text: str):
    return {c.owner: c for c in describe(parse_grammar(HEAD + text))}


def control(card, name: str):
    return next(c for c in card.controls if c.name == name or c.label == name)


@pytest.mark.parametrize(
    ("body", "summary"),
    [
        ("axiom: P(11)\nP(m): m > 0 -> A f(46) P(m-1)\nP(m): m == 0 -> A\n", "row of 12, 46 apart"),
        ("axiom: P(7)\nP(m): m > 0 -> A +(22.5) f(10) +(22.5) P(m-1)\nP(m): m == 0 -> A\n", "ring of 8"),
        ("axiom: P(3)\nP(m): m > 0 -> A f(10) *(0.9) +(30) P(m-1)\nP(m): m == 0 -> A\n", "spiral of 4"),
        (
            "axiom: P(3)\nP(m): m > 0 -> A [ +(30) P(m-1) ] [ -(30) P(m-1) ]\nP(m): m == 0 -> A\n",
            "branching in 2, 4 levels",
        ),
        ("axiom: X\nX -> A f(5) A\n", "group of 2 shapes"),
    ],
)
def test_kinds_in_words(body, summary):
    rule = next(c for c in describe(parse_grammar(HEAD + body)) if c.owner != "axiom")
    assert rule.summary.startswith(summary)


def test_direction_of_a_coupled_pair_moves_both_turns_and_keeps_the_turn():
    g = parse_grammar(
        HEAD
        + "axiom: +(45) f(100) +(-45) P(5)\nP(m): m > 0 -> A +(-80) f(-24) *(0.99) +(91) P(m-1)\nP(m): m == 0 -> A\n"
    )
    start = describe(g)[0]
    direction = control(start, "to P: direction")
    assert direction.value == pytest.approx(45)
    assert direction.values(30) == {"axiom.0.0.v": pytest.approx(30), "axiom.0.2.v": pytest.approx(-30)}
    step = describe(g)[1]
    turn, dirn, dist = (
        control(step, "step turn"),
        control(step, "step direction"),
        control(step, "step distance"),
    )
    assert turn.value == pytest.approx(11) and dist.value == pytest.approx(24)
    g2 = set_params(g, dirn.values(dirn.value + 20))
    after = describe(g2)[1]
    assert control(after, "step turn").value == pytest.approx(11)  # the turn per step stays
    assert control(after, "step direction").value == pytest.approx(dirn.value + 20)
    # the drawing: every step moved by the same rotation of its offset
    d1, d2 = derive(g), derive(g2)
    off1, off2 = np.diff(d1.b) / d1.a[:-1], np.diff(d2.b) / d2.a[:-1]
    np.testing.assert_allclose(off2, off1 * cmath.exp(1j * math.radians(20)), atol=1e-9)
    np.testing.assert_allclose(d2.a, d1.a)  # orientations and scales unchanged


def test_count_writes_every_call_with_that_count():
    c = cards(
        "axiom: Q(3)\nP(m): m > 0 -> A f(10) P(m-1)\nP(m): m == 0 -> A\n"
        "Q(m): m > 0 -> [ P(11) ] +(90) f(20) +(-90) Q(m-1)\nQ(m): m == 0 -> P(11)\n"
    )
    count = control(c["P"], "count")
    assert count.value == 12 and {w.key for w in count.writes} == {"Q.0.1.m", "Q.1.0.m"}
    assert count.values(20) == {"Q.0.1.m": 19.0, "Q.1.0.m": 19.0}
    assert c["Q"].summary.startswith("row of 4 × P, 20 apart")


def test_scale_and_linear_controls():
    c = cards("axiom: P(9)\nP(m): m > 0 -> A f(10) *(0.5) *(2) +(5 + 2*m) P(m-1)\nP(m): m == 0 -> A\n")
    scale = control(c["P"], "step scale")
    assert scale.value == pytest.approx(1.0) and scale.values(1.5) == {"P.0.2.v": pytest.approx(0.75)}
    change = control(c["P"], "step turn change with m")
    assert change.value == 2 and change.values(3) == {"P.0.4.dv": 3}
    assert c["P"].summary.startswith("sequence of 10")


@pytest.mark.parametrize(
    "name", ["helix", "facade", "flower-ring", "tiled-ornament", "branching-plant", "jittered-tiles"]
)
def test_every_control_of_the_examples_sets_its_own_value(name):
    g = parse_grammar((EXAMPLES / f"{name}.lsys").read_text(encoding="utf-8"))
    for card in describe(g):
        for ctl in card.controls:
            new = ctl.value + (1 if ctl.kind == "count" else 0.1 * (abs(ctl.value) or 1))
            again = {
                c.label: c
                for c in next(
                    k for k in describe(set_params(g, ctl.values(new))) if k.owner == card.owner
                ).controls
            }
            assert again[ctl.label].value == pytest.approx(new, rel=1e-9, abs=1e-9), (card.owner, ctl.label)


def test_rules_under_a_rule_are_itself_and_what_it_uses():
    from lsys_core.grammar.semantics import rule_closures, rules_under

    g = parse_grammar((EXAMPLES / "facade.lsys").read_text(encoding="utf-8"))
    assert rules_under(g, "P2") == {"P2", "P1", "X1"}
    assert rules_under(g, "axiom") == {r.name for r in g.rules}
    assert rules_under(g, "X1") == {"X1"}
    closures = rule_closures(g)
    assert set(closures) == {"axiom", *(r.name for r in g.rules)}
    assert all(closures[name] == rules_under(g, name) for name in closures)
