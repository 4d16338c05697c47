"""Near-identical (hand-drawn) copies share a terminal within the tolerance; what the report says."""

from __future__ import annotations

import numpy as np
import pytest

from lsys_core.derive.derivation import derive
from lsys_core.errors import InferenceError
from lsys_core.instancing.deviation import pose_deviations
from lsys_core.pipeline import InferenceSettings, infer, symmetrize
from lsys_core.svg.model import Element
from lsys_core.testing import drawing_scene, hausdorff_rel

from .scenes import LEAF, place, scene


def _hand_drawn(n: int, wobble: float, seed: int = 0) -> list[Element]:
    """``n`` leaves on a ring, each redrawn with its control points moved by up to ``wobble``."""
    rng = np.random.default_rng(seed)
    out = []
    for k in range(n):
        u = np.exp(2j * np.pi * k / n)
        shape = LEAF + wobble * (rng.uniform(-1, 1, LEAF.shape) + 1j * rng.uniform(-1, 1, LEAF.shape))
        shape[-1, -1] = shape[0, 0]  # still closed
        out += place(shape, [(u, 100 + 100j + 50 * u)])
    return out


def test_hand_drawn_copies_share_a_terminal_and_form_one_ring() -> None:
    sc = scene(_hand_drawn(8, 0.15))
    r = infer(sc)
    assert len(r.grammar.terminals) == 1
    assert r.log == ("P1: 1 sequences of A, lengths [8]",)
    assert r.explained == 1.0
    assert 0 < r.max_deviation <= r.tolerance
    assert r.instancing.deviation is not None and r.instancing.deviation.max() <= r.tolerance
    assert hausdorff_rel(sc, drawing_scene(derive(r.grammar))) <= 0.005 + 1e-9


def test_exact_mode_keeps_hand_drawn_copies_apart() -> None:
    sc = scene(_hand_drawn(8, 0.15))
    r = infer(sc, InferenceSettings(deviation=0.0))
    assert len(r.grammar.terminals) == 8
    assert r.explained == 0.0
    assert r.max_deviation <= r.tolerance


def test_a_larger_tolerance_merges_more_and_stays_within_it() -> None:
    sc = scene(_hand_drawn(8, 1.2, seed=3))
    strict = infer(sc)
    loose = infer(sc, InferenceSettings(deviation=5.0))
    assert len(loose.grammar.terminals) < len(strict.grammar.terminals)
    assert loose.max_deviation <= 5.0


def test_the_representative_is_the_medoid_not_the_first_copy() -> None:
    rng = np.random.default_rng(5)
    odd = LEAF * 1.0
    odd[0, 1] += 1.2  # the first copy bulges: a poor representative
    shapes = [odd] + [LEAF + 0.05 * rng.standard_normal(LEAF.shape) for _ in range(5)]
    for s in shapes:
        s[-1, -1] = s[0, 0]
    frames = [(1 + 0j, 30.0 * k + 0j) for k in range(6)]
    sc = scene([e for s, f in zip(shapes, frames, strict=True) for e in place(s, [f])])
    r = infer(sc, InferenceSettings(deviation=2.0))
    assert len(r.instancing.terminals) == 1
    dev = r.instancing.deviation
    assert dev is not None and dev.argmax() == 0  # the bulging copy is the one farthest from the terminal
    assert dev[1:].max() < 0.5 * dev[0]


def test_report_description_lengths_and_symmetrize_of_hand_drawn_jitter() -> None:
    rng = np.random.default_rng(2)
    frames = [(1 + 0j, 25.0 * k + 1j * rng.uniform(-0.8, 0.8)) for k in range(12)]
    sc = scene(place(LEAF, frames))
    r = infer(sc)
    before, after = r.description_bits
    assert after < before
    sym = symmetrize(sc)
    assert sym.log == ("P1: 1 sequences of A, lengths [12]",)
    assert sym.explained == 1.0


def test_bad_deviation_is_rejected() -> None:
    with pytest.raises(InferenceError, match="deviation"):
        infer(scene(place(LEAF, [(1 + 0j, 0j)])), InferenceSettings(deviation=-1.0))


# -- the outline distance ---------------------------------------------------------------------------


def _line(p: complex, q: complex) -> Element:
    return Element(np.array([[p, p + (q - p) / 3, p + 2 * (q - p) / 3, q]]), np.zeros(1, int), (False,))


def test_outline_distance_is_exact_for_copies_and_sees_shifts_and_parts() -> None:
    square = place(np.array([[0, 0, 10, 10], [10, 10, 10 + 10j, 10 + 10j]]), [(1 + 0j, 0j)])[0]
    one = np.ones(1, complex)
    assert pose_deviations([square], [square], np.zeros(1, int), one, np.zeros(1, complex))[0] < 1e-9
    shifted = pose_deviations([square], [square], np.zeros(1, int), one, np.array([0.3j]))[0]
    assert shifted == pytest.approx(0.3, abs=1e-6)
    half = _line(0, 5)  # lies on the shape everywhere, but covers only half of it
    assert pose_deviations([half], [_line(0, 10)], np.zeros(1, int), one, np.zeros(1, complex))[
        0
    ] == pytest.approx(5)
