"""The packed-key sorts give numpy's own answers: stable orders, first occurrences, groups of rows."""

from __future__ import annotations

import numpy as np
import pytest

from lsys_core.sorting import first_occurrences, row_groups, stable_argsort


def _ints(seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(0, 3000))
    span = [3, 200, 10**6, 2**40, 2**62][seed % 5]  # the widest spans take numpy's own sort
    return rng.integers(-span, span, n) if seed % 2 else rng.integers(0, span, n)


@pytest.mark.parametrize("seed", range(20))
def test_stable_argsort_is_numpys(seed: int) -> None:
    x = _ints(seed)
    assert stable_argsort(x).tolist() == np.argsort(x, kind="stable").tolist()
    assert stable_argsort(x.astype(np.int32) if abs(x).max(initial=0) < 2**31 else x).tolist() == (
        np.argsort(x, kind="stable").tolist()
    )


@pytest.mark.parametrize("seed", range(20))
def test_first_occurrences_are_numpys(seed: int) -> None:
    x = _ints(seed) // 7
    assert first_occurrences(x).tolist() == np.sort(np.unique(x, return_index=True)[1]).tolist()


@pytest.mark.parametrize("seed", range(12))
def test_row_groups_are_numpys(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 2000))
    cols = [rng.integers(0, 4, n), rng.integers(1, 30, n), np.round(rng.normal(0, 3, n)), -np.zeros(n)]
    cols[3][::3] = 0.0  # -0.0 and 0.0 are one value, as numpy compares them
    _, first, inv, counts = np.unique(
        np.column_stack(cols), axis=0, return_index=True, return_inverse=True, return_counts=True
    )
    got = row_groups(cols)
    assert got[0].tolist() == first.tolist()
    assert got[1].tolist() == inv.ravel().tolist()
    assert got[2].tolist() == counts.tolist()
    empty = row_groups([np.zeros(0), np.zeros(0, int)])
    assert all(x.size == 0 for x in empty)


@pytest.mark.parametrize("seed", range(12))
def test_distinct_counts_mark_or_sort_to_the_definition(seed: int, monkeypatch) -> None:
    from lsys_core import sorting

    rng = np.random.default_rng(seed)
    n_labels, size = int(rng.integers(1, 60)), int(rng.integers(1, 5000))
    n = int(rng.integers(0, 4000))
    labels, values = rng.integers(0, n_labels, n), rng.integers(0, size, n)
    want = np.bincount(np.unique(labels * size + values) // size, minlength=n_labels)
    assert sorting.distinct_counts(labels, values, n_labels, size).tolist() == want.tolist()
    monkeypatch.setattr(sorting, "DENSE_CELLS", 0)  # the sorting path
    assert not sorting.dense_fits(n_labels, size, n)
    assert sorting.distinct_counts(labels, values, n_labels, size).tolist() == want.tolist()
