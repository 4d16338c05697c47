"""Unit tests of the inference stages: mean shift, transformation spaces, pivots, cancellation."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from lsys_core.cancel import CancelToken
from lsys_core.errors import Cancelled
from lsys_core.geometry.transforms import rel_from_t4, t4_from_rel
from lsys_core.hierarchy.clustering import mean_shift
from lsys_core.hierarchy.spaces import pair_space
from lsys_core.pipeline import infer

from .scenes import LEAF, place, pose, scene


def test_mean_shift_separates_blobs_and_sorts_by_size() -> None:
    rng = np.random.default_rng(0)
    big = rng.normal(0, 0.1, (50, 3))
    small = rng.normal(5, 0.1, (20, 3))
    labels, modes = mean_shift(np.vstack([small, big]))
    assert set(labels[20:]) == {0} and set(labels[:20]) == {1}
    assert np.allclose(modes[0], 0, atol=0.1) and np.allclose(modes[1], 5, atol=0.1)


def test_mean_shift_keeps_lone_points_apart() -> None:
    labels, _ = mean_shift(np.array([[0.0, 0.0], [10.0, 0.0], [0.0, 10.0]]))
    assert len(set(labels.tolist())) == 3


def test_t4_round_trip() -> None:
    A, B = rel_from_t4(30.0, 12.0, 0.8, -50.0)
    al, d, s, be = (float(v) for v in t4_from_rel(A, B))
    assert np.allclose([al, d, s, be], [30, 12, 0.8, -50])


def test_pair_space_links_back_to_both_nodes() -> None:
    a = np.ones(3, complex) * np.exp(1j * np.deg2rad([0, 10, 20]))
    b = np.array([0, 10, 20], complex)
    ps = pair_space(a, b, b, np.ones(3), k=2)
    # Every directed neighbour pair once; the transform maps src's frame to dst's.
    assert sorted(zip(ps.src.tolist(), ps.dst.tolist(), strict=True)) == [
        (0, 1),
        (0, 2),
        (1, 0),
        (1, 2),
        (2, 0),
        (2, 1),
    ]
    i = np.flatnonzero((ps.src == 0) & (ps.dst == 1))[0]
    assert np.isclose(a[0] * ps.A[i], a[1]) and np.isclose(b[0] + a[0] * ps.B[i], b[1])


def test_pivot_makes_rotating_row_linear() -> None:
    # Leaves turning about their base (not their centroid) along a row.
    frames = [pose(20 + 40 * i, 20, 9 * i) for i in range(12)]
    r = infer(scene(place(LEAF, frames)))
    assert r.grammar.production_count == 2
    assert r.stages["reproduction_error"] < 1e-6


def test_cancel_stops_inference() -> None:
    token = CancelToken()
    token.cancel()
    with pytest.raises(Cancelled):
        infer(scene(place(LEAF, [pose(30 * i, 0) for i in range(20)])), cancel=token)


def test_progress_reports_stages() -> None:
    seen: list[tuple[str, float]] = []
    infer(scene(place(LEAF, [pose(30 * i, 0) for i in range(20)])), progress=lambda s, f: seen.append((s, f)))
    stages = {s for s, _ in seen}
    assert {"similarity", "rules"} <= stages
    assert all(0.0 <= f <= 1.0 for _, f in seen)


def test_ring_of_symmetric_bars_is_one_sequence() -> None:
    """Bars look the same turned by 180°: their rotations are unwrapped around the ring."""
    pts = [-1 - 2.5j, 1 - 2.5j, 1 + 2.5j, -1 + 2.5j, -1 - 2.5j]
    bar = np.array([[p, p + (q - p) / 3, p + 2 * (q - p) / 3, q] for p, q in itertools.pairwise(pts)])
    frames = [
        (np.exp(1j * np.deg2rad(30 * k)), 12 + 12j + 9 * np.exp(1j * np.deg2rad(30 * k - 90)))
        for k in range(12)
    ]
    r = infer(scene(place(bar, frames, style="fill:#000")))
    assert r.grammar.production_count == 2
    assert r.stages["reproduction_error"] < 1e-6
