"""The unwrapping walk on Python floats gives the numpy-scalar walk's rotations bit for bit (instancing.orientation)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import breadth_first_order, connected_components, minimum_spanning_tree
from scipy.spatial import cKDTree

from lsys_core.instancing.orientation import TIE, unwrap_turns


def _simple(a: np.ndarray, b: np.ndarray, period: float) -> np.ndarray:
    """The walk as first written: numpy scalars, every component found by a scan."""
    n = a.size
    theta = np.angle(a)
    if n < 2:
        return theta
    k = min(6, n - 1)
    pts = np.column_stack([b.real, b.imag])
    dist, idx = cKDTree(pts).query(pts, k=k + 1)
    graph = coo_matrix(
        (dist[:, 1:].ravel() + 1e-12, (np.repeat(np.arange(n), k), idx[:, 1:].ravel())), shape=(n, n)
    )
    tree = minimum_spanning_tree(graph.tocsr())
    tree = tree + tree.T
    out = theta.copy()
    _, comp = connected_components(tree, directed=False)
    for c in np.unique(comp):
        root = int(np.flatnonzero(comp == c)[0])
        order, parent = breadth_first_order(tree, root, directed=False, return_predecessors=True)
        for node in order[1:]:
            p = out[parent[node]]
            turn = np.mod(theta[node] - p + period / 2, period) - period / 2
            if abs(abs(turn) - period / 2) < TIE:
                turn = (
                    period / 2
                    if abs(p + period / 2 - theta[node]) <= abs(p - period / 2 - theta[node])
                    else -period / 2
                )
            out[node] = p + turn
    return out


@pytest.mark.parametrize("order", [1, 2, 3, 4, 6])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_walk_is_the_simple_one_bit_for_bit(order: int, seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = 400
    # clusters far apart (several components), a grid turning steadily, and exact half periods
    centres = rng.normal(size=5) * 1e4 + 1j * rng.normal(size=5) * 1e4
    b = centres[rng.integers(0, 5, n)] + rng.normal(size=n) * 10 + 1j * rng.normal(size=n) * 10
    b[:100] = np.arange(100) % 10 + 1j * (np.arange(100) // 10)
    angle = rng.uniform(-np.pi, np.pi, n)
    angle[:100] = np.arange(100) * 0.37
    period = 2 * np.pi / order
    angle[100:150] = np.round(angle[100:150] / (period / 2)) * (period / 2)  # ties at half a period
    a = rng.uniform(0.5, 2.0, n) * np.exp(1j * angle)
    got = unwrap_turns(a, b, period)
    assert got.tobytes() == _simple(a, b, period).tobytes()


def test_a_single_instance_keeps_its_rotation() -> None:
    a = np.array([np.exp(0.3j)])
    assert unwrap_turns(a, np.array([0j]), np.pi).tobytes() == np.angle(a).tobytes()
