"""Derivation: counts, geometry against a step-by-step turtle, limits, randomization."""

from __future__ import annotations

import numpy as np
import pytest

from lsys_core.derive.derivation import Randomize, derive
from lsys_core.errors import LimitError
from lsys_core.grammar import parse_grammar

HEADER = 'lsys 1\nterminal A "M0 0 L10 0"\n'
HELIX = HEADER + "axiom: P(336)\nP(m): m > 0 -> A f(27.5) *(0.993) +(8.5) P(m-1)\nP(m): m == 0 -> A\n"
FIG1 = HEADER + (
    "axiom: R(3)\n"
    "R(m): m > 0 -> A [ -(17) f(64) *(0.8) -(3) R(m-1) ] [ +(7) f(181) *(0.6) +(23) R(m-1) ]\n"
    "R(m): m == 0 -> A\n"
)


def turtle_reference(n: int, d: float, s: float, beta: float) -> tuple[np.ndarray, np.ndarray]:
    """Frames of the helix computed one step at a time."""
    a, b, out_a, out_b = 1 + 0j, 0j, [], []
    for _ in range(n):
        out_a.append(a)
        out_b.append(b)
        b += a * d
        a *= s * np.exp(1j * np.deg2rad(beta))
    return np.array(out_a), np.array(out_b)


def test_helix_count_and_geometry() -> None:
    d = derive(parse_grammar(HELIX))
    assert len(d) == 337
    ra, rb = turtle_reference(337, 27.5, 0.993, 8.5)
    assert np.allclose(d.b, rb, atol=1e-9)
    assert np.allclose(d.a, ra, atol=1e-12)


def test_fig1_branching_count() -> None:
    g = parse_grammar(FIG1)
    assert len(derive(g)) == 15
    deeper = parse_grammar(FIG1.replace("R(3)", "R(10)"))
    assert len(derive(deeper)) == 2**11 - 1


def test_branch_children_follow_turtle() -> None:
    d = derive(parse_grammar(FIG1.replace("R(3)", "R(1)")))
    # Root at the origin; children at -(17) f(64) and +(7) f(181) from it.
    b = sorted(d.b.tolist(), key=abs)
    assert b[0] == 0
    assert np.isclose(b[1], 64 * np.exp(-1j * np.deg2rad(17)))
    assert np.isclose(b[2], 181 * np.exp(1j * np.deg2rad(7)))


def test_linear_parameters() -> None:
    g = parse_grammar(HEADER + "axiom: P(3)\nP(m): m > 0 -> A +(10 + 5*m) f(2) P(m-1)\nP(m): m == 0 -> A\n")
    d = derive(g)
    # Turns 25, 20, 15 degrees for m = 3, 2, 1.
    expected = np.cumsum([0, 25, 20, 15])
    assert np.allclose(np.angle(d.a, deg=True), expected)


def test_element_limit_names_rule() -> None:
    g = parse_grammar(HELIX.replace("P(336)", "P(1000000000)"))
    with pytest.raises(LimitError, match="rule P"):
        derive(g)
    with pytest.raises(LimitError):
        derive(parse_grammar(FIG1.replace("R(3)", "R(40)")), limit=10_000)


def test_randomize_is_seeded() -> None:
    g = parse_grammar(HELIX)
    r = Randomize(angle=5, distance=0.1, scale=0.05, seed=7)
    a, b = derive(g, randomize=r), derive(g, randomize=r)
    assert np.array_equal(a.b, b.b)
    other = derive(g, randomize=Randomize(angle=5, distance=0.1, scale=0.05, seed=8))
    assert not np.allclose(a.b, other.b)
    assert not np.allclose(a.b, derive(g).b)


def test_negative_counter_draws_nothing_and_eps() -> None:
    g = parse_grammar(HEADER + "axiom: P(-1) A\nP(m) -> A P(m-1)\n")
    assert len(derive(g)) == 1


def test_chain_frames_of_one_step_equal_the_general_ones() -> None:
    """Chains of one repeated step (its powers) give the frames of steps that differ (logs)."""
    from lsys_core.derive.turtle import chain_frames

    lengths = np.array([4, 0, 7, 1])
    starts = np.concatenate(([0], np.cumsum(lengths)[:-1]))
    step_a = 0.97 * np.exp(1j * np.deg2rad(11.0))
    a = np.full(lengths.sum(), step_a)
    b = np.linspace(1.0, 3.0, a.size) + 0.5j
    fast_a, fast_b = chain_frames(a, b, starts, lengths)
    nudged = a.copy()
    nudged[-1] *= 1 + 1e-15  # one step differs (by nothing that shows): the general path
    slow_a, slow_b = chain_frames(nudged, b, starts, lengths)
    assert np.allclose(fast_a, slow_a, rtol=1e-12) and np.allclose(fast_b, slow_b, rtol=1e-12)
    k = np.arange(a.size) - np.repeat(starts, lengths)
    assert np.allclose(fast_a, step_a**k, rtol=1e-12)
    assert fast_b[starts[0]] == 0 and np.isclose(fast_b[1], b[0])
