"""A looser tolerance only buys structure: when merging two kinds of shape hides what each repeats, the tighter one is kept."""

from __future__ import annotations

from itertools import pairwise

import numpy as np
import pytest

from lsys_core.derive.derivation import derive
from lsys_core.pipeline import DEFAULT_DEVIATION, TIGHTER, infer
from lsys_core.report import bounds
from lsys_core.testing import drawing_scene, hausdorff_rel

from .scenes import place, pose, scene


def _polyline(*points: complex) -> np.ndarray:
    pts = [complex(p) for p in points]
    return np.array([[p, p, q, q] for p, q in pairwise(pts)])


def _corner(left: float, right: float) -> np.ndarray:
    """A corner mark: two legs meeting at 120° at the origin."""
    u, v = np.exp(1j * np.radians(150.0)), np.exp(1j * np.radians(30.0))
    return _polyline(left * u, 0, right * v)


def _dashed_hexagon(stretch: float) -> list:
    """Corner marks of a hexagon, two with equal legs and four with one leg ``stretch`` times longer
    (mirrored on one side), and three spokes from the centre, one ``stretch`` times longer."""
    even, odd = _corner(10.0, 10.0), _corner(10.0, 10.0 * stretch)
    els = []
    for k in range(6):
        c = 100 + 100j + 60 * np.exp(1j * np.radians(60 * k))
        shape = even if k in (0, 3) else odd
        els += place(shape.conj() if k in (2, 5) else shape, [pose(c.real, c.imag, 60 * k - 90)])
    line = _polyline(0, 1)
    for k, length in enumerate((12.0, 12.0, 12.0 * stretch)):
        turn = np.radians(90 + 120 * k)
        els += place(line, [pose(100 + 10 * np.cos(turn), 100 + 10 * np.sin(turn), 90 + 120 * k, length)])
    return els


def test_two_kinds_merged_by_the_tolerance_are_told_apart_when_that_explains_more() -> None:
    sc = scene(_dashed_hexagon(1.06))  # the corners differ by less than the default tolerance
    lo, hi = bounds(sc)
    r = infer(sc)
    assert r.explained == 1.0  # merged into one terminal, the even corners were placed one by one
    assert r.tolerance == pytest.approx(
        TIGHTER * DEFAULT_DEVIATION * abs(hi - lo)
    )  # the tighter one was kept
    assert len(r.grammar.terminals) >= 3  # even corners, odd corners and spokes
    assert r.max_deviation <= r.tolerance
    assert hausdorff_rel(sc, drawing_scene(derive(r.grammar))) <= TIGHTER * DEFAULT_DEVIATION + 1e-9


def test_without_merged_shapes_the_users_tolerance_stays() -> None:
    sc = scene(_dashed_hexagon(1.0))  # one kind of corner: no shapes differ, nothing to tell apart
    lo, hi = bounds(sc)
    r = infer(sc)
    assert r.tolerance == pytest.approx(DEFAULT_DEVIATION * abs(hi - lo))
