"""Rows far longer than the distance between them are one sequence of rows (spacing-capped bandwidths).

The clustering bandwidth of a row is relative to its size (§5.3); a row 40 times longer than
the distance to the next would merge the step to the next row with the step to the one after,
and the rows came back as two interleaved sequences of every other row.
"""

from __future__ import annotations

import numpy as np

from lsys_core.derive.derivation import derive
from lsys_core.hierarchy.spaces import pair_space
from lsys_core.hierarchy.spacing import spacing_cap
from lsys_core.pipeline import infer
from lsys_core.testing import drawing_scene, hausdorff_rel

from .scenes import LEAF, place, pose, scene


def _rows(rows: int, cols: int, pitch: float, turn: float):
    """``rows`` rows ``pitch`` apart of ``cols`` leaves ``pitch`` apart, each turned ``turn``° more than the last."""
    return scene(
        place(LEAF, [pose(pitch * c, pitch * r, turn * c) for r in range(rows) for c in range(cols)])
    )


def test_close_rows_are_one_sequence_of_rows() -> None:
    sc = _rows(8, 200, 40.0, 7.0)  # rows 8,000 long, 40 apart: 2 % of a row's radius is 80
    res = infer(sc)
    g = res.grammar
    assert res.log[-1] == "P2: 1 sequences of P1, lengths [8]", res.log  # not every other row twice
    assert len(g.rules) == 2 and res.explained == 1.0
    assert hausdorff_rel(drawing_scene(derive(g)), sc) < 0.005


def test_cap_follows_spacing_and_spares_terminals() -> None:
    n = 10
    a = np.ones(n, complex)
    b = np.arange(n) * 3j
    ps = pair_space(a, b, b, np.full(n, 400.0), k=4)
    key = np.zeros(len(ps), np.int64)
    composite = ps.src >= 0
    cap = spacing_cap(ps, key, composite, n, floor=0.1)
    assert np.allclose(cap, 0.75)  # a quarter of the nearest-neighbour distance 3
    assert np.all(np.isinf(spacing_cap(ps, key, ~composite, n, floor=0.1)))
    assert np.allclose(spacing_cap(ps, key, composite, n, floor=2.0), 2.0)  # never below the floor
