"""Clean numbers: the simplest value within tolerance."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from lsys_core.grammar import format_grammar, parse_grammar
from lsys_core.grammar.snap import decimals_for, snap, snap_params


@pytest.mark.parametrize(
    ("value", "tol", "kind", "expected"),
    [
        (0.44, 0.5, "angle", 0.0),
        (-0.44, 0.5, "angle", 0.0),
        (44.98, 0.5, "angle", 45.0),
        (-89.7, 0.5, "angle", -90.0),
        (51.4286, 0.01, "angle", 360 / 7),
        (11.02, 0.05, "angle", 11.0),
        (11.02, 0.001, "angle", 11.02),
        (1.0000001, 0.0005, "scale", 1.0),
        (0.99003, 0.0005, "scale", 0.99),
        (18.503999999999998, 0.01, "distance", 18.5),
        (571.751, 0.05, "distance", 571.8),
        (46.00002, 0.05, "distance", 46.0),
        (0.30000000000000004, 0.01, "distance_delta", 0.3),
        (11.6, 0.5, "count", 12.0),
    ],
)
def test_simplest_value_within_tolerance(value, tol, kind, expected):
    assert snap(value, tol, kind) == pytest.approx(expected, abs=1e-12)


def test_a_known_ring_count_comes_first_and_zero_tolerance_keeps_values():
    assert snap(27.7, 0.1, "angle", ring=13) == pytest.approx(360 / 13)
    assert snap(0.44, 0.0, "angle") == 0.44
    assert snap(math.nan, 1.0) != snap(math.nan, 1.0)  # nan stays nan


@given(
    st.floats(-1e4, 1e4, allow_nan=False),
    st.floats(1e-6, 10.0),
    st.sampled_from(["angle", "distance", "scale", "angle_delta"]),
)
def test_snapped_value_is_always_within_tolerance(value, tol, kind):
    limit = abs(value) * tol if kind == "scale" else tol
    assert abs(snap(value, tol, kind) - value) <= limit * (1 + 1e-9) + 1e-12


def test_snap_params_cleans_a_grammar_and_keeps_counts():
    g = parse_grammar(
        'lsys 1\nterminal A "M 0 0 L 1 0"\naxiom: +(0.44) f(571.751) +(-0.44) P(119)\n'
        "P(m): m > 0 -> A f(18.503999999999998) *(1.0000001) +(44.98) P(m-1)\nP(m): m == 0 -> A\n"
    )
    text = format_grammar(snap_params(g))
    assert "axiom: +(0) f(571.8) +(0) P(119)" in text
    assert "A f(18.5) *(1) +(45) P(m-1)" in text
    clean = snap_params(g)
    assert snap_params(clean) is clean  # nothing left to change


def test_decimals_for_a_precision():
    assert (
        decimals_for(18.504, 0.01) == 1
        and decimals_for(18.504, 0.001) == 3
        and decimals_for(46.0, 0.01) == 0
        and decimals_for(0.125, 1e-4) == 3
    )


def test_plainer_leaves_a_collapsing_transform_alone():
    """A cluster whose transform scales to nothing (seen in a real flag) has no plain step."""
    import numpy as np

    from lsys_core.hierarchy.candidates import PairCandidate, SeqCandidate
    from lsys_core.hierarchy.snap import plainer

    groups = (np.array([0, 1]), np.array([2, 3]))
    for kind in (SeqCandidate, PairCandidate):
        for a in (0j, complex("nan"), complex("inf")):
            assert plainer(kind(space=(0, 0), groups=groups, h=1.0, phi=1.0, l=0.5, A=a, B=1 + 0j)) is None
        step = plainer(
            kind(space=(0, 0), groups=groups, h=1.0, phi=1.0, l=0.5, A=complex(0.9999, 0.001), B=1 + 0j)
        )
        assert step is not None and step.A == 1.0


def test_plainer_puts_a_step_a_degree_off_on_its_axis():
    """Copies placed by hand in a row measure a step a degree off the row's axis: the plain step lies on it."""
    import numpy as np

    from lsys_core.hierarchy.candidates import SeqCandidate
    from lsys_core.hierarchy.snap import plainer

    groups = (np.array([0, 1, 2]),)
    for step, axis in ((4.699 + 0.082j, 4.699), (-0.05 - 9.0j, -9.0j)):
        c = SeqCandidate(space=(0, 0), groups=groups, h=1.0, phi=1.0, l=2.0, A=1 + 0j, B=step)
        plain = plainer(c)
        assert plain is not None and plain.A == 1.0
        assert abs(plain.B - abs(step) * axis / abs(axis)) < 1e-12
        assert (plain.B.real == 0.0) or (plain.B.imag == 0.0)  # one number fewer to write
    off = SeqCandidate(space=(0, 0), groups=groups, h=1.0, phi=1.0, l=2.0, A=1 + 0j, B=4.0 + 1.0j)
    assert plainer(off) is None  # 14° off: a slanted row, not a jittered one
