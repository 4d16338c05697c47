"""The ``randomize`` line of ``.lsys`` files and per-instance or cumulative jitter."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from lsys_core.derive.derivation import derive
from lsys_core.errors import GrammarSyntaxError
from lsys_core.grammar import Randomize, format_grammar, parse_grammar

ROW = 'terminal A "M 0 0 L 1 0"\naxiom: P(40)\nP(m): m > 0 -> A f(10) +(0) P(m-1)\nP(m): m == 0 -> A\n'


def test_randomize_line_round_trips_and_needs_version_2():
    g = parse_grammar("lsys 2\nrandomize seed 9 angle 2.5 jitter instance\n" + ROW)
    assert g.randomize == Randomize(angle=2.5, seed=9, jitter="instance")
    text = format_grammar(g)
    assert text.startswith("lsys 2\nrandomize angle 2.5 seed 9 jitter instance\n")
    assert parse_grammar(text) == g
    plain = parse_grammar("lsys 1\n" + ROW)
    assert plain.randomize is None and format_grammar(plain).startswith("lsys 1\n")  # old files stay v1
    # randomized, it needs version 2, where its terminal keeps version 1's strokes ('scaled')
    again = format_grammar(dataclasses.replace(plain, randomize=g.randomize))
    assert again == text.replace('terminal A "M 0 0 L 1 0"', 'terminal A "M 0 0 L 1 0" scaled')
    assert parse_grammar(again) == dataclasses.replace(plain, randomize=g.randomize)


@pytest.mark.parametrize(
    ("line", "column", "fragment"),
    [
        ("randomize angle 1", 1, "needs format version 2"),
        ("randomize angle -1", 17, "angle must be a number >= 0"),
        ("randomize seed 2.5", 16, "seed must be a whole number"),
        ("randomize jitter wobbly", 18, "'instance' or 'cumulative'"),
        ("randomize scale 1 scale 2", 19, "duplicate 'scale'"),
    ],
)
def test_bad_randomize_lines_name_line_and_column(line, column, fragment):
    version = 1 if "needs" in fragment else 2
    with pytest.raises(GrammarSyntaxError) as err:
        parse_grammar(f"lsys {version}\n{line}\n{ROW}")
    assert (err.value.line, err.value.column) == (2, column) and fragment in str(err.value)


def test_a_rule_called_randomize_still_reads():
    g = parse_grammar('lsys 1\nterminal A "M 0 0"\naxiom: randomize\nrandomize -> A\n')
    assert g.rules[0].name == "randomize" and g.randomize is None


def test_derive_uses_the_grammars_randomize_unless_told_otherwise():
    g = parse_grammar("lsys 2\nrandomize distance 0.2 seed 3 jitter cumulative\n" + ROW)
    plain = derive(g, randomize=Randomize())
    noisy = derive(g)
    assert not np.allclose(noisy.b, plain.b)
    np.testing.assert_allclose(derive(g).b, noisy.b)


def test_instance_jitter_stays_near_the_row_and_cumulative_drifts():
    g = parse_grammar("lsys 1\n" + ROW)
    plain = derive(g)
    inst = derive(g, randomize=Randomize(distance=0.1, angle=5, scale=0.1, seed=1, jitter="instance"))
    cumul = derive(g, randomize=Randomize(distance=0.1, angle=5, scale=0.1, seed=1, jitter="cumulative"))
    moved = np.abs(inst.b - plain.b)
    assert 0 < moved.max() <= 0.1 * 10 * np.sqrt(2) + 1e-9  # at most 10 % of the gap, along and across
    assert np.abs(cumul.b - plain.b)[-5:].mean() > 2 * moved.max()  # errors add up along the row
    ratio = np.abs(inst.a / plain.a)
    assert np.all((ratio >= 0.9 - 1e-12) & (ratio <= 1.1 + 1e-12))


def test_instance_jitter_leaves_the_axioms_instances_alone():
    g = parse_grammar("lsys 1\n" + ROW.replace("axiom: P(40)", "axiom: A f(5) P(40)"))
    plain = derive(g)
    inst = derive(g, randomize=Randomize(distance=0.3, angle=9, scale=0.2, seed=2, jitter="instance"))
    by_axiom = plain.rule < 0
    assert by_axiom.sum() == 1
    np.testing.assert_array_equal(inst.b[by_axiom], plain.b[by_axiom])
    np.testing.assert_array_equal(inst.a[by_axiom], plain.a[by_axiom])
    assert not np.allclose(inst.b[~by_axiom], plain.b[~by_axiom])
