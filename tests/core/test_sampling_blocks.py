"""The arc-length table is computed in blocks: the same numbers as all at once, bounded memory."""

from __future__ import annotations

import numpy as np

from lsys_core.instancing import sampling


def test_blocks_give_the_numbers_of_one_pass(monkeypatch):
    rng = np.random.default_rng(7)
    cubics = rng.normal(size=(1000, 4)) + 1j * rng.normal(size=(1000, 4))
    whole = sampling._chord_table(cubics)
    monkeypatch.setattr(sampling, "_CHUNK", 37)  # blocks that do not divide the count
    assert np.array_equal(sampling._chord_table(cubics), whole)
