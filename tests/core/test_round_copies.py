"""Hand-drawn round shapes (dots, stamens, beads) turned at random are copies, and a ring of them one rule."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from lsys_core.derive.derivation import derive
from lsys_core.instancing.model import Instancing
from lsys_core.instancing.orientation import ring_headings
from lsys_core.instancing.roundness import round_within, turn_deviation
from lsys_core.pipeline import infer
from lsys_core.render.structured import drawing_to_structured_svg
from lsys_core.svg.model import Element
from lsys_core.testing import drawing_scene, hausdorff_rel

from .scenes import LEAF, place, scene

_K = 4.0 / 3.0 * (np.sqrt(2.0) - 1.0)
#: A unit circle as four cubics about the origin.
CIRCLE = np.array(
    [
        [1, 1 + _K * 1j, _K + 1j, 1j],
        [1j, -_K + 1j, -1 + _K * 1j, -1],
        [-1, -1 - _K * 1j, -_K - 1j, -1j],
        [-1j, _K - 1j, 1 - _K * 1j, 1],
    ],
    complex,
)
#: A frame that gives the drawing its size (diagonal 170, tolerance 0.85).
FRAME = Element(
    np.array([[0, 0, 120, 120], [120, 120, 120 + 120j, 120 + 120j], [120 + 120j, 120 + 120j, 120j, 120j]]),
    np.zeros(3, int),
    (False,),
    "fill:none;stroke:#000",
)


def _closed(elements: list[Element]) -> list[Element]:
    """The elements as closed outlines (filled dots)."""
    return [replace(e, closed=(True,)) for e in elements]


def _dot(rng: np.random.Generator, wobble: float, radius: float = 4.0) -> np.ndarray:
    """A dot drawn by hand: a circle of ``radius`` with every control point moved by up to ``wobble`` radii."""
    shape = radius * (
        CIRCLE + wobble * (rng.uniform(-1, 1, CIRCLE.shape) + 1j * rng.uniform(-1, 1, CIRCLE.shape))
    )
    shape[:, 0] = np.roll(shape[:, 3], 1)  # still one closed outline
    return shape


def _ring_of_dots(n: int, seed: int, wobble: float = 0.03, jitter: float = 0.1) -> list[Element]:
    """``n`` hand-drawn dots on a ring of radius 12, each turned at random and placed within ``jitter``."""
    rng = np.random.default_rng(seed)
    out = []
    for k in range(n):
        u = np.exp(2j * np.pi * k / n)
        turn = np.exp(1j * rng.uniform(0, 2 * np.pi))
        where = 60 + 60j + 12 * u + jitter * (rng.uniform(-1, 1) + 1j * rng.uniform(-1, 1))
        out += _closed(place(_dot(rng, wobble), [(turn, where)], "fill:#fdd0b1"))
    return out


@pytest.mark.parametrize("seed", range(3))
def test_a_ring_of_hand_drawn_dots_turned_at_random_is_one_ring_rule(seed: int) -> None:
    sc = scene(_ring_of_dots(5, seed), [FRAME])
    r = infer(sc)
    assert len(r.grammar.terminals) == 2  # the dots share one terminal, the frame has its own
    assert r.instancing.symmetry[r.instancing.group[0]] == 0  # round within the tolerance
    assert r.log[0] == "P1: 1 sequences of A, lengths [5]", r.log
    assert r.explained == pytest.approx(5 / 6)
    assert r.max_deviation <= r.tolerance
    assert hausdorff_rel(sc, drawing_scene(derive(r.grammar))) <= 0.005


def test_round_within_measures_the_cost_of_a_turn_and_keeps_other_shapes() -> None:
    rng = np.random.default_rng(1)
    dot = Element(_dot(rng, 0.03), np.zeros(4, int), (True,), "")
    leaf = Element(LEAF * 0.5, np.zeros(2, int), (True,), "")
    cost = turn_deviation(dot)
    assert 0.0 < cost < 0.5  # a hand-drawn dot of radius 4 moves by a fraction of a unit when turned
    assert turn_deviation(leaf) > 2.0
    inst = Instancing(
        group=np.array([0, 0, 1]),
        a=np.array([np.exp(1j), 2 * np.exp(2j), np.exp(0.5j)]),
        b=np.array([10 + 0j, 30 + 0j, 50 + 0j]),
        terminals=(),
        symmetry=np.array([1, 1]),
        mirrored_of=np.array([-1, -1]),
        deviation=np.array([0.1, 0.2, 0.0]),
    )
    out = round_within([dot, leaf], inst, tolerance=2.0)
    assert out.symmetry.tolist() == [0, 1]
    np.testing.assert_allclose(out.a[:2], [1.0, 2.0])  # round instances carry no turn
    assert out.a[2] == inst.a[2]
    assert out.deviation is not None
    np.testing.assert_allclose(out.deviation, [0.1 + cost, 0.2 + 2 * cost, 0.0])
    # a tolerance smaller than what a turn costs (at scale 2) keeps the dot as drawn
    assert round_within([dot, leaf], inst, tolerance=cost).symmetry.tolist() == [1, 1]


def test_round_shapes_on_a_ring_face_its_centre_and_rows_keep_their_headings() -> None:
    ring = 50 + 50j + 20 * np.exp(2j * np.pi * np.arange(7) / 7)
    row = 10 + 90j + 8.0 * np.arange(4)
    inst = Instancing(
        group=np.array([0] * 7 + [1] * 4),
        a=np.ones(11, complex),
        b=np.concatenate([ring, row]),
        terminals=(),
        symmetry=np.array([0, 0]),
        mirrored_of=np.array([-1, -1]),
    )
    out = ring_headings(inst, tolerance=0.1)
    np.testing.assert_allclose(out.a[:7], (ring - (50 + 50j)) / 20, atol=1e-9)
    np.testing.assert_allclose(out.a[7:], 1.0)
    assert out.symmetry.tolist() == [0, 0]


def test_a_ring_of_circles_is_one_constant_sequence_written_as_circles() -> None:
    frames = [(1 + 0j, complex(60 + 60j + 20 * np.exp(2j * np.pi * k / 8))) for k in range(8)]
    r = infer(scene(_closed(place(3 * CIRCLE, frames, "fill:#000"))))
    assert r.log == ("P1: 1 sequences of A, lengths [8]",)
    svg = drawing_to_structured_svg(derive(r.grammar))
    assert "<circle" in svg and "rotate(" not in svg
