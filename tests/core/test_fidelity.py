"""Elements that only resemble their group's shape keep their own terminal."""

from __future__ import annotations

import itertools

import numpy as np

from lsys_core.derive.derivation import derive
from lsys_core.pipeline import infer

from .scenes import place, pose, scene


def bar(h: float) -> np.ndarray:
    pts = [0, 15, 15 + 1j * h, 1j * h, 0]
    return np.array([[p, p + (q - p) / 3, p + 2 * (q - p) / 3, q] for p, q in itertools.pairwise(pts)])


def test_taller_bar_is_not_replaced_by_the_short_one() -> None:
    short = place(bar(120), [pose(30 * i, 0) for i in (0, 1, 3, 4)])
    tall = place(bar(140), [pose(60, -10)])
    r = infer(scene(short, tall))
    assert len(derive(r.grammar)) == 5
    assert r.stages["reproduction_error"] < 1e-6
    # drawn as itself: a terminal of its own, or the short bar stretched by 20 (``~(20)``)
    assert r.instancing.deviation is not None and r.instancing.deviation.max() < 1e-6
    assert r.max_deviation < 0.01  # the rules' rounding; the short bar in its place would be 10 off


def test_redrawn_copies_still_share_a_terminal() -> None:
    b = bar(120)
    reversed_bar = np.array([seg[::-1] for seg in b[::-1]])
    r = infer(
        scene(
            place(b, [pose(30 * i, 0) for i in range(3)]),
            place(reversed_bar, [pose(90 + 30 * i, 0) for i in range(3)]),
        )
    )
    assert len(r.grammar.terminals) == 1
