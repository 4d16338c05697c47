"""The shortcuts of the description length give the same bits and the same decisions.

A set's bits computed on Python floats equal the vectorised code bit for bit; a family's pose
bits read from its table equal the sum of the ``gammaln`` terms; a candidate's ceiling is never
below its gain, so no candidate that pays is dropped before its numbers are rounded.
"""

from __future__ import annotations

import itertools

import numpy as np

from lsys_core.hierarchy import gain as gain_module
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
