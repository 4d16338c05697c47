"""Inference on small constructed scenes: recovered parameters and rule structure."""

from __future__ import annotations

import numpy as np
import pytest

from lsys_core.derive.derivation import derive
from lsys_core.grammar import Symbol, Turtle, format_grammar, parse_grammar
from lsys_core.pipeline import InferenceSettings, infer, symmetrize
from lsys_core.report import reproduction_error

from .scenes import HOOK, LEAF, place, pose, scene, turtle_sequence


def turtle_values(g, op):
    return [
        m.value.c0 for r in g.rules for c in r.cases for m in c.body if isinstance(m, Turtle) and m.op == op
    ]


def check_reproduces(result, sc) -> None:
    d = derive(result.grammar)
    assert len(d) == len(sc.elements)
    assert result.stages["reproduction_error"] < 1e-6 * 1000
    # And the text round-trips to the same drawing.
    again = derive(parse_grammar(format_grammar(result.grammar)))
    assert np.allclose(np.sort_complex(again.b), np.sort_complex(d.b), atol=1e-4)


def test_five_element_sequence_recovers_step() -> None:
    frames = turtle_sequence(5, pose(50, 50, 30), (0, 45, 1, 0))
    sc = scene(place(LEAF, frames))
    r = infer(sc)
    check_reproduces(r, sc)
    assert r.grammar.production_count == 2
    f = turtle_values(r.grammar, "f")
    assert any(abs(abs(v) - 45) < 1e-3 for v in f)
    axiom_counts = [m.arg.k0 for m in r.grammar.axiom if isinstance(m, Symbol) and m.arg]
    assert axiom_counts == [4]


def test_helix_recovers_scale_and_angle() -> None:
    frames = turtle_sequence(60, pose(300, 300, 90), (0, 24, 0.99, 11))
    sc = scene(place(LEAF, frames))
    r = infer(sc)
    check_reproduces(r, sc)
    assert r.grammar.production_count == 2
    scales = turtle_values(r.grammar, "*")
    assert any(abs(s - 0.99) < 0.99e-3 or abs(1 / s - 0.99) < 0.99e-3 for s in scales)
    # The relative rotation per step is 11° (α + β), within 0.1°.
    rule = r.grammar.rules[0]
    turns = [
        m.value.c0 * (1 if m.op == "+" else -1)
        for m in rule.cases[0].body
        if isinstance(m, Turtle) and m.op in "+-"
    ]
    assert abs(abs(((sum(turns) + 180) % 360) - 180) - 11) < 0.1


def test_ring_is_one_sequence() -> None:
    frames = [
        pose(200 + 60 * np.cos(t), 200 + 60 * np.sin(t), np.rad2deg(t) + 90)
        for t in np.linspace(0, 2 * np.pi, 12, endpoint=False)
    ]
    sc = scene(place(HOOK, frames))
    r = infer(sc)
    check_reproduces(r, sc)
    assert r.grammar.production_count == 2


def test_grid_is_two_nested_sequences() -> None:
    frames = [pose(20 + 30 * i, 20 + 26 * j) for j in range(3) for i in range(4)]
    sc = scene(place(LEAF, frames))
    r = infer(sc)
    check_reproduces(r, sc)
    assert r.grammar.production_count == 4
    assert sum(1 for rule in r.grammar.rules if rule.parametric) == 2


def test_fig1_branching_is_one_rule() -> None:
    from lsys_core.derive.derivation import derive as d2

    g = parse_grammar(
        'lsys 1\nterminal A "M0 0 C8 -3 30 -6 40 0 C30 4 14 5 0 0 Z"\naxiom: R(3)\n'
        "R(m): m > 0 -> A [ -(17) f(64) *(0.8) -(3) R(m-1) ] [ +(7) f(181) *(0.6) +(23) R(m-1) ]\n"
        "R(m): m == 0 -> A\n"
    )
    truth = d2(g)
    from lsys_core.geometry.paths import cubics_from_d

    shape = cubics_from_d(g.terminals[0].path)[0]
    sc = scene(place(shape, zip(truth.a, truth.b, strict=True)))
    r = infer(sc)
    check_reproduces(r, sc)
    assert r.grammar.production_count == 2
    assert r.grammar.rules[0].name.startswith("R")


def test_mirrored_shapes_get_two_terminals() -> None:
    mirrored = np.conj(LEAF)
    left = place(LEAF, [pose(30 + 60 * i, 50) for i in range(5)])
    right = place(mirrored, [pose(60 + 60 * i, 50) for i in range(5)])
    sc = scene(left, right)
    r = infer(sc)
    check_reproduces(r, sc)
    assert len(r.grammar.terminals) == 2
    assert any(t.mirror_of for t in r.grammar.terminals)
    assert r.grammar.production_count <= 4


def test_resegmented_copy_shares_terminal() -> None:
    # Split every cubic of the leaf in two (de Casteljau): same shape, other path data.
    def split(c):
        p0, p1, p2, p3 = c
        q0, q1, q2 = (p0 + p1) / 2, (p1 + p2) / 2, (p2 + p3) / 2
        r0, r1 = (q0 + q1) / 2, (q1 + q2) / 2
        s = (r0 + r1) / 2
        return [[p0, q0, r0, s], [s, r1, q2, p3]]

    fine = np.array([seg for c in LEAF for seg in split(c)])
    sc = scene(
        place(LEAF, [pose(20 + 40 * i, 20) for i in range(3)]),
        place(fine, [pose(140 + 40 * i, 20) for i in range(3)]),
    )
    r = infer(sc)
    assert len(r.grammar.terminals) == 1
    check_reproduces(r, sc)


def test_rotating_row_uses_linear_parameters() -> None:
    frames = [pose(20 + 40 * i, 20, 12 * i) for i in range(10)]
    sc = scene(place(LEAF, frames))
    r = infer(sc)
    check_reproduces(r, sc)
    assert r.grammar.production_count == 2
    deltas = [
        m.value.cd
        for rule in r.grammar.rules
        for c in rule.cases
        for m in c.body
        if isinstance(m, Turtle) and m.value.cd
    ]
    assert any(abs(abs(d) - 12) < 0.1 for d in deltas)


def test_weights_change_grouping_fig7() -> None:
    """Proximity preferred: neighbouring A-B pairs first; similarity preferred: like shapes first."""
    a = place(LEAF, [pose(20 + 60 * i, 20) for i in range(6)])
    b = place(HOOK, [pose(40 + 60 * i, 10) for i in range(6)])
    sc = scene(a, b)
    near = infer(sc, InferenceSettings(wn=0.0, wh=1.0, wphi=0.0, wl=0.0))
    alike = infer(sc, InferenceSettings(wn=0.0, wh=0.0, wphi=1.0, wl=1.0))
    first_near = near.log[0]
    first_alike = alike.log[0]
    assert "pairs" in first_near and "-" in first_near.split("pairs", 1)[1]
    assert "sequences of" in first_alike
    assert format_grammar(near.grammar) != format_grammar(alike.grammar)
    for res in (near, alike):
        assert len(derive(res.grammar)) == 12


def test_clutter_is_never_lost() -> None:
    rng = np.random.default_rng(3)
    frames = [pose(*rng.uniform(0, 500, 2), rng.uniform(0, 360), rng.uniform(0.4, 1.2)) for _ in range(20)]
    sc = scene(place(LEAF, frames))
    r = infer(sc)
    check_reproduces(r, sc)


def test_symmetrize_regularises_jitter() -> None:
    rng = np.random.default_rng(1)
    frames = [
        pose(20 + 25 * i + rng.normal(0, 0.6), 50 + rng.normal(0, 0.6), rng.normal(0, 1.5)) for i in range(30)
    ]
    sc = scene(place(LEAF, frames))
    r = symmetrize(sc)
    d = derive(r.grammar)
    assert len(d) == 30
    steps = np.diff(np.sort(d.b.real))
    assert steps.std() < 0.05 * steps.mean()
    assert r.grammar.production_count <= 3


def test_reproduction_error_detects_missing() -> None:
    sc = scene(place(LEAF, [pose(10 * i, 0) for i in range(4)]))
    r = infer(sc)
    d = derive(r.grammar)
    from dataclasses import replace

    fewer = replace(d, symbol=d.symbol[:-1], a=d.a[:-1], b=d.b[:-1], rule=d.rule[:-1])
    assert reproduction_error(r.instancing, np.ones(1), fewer) == float("inf")


@pytest.mark.parametrize("bad", [dict(wn=2.0), dict(similarity=0.0), dict(tolerance=-1.0)])
def test_bad_settings_are_rejected(bad) -> None:
    from lsys_core.errors import InferenceError

    with pytest.raises(InferenceError):
        infer(scene(place(LEAF, [pose(0, 0)])), InferenceSettings(**bad))
