"""Fast paths for small inputs give what the general code gives: rules compared with them off."""

from __future__ import annotations

import numpy as np

from lsys_core import sorting
from lsys_core.derive.derivation import derive
from lsys_core.grammar import format_grammar
from lsys_core.pipeline import infer

from .scenes import LEAF, place, pose, scene


def _rotating_grid(rows: int, cols: int):
    """Leaves whose rotation grows 12° per column: linear sequences and constant pairs."""
    frames = [pose(40.0 * c, 40.0 * r, 12.0 * c) for r in range(rows) for c in range(cols)]
    return scene(place(LEAF, frames))


def _rules(grid):
    result = infer(grid)
    return format_grammar(result.grammar), derive(result.grammar), result.log


def test_distinct_counts_by_marking_give_the_rules_of_sorting(monkeypatch) -> None:
    grid = _rotating_grid(12, 16)
    marked: list[bool] = []
    fits = sorting.dense_fits

    def spy(n_labels: int, size: int, entries: int) -> bool:
        marked.append(fits(n_labels, size, entries))
        return marked[-1]

    monkeypatch.setattr(sorting, "dense_fits", spy)
    import lsys_core.hierarchy.linear as linear

    monkeypatch.setattr(linear, "dense_fits", spy)
    fast = _rules(grid)
    assert any(marked)  # the marking path ran
    monkeypatch.setattr(sorting, "DENSE_CELLS", 0)
    marked.clear()
    slow = _rules(grid)
    assert not any(marked)
    assert fast[0] == slow[0] and fast[2] == slow[2]
    assert np.array_equal(fast[1].a, slow[1].a) and np.array_equal(fast[1].b, slow[1].b)


def test_start_orders_in_one_pass_are_the_per_candidate_means() -> None:
    from lsys_core.hierarchy.candidates import SeqCandidate
    from lsys_core.hierarchy.flat import Groups
    from lsys_core.hierarchy.reuse import start_orders

    rng = np.random.default_rng(5)
    for _ in range(50):
        n = 200
        cands = [
            SeqCandidate(
                space=(0, 0),
                groups=Groups.of(
                    [rng.integers(0, n, int(rng.integers(1, 5))) for _ in range(int(rng.integers(1, 6)))]
                ),
                h=1.0,
                phi=1.0,
                l=1.0,
                A=1 + 0j,
                B=0j,
            )
            for _ in range(int(rng.integers(1, 20)))
        ]
        first = rng.permutation(n).astype(np.float64)
        want = [
            (
                float(np.mean(first[c.groups.firsts])),
                float(np.mean(first[[g[1] if g.size > 1 else g[0] for g in c.groups]])),
            )
            for c in cands
        ]
        assert start_orders(cands, first) == want


def test_cluster_means_at_once_are_the_per_cluster_means() -> None:
    from lsys_core.hierarchy.candidates import cluster_means, mean_rel

    rng = np.random.default_rng(11)
    for _ in range(40):
        n = int(rng.integers(50, 3000))
        A = np.exp(rng.normal(size=n) * rng.uniform(0, 2) + 1j * rng.uniform(-np.pi, np.pi, n))
        B = (rng.normal(size=n) + 1j * rng.normal(size=n)) * 10 ** rng.uniform(-3, 4)
        h = rng.uniform(0, 1, n)
        perm, members, i = rng.permutation(n), [], 0
        while i < n and len(members) < 300:
            size = int(rng.choice([0, 1, 2, 2, 3, 4, 5, 9, 17, 64, 130]))
            members.append(np.sort(perm[i : i + size]))
            i += size
        for m, got in zip(members, cluster_means(A, B, h, members), strict=True):
            if m.size == 0:
                assert got is None
            else:
                assert got == (*mean_rel(A[m], B[m]), float(np.mean(h[m])))
