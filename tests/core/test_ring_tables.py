"""Rings and arcs whose copies each vary a little are one rule with table values.

Petals turned about a flower's centre by hand: every copy a few degrees off its place, a little
nearer or farther, turned and scaled a little.  No two steps are equal, so no exact sequence
codes them; one ring rule with a table of every copy's deviation does (and stays within the
tolerance).  Copies at random places and turns get no ring.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from lsys_core.derive.derivation import derive
from lsys_core.pipeline import infer
from lsys_core.testing import drawing_scene, hausdorff_rel

from .scenes import HOOK, LEAF, place, scene

RING_SIZES = (3, 4, 5, 7, 12)


def _copies(n: int, *, arc: bool, seed: int, slots: int | None = None) -> list[tuple[complex, complex]]:
    """``n`` copies on a ring (or a 150° arc) of radius 60, each off its place on the ring by up
    to 2° (a tenth of a step at most), by 2 % in distance, 3° in turn and 1.0–1.3 in scale."""
    rng = np.random.default_rng(seed)
    step = 150.0 / (n - 1) if arc else 360.0 / (slots or n)
    off = min(2.0, 0.1 * step)
    where = step * np.arange(n) + 17.0 + rng.uniform(-off, off, n)
    u = np.exp(1j * np.deg2rad(where))
    turn = np.exp(1j * np.deg2rad(where + rng.uniform(-3, 3, n)))
    scale = rng.uniform(1.0, 1.3, n)
    dist = 60.0 * rng.uniform(0.98, 1.02, n)
    return [
        (complex(s * t), complex(100 + 100j + d * z)) for s, t, d, z in zip(scale, turn, dist, u, strict=True)
    ]


def _check(sc, result, n: int) -> None:
    assert any(re.fullmatch(rf"P\d+: a ring of {n} nodes( \(table\))?", line) for line in result.log), (
        result.log
    )
    assert result.max_deviation <= result.tolerance
    assert hausdorff_rel(sc, drawing_scene(derive(result.grammar))) <= 0.005 + 1e-9


@pytest.mark.parametrize("arc", [False, True], ids=["ring", "arc"])
@pytest.mark.parametrize("mirror", [False, True], ids=["plain", "mirror"])
@pytest.mark.parametrize("n", RING_SIZES)
def test_copies_that_vary_a_little_on_a_ring_or_arc_are_one_rule(n: int, arc: bool, mirror: bool) -> None:
    shape = np.conj(LEAF) if mirror else LEAF
    sc = scene(place(shape, _copies(n, arc=arc, seed=n)))
    result = infer(sc)
    _check(sc, result, n)
    assert result.explained == pytest.approx(1.0)


def test_a_ring_with_one_copy_drawn_differently_is_one_rule_of_the_others() -> None:
    frames = _copies(5, arc=False, seed=11)
    sc = scene(place(LEAF, frames[:2] + frames[3:]), place(HOOK, [frames[2]]))
    result = infer(sc)
    _check(sc, result, 4)  # the ring's copies after the odd one, then those before it


@pytest.mark.parametrize("seed", range(4))
def test_copies_at_random_places_turns_and_sizes_get_no_ring(seed: int) -> None:
    rng = np.random.default_rng(seed)
    a = rng.uniform(1.0, 1.3, 20) * np.exp(1j * rng.uniform(0, 2 * np.pi, 20))
    b = rng.uniform(0, 200, 20) + 1j * rng.uniform(0, 200, 20)
    result = infer(scene(place(LEAF, list(zip(a, b, strict=True)))))
    assert not any("ring" in line for line in result.log), result.log


def test_copies_turned_in_place_or_stacked_get_no_ring_and_no_error() -> None:
    turns = np.exp(1j * np.deg2rad([0.0, 72.0, 144.0, 216.0, 288.0]))
    in_place = [(complex(t), 100 + 100j) for t in turns]  # one centre: no ring has a radius
    stacked = [(1 + 0j, 40 + 40j)] * 3
    sc = scene(place(LEAF, in_place), place(HOOK, stacked))
    result = infer(sc)
    assert not any("ring" in line for line in result.log), result.log
    assert result.max_deviation <= result.tolerance
