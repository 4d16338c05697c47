"""Partly regular repetitions become one rule with a table value (lsys_core.hierarchy.tabulated)."""

from __future__ import annotations

import numpy as np

from lsys_core.derive.derivation import derive
from lsys_core.grammar.model import Grammar, Turtle
from lsys_core.hierarchy.tabulated import _level_runs
from lsys_core.pipeline import infer
from lsys_core.testing import assert_scenes_close, drawing_scene
from tests.core.scenes import LEAF, place, pose, scene

#: A circle of radius 1 about the origin, four cubics.
_K = 0.5522847498
CIRCLE = np.array(
    [
        [1, 1 + _K * 1j, _K + 1j, 1j],
        [1j, -_K + 1j, -1 + _K * 1j, -1],
        [-1, -1 - _K * 1j, -_K - 1j, -1j],
        [-1j, _K - 1j, 1 - _K * 1j, 1],
    ]
)


def _table_rules(g: Grammar) -> list[str]:
    """Names of the rules whose bodies hold a table value."""
    return [
        r.name
        for r in g.rules
        if any(isinstance(m, Turtle) and m.value.table for c in r.cases for m in c.body)
    ]


def _placed_by(g: Grammar, name: str) -> int:
    """How many instances the derivation draws through rule ``name``."""
    d = derive(g)
    names = [r.name for r in g.rules]
    return int(np.count_nonzero(d.rule == names.index(name)))


def test_concentric_circles_of_irregular_radii_in_alternating_colours_are_one_rule() -> None:
    radii = [18, 17, 13, 11, 9, 6, 2, 1]  # no progression: the paper's sequences cannot code them
    colours = ["#191919", "#313131"] * 4
    elements = [
        e
        for r, c in zip(radii, colours, strict=True)
        for e in place(CIRCLE, [pose(50, 40, 0, r)], f"fill:{c};stroke:none")
    ]
    s = scene(elements, place(LEAF, [pose(5, 5)]))
    g = infer(s).grammar
    tables = _table_rules(g)
    assert len(tables) == 1
    assert _placed_by(g, tables[0]) == 8
    assert_scenes_close(s, drawing_scene(derive(g)))


def test_rows_of_dots_at_data_positions_are_one_rule() -> None:
    rng = np.random.default_rng(3)
    # a dot plot: 12 evenly spaced rows, in each a dot of two series at its own x
    x = 100 + rng.uniform(0, 60, (12, 2))
    frames = [pose(x[i, j], 20 + 12 * i, 0, 2.5) for j in range(2) for i in rng.permutation(12)]
    s = scene(
        place(CIRCLE, frames, "fill:#4c78a8;stroke:none"), place(LEAF, [pose(0, 0), pose(300, 200, 40)])
    )
    g = infer(s).grammar
    tables = _table_rules(g)
    assert len(tables) == 1
    assert _placed_by(g, tables[0]) == 24
    assert_scenes_close(s, drawing_scene(derive(g)))


def test_rows_of_dots_step_over_a_legend_of_the_same_dots() -> None:
    rng = np.random.default_rng(5)
    # a dot plot as above, with two legend dots of the same shape among its rows: one between
    # two rows, one two units above a row (it would merge with that row's dots)
    x = 100 + rng.uniform(0, 60, (12, 2))
    frames = [pose(x[i, j], 20 + 12 * i, 0, 2.5) for i in range(12) for j in range(2)]
    legend = [pose(250, 20 + 12 * 3 + 5, 0, 2.5), pose(250, 20 + 12 * 7 - 2, 0, 2.5)]
    s = scene(
        place(CIRCLE, frames + legend, "fill:#4c78a8;stroke:none"),
        place(LEAF, [pose(0, 0), pose(300, 200, 40)]),
    )
    g = infer(s).grammar
    tables = _table_rules(g)
    assert len(tables) == 1
    assert _placed_by(g, tables[0]) == 24
    assert_scenes_close(s, drawing_scene(derive(g)))


def test_copies_at_random_places_make_no_table_rule() -> None:
    rng = np.random.default_rng(7)
    frames = [pose(*xy) for xy in rng.uniform(0, 1000, (300, 2))]
    g = infer(scene(place(LEAF, frames))).grammar
    assert _table_rules(g) == []


def test_copies_stacked_at_one_size_are_not_concentric() -> None:
    frames = [pose(20, 20)] * 3 + [pose(200, 20, 30), pose(120, 150, 80)]
    g = infer(scene(place(LEAF, frames))).grammar
    assert _table_rules(g) == []


def test_rows_of_turned_shapes_keep_their_pose() -> None:
    rng = np.random.default_rng(5)
    x = 100 + rng.uniform(0, 60, (14, 3))
    # three series of an asymmetric shape, turned 30°, in 14 columns 15 apart
    frames = [pose(20 + 15 * i, x[i, j], 30, 0.8) for i in rng.permutation(14) for j in range(3)]
    s = scene(place(LEAF, frames))
    g = infer(s).grammar
    tables = _table_rules(g)
    assert len(tables) == 1
    assert _placed_by(g, tables[0]) == 42
    assert_scenes_close(s, drawing_scene(derive(g)))


def test_a_level_spread_wider_than_the_tolerance_ends_a_row() -> None:
    # four levels of four values; the third's values are chained 1.1 apart (one level at a
    # merge distance of 1.2) and one more: its four nearest its place reach 2.2 from it
    spread = [17.8, 18.9, 20.0, 21.1, 22.2]
    along = np.array([0.0] * 4 + [10.0] * 4 + spread + [30.0] * 4)
    assert _level_runs(along, 1.2) == []
    # the same with the stray one near the place: the row takes the four within the tolerance
    along = np.array([0.0] * 4 + [10.0] * 4 + [19.0, 19.9, 20.0, 20.1, 21.0] + [30.0] * 4)
    (at, k, step), *_ = _level_runs(along, 1.2)
    assert (k, step, at.size) == (4, 10.0, 16)
    assert np.max(np.abs(along[at].reshape(4, 4) - [[0], [10], [20], [30]])) <= 1.2
