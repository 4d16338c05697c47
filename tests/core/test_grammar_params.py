"""Tests of the named numeric parameters of a grammar (sliders, ``--set NAME=VALUE``)."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lsys_core.errors import GrammarError
from lsys_core.grammar import (
    Count,
    Linear,
    Param,
    Symbol,
    Turtle,
    format_grammar,
    list_params,
    parse_grammar,
    set_param,
    set_params,
    validate,
)
from lsys_core.grammar.params import KINDS

TEXT = """\
lsys 1
terminal A "M 0 0 L 10 0"
axiom: +(90) f(100) *(0.5) P(119)
P(m): m > 0 -> A f(24) *(0.99) +(11) P(m-1)
P(m): m == 0 -> A [ -(3) G(5) ]
G(m) -> A +(10 + 2*m) f(5 - 0.5*m) *(1 + 0*m) G(m-1)
X -> A f(10) Q(2)
Q(m): m > 0 -> Q(m-1) Q(m-1)
"""


@pytest.fixture
def g():
    return parse_grammar(TEXT)


def by_key(params: list[Param]) -> dict[str, Param]:
    """Index parameters by key."""
    return {p.key: p for p in params}


def test_lists_every_value_with_kind_and_label(g):
    params = by_key(list_params(g))
    assert params["P.0.1.v"] == Param("P.0.1.v", "P (m > 0): f #1", 24.0, "distance")
    assert params["P.0.2.v"].kind == "scale" and params["P.0.2.v"].value == 0.99
    assert params["P.0.3.v"].kind == "angle" and params["P.0.3.v"].label == "P (m > 0): + #1"
    assert params["P.1.2.v"] == Param("P.1.2.v", "P (m == 0): - #1", 3.0, "angle")
    assert params["axiom.0.0.v"].label == "axiom: + #1"
    assert {p.kind for p in params.values()} <= set(KINDS)


def test_deltas_are_listed_only_when_non_zero(g):
    params = by_key(list_params(g))
    assert params["G.0.1.dv"] == Param("G.0.1.dv", "G: + #1 Δ", 2.0, "angle_delta")
    assert params["G.0.2.dv"].value == -0.5 and params["G.0.2.dv"].kind == "distance_delta"
    assert "G.0.3.dv" not in params and params["G.0.3.v"].value == 1.0
    assert "P.0.1.dv" not in params


def test_constant_counter_arguments_are_counts(g):
    params = by_key(list_params(g))
    assert params["axiom.0.3.m"] == Param("axiom.0.3.m", "axiom: P #1 count", 119.0, "count")
    assert params["P.1.3.m"].value == 5.0 and params["X.0.2.m"].value == 2.0
    assert not any(k.startswith("Q.") for k in params)  # Q(m-1) is not a constant
    assert list_params(g)[0].key == "axiom.0.0.v"  # axiom first, then rules in text order


def test_keys_follow_the_owner_case_index_field_scheme(g):
    for p in list_params(g):
        owner, case, index, field = p.key.split(".")
        body = g.axiom if owner == "axiom" else g.rule(owner).cases[int(case)].body
        mod = body[int(index)]
        if field == "m":
            assert mod.arg.k0 == p.value
        else:
            assert getattr(mod.value, "c0" if field == "v" else "cd") == p.value


def test_set_param_changes_one_value_and_leaves_the_input_alone(g):
    h = set_param(g, "P.0.1.v", 27.5)
    assert h.rule("P").cases[0].body[1] == Turtle("f", Linear(27.5))
    assert g.rule("P").cases[0].body[1] == Turtle("f", Linear(24.0))
    changed = {k for k, p in by_key(list_params(h)).items() if by_key(list_params(g))[k] != p}
    assert changed == {"P.0.1.v"}
    assert parse_grammar(format_grammar(h)) == h


def test_set_param_on_deltas_and_counts(g):
    h = set_params(g, {"G.0.1.dv": -1.5, "G.0.1.v": 0, "m": 200, "P.1.3.m": 7.0, "G.0.3.dv": 0.25})
    assert h.rule("G").cases[0].body[1].value == Linear(0, -1.5)
    assert h.rule("G").cases[0].body[3].value == Linear(1.0, 0.25)
    assert h.axiom[3] == Symbol("P", Count(200)) and isinstance(h.axiom[3].arg.k0, int)
    assert h.rule("P").cases[1].body[3].arg == Count(7)
    validate(h)


def test_alias_m_is_the_first_constant_counter_of_the_axiom(g):
    assert set_param(g, "m", 3) == set_param(g, "axiom.0.3.m", 3)
    no_counter = parse_grammar('lsys 1\nterminal A "M0 0"\naxiom: A\n')
    with pytest.raises(GrammarError, match="no counter"):
        set_param(no_counter, "m", 3)


@pytest.mark.parametrize(
    ("key", "value", "fragment"),
    [
        ("P.9.1.v", 1, "unknown parameter 'P.9.1.v'"),
        ("Z.0.0.v", 1, "unknown parameter"),
        ("P.0.0.v", 1, "unknown parameter"),  # module 0 is the terminal A
        ("P.0.1.m", 1, "unknown parameter"),
        ("X.0.1.dv", 1, "unknown parameter"),  # X has no counter: no Δ
        ("axiom.0.0.dv", 1, "unknown parameter"),
        ("Q.0.0.m", 1, "unknown parameter"),  # Q(m-1) is not a constant
        ("P.0.1", 1, "unknown parameter"),
        ("P.0.1.v", float("nan"), "finite"),
        ("P.0.1.v", math.inf, "finite"),
        ("P.0.1.v", "abc", "not a number"),
        ("P.0.2.v", 0, "scale must be positive"),
        ("P.0.2.v", -0.5, "scale must be positive"),
        ("G.0.3.dv", 0, None),  # 1 + 0*m is a positive constant: fine
        ("m", 2.5, "whole number"),
        ("m", -1, "whole number"),
    ],
)
def test_set_param_rejects_bad_keys_and_values(g, key, value, fragment):
    if fragment is None:
        validate(set_param(g, key, value))
        return
    with pytest.raises(GrammarError) as info:
        set_param(g, key, value)
    assert fragment in str(info.value)


def test_unknown_key_lists_some_valid_keys(g):
    with pytest.raises(GrammarError, match=r"valid keys: axiom\.0\.0\.v, axiom\.0\.1\.v, .*\.\.\."):
        set_param(g, "nope", 1)


@settings(max_examples=60, deadline=None)
@given(st.data())
def test_setting_any_listed_parameter_to_a_valid_value_round_trips(data):
    g = parse_grammar(TEXT)
    p = data.draw(st.sampled_from(list_params(g)))
    if p.kind == "count":
        value = float(data.draw(st.integers(0, 10_000)))
    elif p.kind == "scale":
        value = data.draw(st.floats(min_value=1e-6, max_value=1e6))
    else:
        value = data.draw(st.floats(-1e6, 1e6).filter(lambda x: x != 0 or not p.kind.endswith("delta")))
    assert set_param(g, p.key, p.value) == g
    h = set_param(g, p.key, value)
    validate(h)
    assert by_key(list_params(h))[p.key].value == value
    assert parse_grammar(format_grammar(h)) == h
