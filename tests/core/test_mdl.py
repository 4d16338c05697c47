"""Minimum description length: rules only where they shorten the description (issue: chance vs structure).

Rings and arcs of any length are one sequence rule; random placements and random turns get no
rule; the description length of grammars behaves as a code length should.
"""

from __future__ import annotations

import numpy as np
import pytest

from lsys_core.grammar.model import Case, Grammar, Linear, Pop, Push, Rule, Symbol, Terminal, Turtle
from lsys_core.hierarchy.describe import grammar_bits
from lsys_core.hierarchy.mdl import Precision, count_bits, log2_binom, placement_set_bits
from lsys_core.pipeline import DEFAULT_DEVIATION, infer

from .scenes import LEAF, place, scene

RING_SIZES = (3, 4, 5, 7, 12)


def _ring_frames(n: int, *, arc: bool, radius: float = 60.0) -> list[tuple[complex, complex]]:
    step = 150.0 / (n - 1) if arc else 360.0 / n
    units = np.exp(1j * np.deg2rad(step * np.arange(n) + 17.0))
    return [(complex(u), complex(100 + 100j + radius * u)) for u in units]


def _sequence_logs(result) -> list[str]:
    return [line for line in result.log if not line.startswith("Z")]


@pytest.mark.parametrize("arc", [False, True], ids=["ring", "arc"])
@pytest.mark.parametrize("mirror", [False, True], ids=["plain", "mirror"])
@pytest.mark.parametrize("n", RING_SIZES)
def test_rings_and_arcs_of_any_length_are_one_sequence(n: int, arc: bool, mirror: bool) -> None:
    shape = np.conj(LEAF) if mirror else LEAF  # a ring of the mirror image turns the other way
    result = infer(scene(place(shape, _ring_frames(n, arc=arc))))
    assert result.grammar.production_count == 2, result.log
    assert result.log == (f"P1: 1 sequences of A, lengths [{n}]",)
    assert result.stages["reproduction_error"] < 0.1 * DEFAULT_DEVIATION  # rounding spends a tenth


@pytest.mark.parametrize("arc", [False, True], ids=["ring", "arc"])
@pytest.mark.parametrize("n", RING_SIZES)
def test_rings_of_a_shape_and_its_mirror_image_are_pairs_in_one_sequence(n: int, arc: bool) -> None:
    frames = _ring_frames(n, arc=arc)
    outer = [(a, 100 + 100j + (b - 100 - 100j) * 80 / 60) for a, b in frames]
    result = infer(scene(place(LEAF, frames), place(np.conj(LEAF), outer)))
    assert result.grammar.production_count == 3, result.log
    assert result.log[-1] == f"P1: 1 sequences of X1, lengths [{n}]"


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("where", ["scattered", "own centre", "common pivot"])
def test_random_turns_of_one_shape_claim_no_rotation_sequence(seed: int, where: str) -> None:
    rng = np.random.default_rng(seed)
    a = np.exp(1j * rng.uniform(0, 2 * np.pi, 20))
    if where == "scattered":
        b = rng.uniform(0, 200, 20) + 1j * rng.uniform(0, 200, 20)
    elif where == "own centre":
        b = 100 + 100j - a * LEAF.mean()  # turned about the leaf's centre
    else:
        b = 100 + 100j + 40 * a  # spokes at random angles about one point
    result = infer(scene(place(LEAF, list(zip(a, b, strict=True)))))
    assert _sequence_logs(result) == []
    assert result.grammar.production_count == 1


def test_random_placements_of_one_shape_get_no_rule() -> None:
    rng = np.random.default_rng(7)
    b = rng.uniform(0, 100, 600) + 1j * rng.uniform(0, 100, 600)
    result = infer(scene(place(np.array([[0, 10, 10 + 5j, 7 + 13j]]), [(1 + 0j, z) for z in b])))
    assert result.grammar.production_count <= 3
    assert _sequence_logs(result) == []


def test_a_regular_row_hidden_among_random_copies_is_still_found() -> None:
    rng = np.random.default_rng(3)
    noise = rng.uniform(0, 300, 60) + 1j * rng.uniform(150, 300, 60)
    row = 20 + 40j + 25.0 * np.arange(10)
    result = infer(scene(place(LEAF, [(1 + 0j, z) for z in np.concatenate([row, noise])])))
    assert any("lengths [10]" in line for line in result.log), result.log


# -- the code itself ---------------------------------------------------------------------------------


def test_set_code_is_the_log_of_the_number_of_sets() -> None:
    prec = Precision(1.0, 100.0, 64.0)  # 64 cells
    assert placement_set_bits(prec, 1) == pytest.approx(6.0)
    assert placement_set_bits(prec, 2) == pytest.approx(np.log2(64 * 63 / 2))
    assert float(log2_binom(10, 3)) == pytest.approx(np.log2(120))
    # two placements in one cell: the cell, and nothing to tell them apart (same heading)
    assert placement_set_bits(prec, 2, occupied=1) == pytest.approx(6.0)
    assert count_bits(0) == 1 and count_bits(2) == 3 and count_bits(3) == 5


def _row_grammars(n: int) -> tuple[Grammar, Grammar]:
    leaf = Terminal("A", "M0 0 L10 0 L5 4 Z")
    flat = Rule(
        "Z",
        False,
        (
            Case(
                None,
                tuple(
                    m
                    for k in range(n)
                    for m in (Push(), *((Turtle("f", Linear(23.0 * k)),) if k else ()), Symbol("A"), Pop())
                ),
            ),
        ),
    )
    from lsys_core.grammar.model import COND_EQ0, COND_GT0, Count

    seq = Rule(
        "P",
        True,
        (
            Case(COND_GT0, (Symbol("A"), Turtle("f", Linear(23.0)), Symbol("P", Count(-1, 1)))),
            Case(COND_EQ0, (Symbol("A"),)),
        ),
    )
    return (
        Grammar((leaf,), (flat,), (Symbol("Z"),)),
        Grammar((leaf,), (seq,), (Symbol("P", Count(n - 1)),)),
    )


def test_a_sequence_rule_is_shorter_than_placing_a_long_row_one_by_one() -> None:
    prec = Precision(0.5, 23.0 * 20, 23.0 * 20 * 10)
    flat, seq = _row_grammars(20)
    assert grammar_bits(seq, prec) < grammar_bits(flat, prec) - 50
    # the shapes cost the same in both
    assert grammar_bits(flat, prec) - grammar_bits(flat, prec, shapes=False) == pytest.approx(
        grammar_bits(seq, prec) - grammar_bits(seq, prec, shapes=False)
    )
