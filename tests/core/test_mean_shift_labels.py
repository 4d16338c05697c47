"""Mean shift labels its points per cell only where that gives the KD-tree's answer.

:func:`lsys_core.hierarchy.clustering.mean_shift` labels large point sets by reasoning per
half-bandwidth cell (a cell whose reach holds one mode needs no tree query).  With the
threshold lowered to 0, every size takes that path; with it raised, every point is queried:
the labels and modes must be the same, including points farther than a bandwidth from every
mode (singleton clusters) and cells between two modes.
"""

from __future__ import annotations

import numpy as np
import pytest

from lsys_core.hierarchy import clustering


def scene(seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    dim = int(rng.integers(1, 7))
    k = int(rng.integers(1, 60))
    n = int(rng.integers(200, 4000))
    centres = rng.normal(0.0, rng.uniform(0.5, 12.0), (k, dim))
    return centres[rng.integers(0, k, n)] + rng.normal(0.0, rng.uniform(0.05, 2.0), (n, dim))


@pytest.mark.parametrize("seed", range(40))
def test_cell_labels_equal_tree_labels(seed: int, monkeypatch: pytest.MonkeyPatch) -> None:
    pts = scene(seed)
    monkeypatch.setattr(clustering, "_DIRECT", 10**12)
    by_tree = clustering.mean_shift(pts)
    monkeypatch.setattr(clustering, "_DIRECT", 0)
    monkeypatch.setattr(clustering, "_BLOCK", 97)  # several blocks, one of them partial
    by_cell = clustering.mean_shift(pts)
    np.testing.assert_array_equal(by_cell[0], by_tree[0])
    np.testing.assert_array_equal(by_cell[1], by_tree[1])
