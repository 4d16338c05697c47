"""The shortcuts of the description length give the same bits and the same decisions.

A set's bits computed on Python floats equal the vectorised code bit for bit; a family's pose
bits read from its table equal the sum of the ``gammaln`` terms, and the ledger's sum by cell
heights equals it up to rounding; a candidate's ceiling is never below its gain, so no candidate
that pays is dropped before its numbers are rounded; the ceilings of a whole level, worked out
together, are every candidate's own, bit for bit.
"""

from __future__ import annotations

import itertools

import numpy as np

from lsys_core.hierarchy import gain as gain_module
from lsys_core.hierarchy import reuse
from lsys_core.hierarchy.mdl import Precision, log2_binom, placement_set_bits, pose_bits, stack_table
from lsys_core.pipeline import infer

from .scenes import LEAF, place, pose, scene


def test_single_sets_cost_what_the_vectorised_code_says_bit_for_bit() -> None:
    prec = Precision.of_box(0j, 500 + 300j, 0.7)
    ns = [0, 1, 2, 3, 7, 40, 1000]
    for n, occ, p, cnt in itertools.product(ns, [None, 0, 1, 2, 5, 50], [0.0, 3.25, 17.0], [0.0, 1.5]):
        one = placement_set_bits(prec, n, occupied=occ, pose=p, counts=cnt, token=5.3)
        arr = placement_set_bits(
            prec,
            np.array([n, n]),
            occupied=None if occ is None else np.array([occ, occ]),
            pose=np.array([p, p]),
            counts=np.array([cnt, cnt]),
            token=5.3,
        )
        assert isinstance(one, float)
        assert one == arr[0], (n, occ, p, cnt)


def test_pose_bits_from_the_table_equal_the_gammaln_terms() -> None:
    rng = np.random.default_rng(3)
    for headings in (0.5, 1.0, 7.3, 250.0):
        stacks = rng.integers(0, 9, size=333)
        table = stack_table(headings, int(stacks.max()))
        direct = float(np.sum(log2_binom(np.maximum(headings, stacks.astype(float)), stacks.astype(float))))
        assert float(np.sum(table[stacks])) == direct
        assert float(np.sum(table[stacks])) + 0.0 == pose_bits(headings, 0.0, stacks)


def test_no_candidate_gains_more_than_its_ceiling(monkeypatch) -> None:
    seen: list[tuple[float, float]] = []
    exact = gain_module.Ledger.gain

    def gain(self, c):
        value = exact(self, c)
        seen.append((self.ceiling(c), value))
        return value

    monkeypatch.setattr(gain_module.Ledger, "gain", gain)
    rng = np.random.default_rng(5)
    row = [pose(40.0 * i, 0.0, 10.0 * i) for i in range(6)]
    scattered = [pose(*rng.uniform(0, 400, 2), rng.uniform(0, 360)) for _ in range(30)]
    infer(scene(place(LEAF, row), place(LEAF, scattered)))
    assert seen and any(v > 0 for _, v in seen)
    assert all(ceiling >= value for ceiling, value in seen)


def _row_and_clutter(seed: int):
    rng = np.random.default_rng(seed)
    row = [pose(40.0 * i, 0.0, 10.0 * i) for i in range(6)]
    ring = [pose(300 + 60 * np.cos(t), 300 + 60 * np.sin(t), np.degrees(t)) for t in np.linspace(0, 6, 8)]
    scattered = [pose(*rng.uniform(0, 400, 2), rng.uniform(0, 360)) for _ in range(30)]
    stacked = [pose(100.0, 200.0, 15.0 * i) for i in range(4)]  # one place, four turns: a cell of four
    return scene(place(LEAF, row), place(LEAF, ring), place(LEAF, scattered), place(LEAF, stacked))


def test_a_levels_ceilings_together_are_each_candidates_own(monkeypatch) -> None:
    levels: list[int] = []
    made = reuse.LevelView.__init__

    def init(self, cands, ledger, first) -> None:
        made(self, cands, ledger, first)
        one = [ledger.ceiling(c) for c in self.cands]  # before the level's ceilings are remembered
        together = ledger.ceilings(self.cands)
        assert together.tolist() == one
        levels.append(len(one))

    monkeypatch.setattr(reuse.LevelView, "__init__", init)
    for seed in range(3):
        infer(_row_and_clutter(seed))
    assert len(levels) >= 3 and sum(levels) > 100


def test_pose_bits_by_cell_heights_equal_the_terms_per_cell() -> None:
    rng = np.random.default_rng(11)
    for headings in (0.0, 1.0, 7.3, 250.0):
        stacks = rng.integers(1, 6, size=400)
        ledger = gain_module.Ledger.__new__(gain_module.Ledger)
        ledger.scale = np.array([0.8])
        ledger.tables = [stack_table(headings, int(stacks.max())) if headings > 0 else None]
        by_heights = ledger._key_pose(0, int(stacks.sum()), np.bincount(stacks))
        per_cell = pose_bits(headings, 0.8, stacks)
        assert abs(by_heights - per_cell) <= 1e-9 * max(per_cell, 1.0)
