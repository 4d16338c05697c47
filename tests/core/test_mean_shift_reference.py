"""The project's mean shift against scikit-learn's ``MeanShift``, the reference implementation.

scikit-learn is a test dependency only (the ``test`` extra): the project's vectorised mean
shift (flat kernel, weighted bin seeding on half-bandwidth cells) must find the same
clusters as ``sklearn.cluster.MeanShift(bandwidth=1, bin_seeding=True)`` where the answer
is not ambiguous, i.e. on blobs much narrower than the bandwidth and far apart.
"""

from __future__ import annotations

import numpy as np
import pytest

from lsys_core.hierarchy.clustering import mean_shift

sklearn_cluster = pytest.importorskip("sklearn.cluster", reason="scikit-learn is in the test extra")


def blobs(seed: int, dim: int) -> np.ndarray:
    """Blobs of 1-40 points, spread 0.1, whose centres are at least 4 bandwidths apart."""
    rng = np.random.default_rng(seed)
    k = int(rng.integers(2, 9))
    side = 40 if dim == 1 else 6
    grid = rng.permutation(np.arange(side**dim))[:k]
    centres = np.stack(np.unravel_index(grid, (side,) * dim), axis=1) * 5.0 + rng.uniform(-0.5, 0.5, (k, dim))
    sizes = rng.integers(1, 41, k)
    pts = np.concatenate([c + rng.normal(0.0, 0.1, (s, dim)) for c, s in zip(centres, sizes, strict=True)])
    return pts[rng.permutation(len(pts))]


def same_partition(a: np.ndarray, b: np.ndarray) -> bool:
    """Whether two labellings group the points identically (labels may differ)."""
    pairs = set(zip(a.tolist(), b.tolist(), strict=True))
    return len(pairs) == len(set(a.tolist())) == len(set(b.tolist()))


@pytest.mark.parametrize("dim", [1, 2, 3, 4])
@pytest.mark.parametrize("seed", range(5))
def test_mean_shift_matches_scikit_learn(seed: int, dim: int) -> None:
    pts = blobs(seed, dim)
    ours, modes = mean_shift(pts)
    ref = sklearn_cluster.MeanShift(bandwidth=1.0, bin_seeding=True).fit(pts)
    assert same_partition(ours, ref.labels_)
    # the same modes, up to the order: each of ours is within 0.05 of one of scikit-learn's
    dist = np.linalg.norm(modes[:, None, :] - ref.cluster_centers_[None, :, :], axis=2)
    assert modes.shape == ref.cluster_centers_.shape
    assert np.all(dist.min(axis=1) < 0.05)
