"""Bulk readings of the elements give what the element-by-element readings gave (instancing)."""

from __future__ import annotations

import numpy as np
import pytest

from lsys_core.instancing import similarity
from lsys_core.instancing.exact import structure_ids, structure_key
from lsys_core.instancing.stretch import _stacked
from lsys_core.svg.model import Element


def _simple_next(group: np.ndarray, cursor: int) -> int:
    while cursor < group.size and group[cursor] >= 0:
        cursor += 1
    return cursor


@pytest.mark.parametrize("seed", range(4))
def test_next_free_is_the_one_by_one_scan(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 20_000))
    group = np.where(rng.random(n) < rng.choice([0.0, 0.5, 0.999, 1.0]), 3, -1)
    group[rng.integers(0, n, 3)] = -1
    for cursor in [0, 1, n // 2, n - 1, n, *rng.integers(0, n, 20).tolist()]:
        assert similarity._next_free(group, int(cursor)) == _simple_next(group, int(cursor))


def _element(k: int, subpaths, closed) -> Element:
    return Element(np.arange(4 * k, dtype=float).reshape(k, 4) * (1 + 1j), np.asarray(subpaths), closed)


def test_structure_ids_number_the_structure_keys() -> None:
    elements = [
        _element(2, [0, 0], (True,)),
        _element(2, [0, 1], (True, False)),
        _element(2, [0, 0], (np.True_,)),  # numpy booleans: the same structure
        _element(2, [0, 1], (True, True)),
        _element(1, [0], (True,)),
        _element(2, [0, 0], (False,)),
        _element(2, np.array([0, 1], np.int32), (True, False)),  # other bytes: another structure
        _element(2, [0, 1], (True, False)),
    ]
    keys = [structure_key(e) for e in elements]
    first = {k: i for i, k in enumerate(dict.fromkeys(keys))}
    expected = np.array([first[k] for k in keys])
    np.testing.assert_array_equal(structure_ids(elements), expected)
    listed = [*elements[:-1], Element(elements[-1].cubics, elements[-1].subpaths, [True, False])]  # type: ignore[arg-type]
    np.testing.assert_array_equal(structure_ids(listed), expected)  # a list of flags: keyed the slow way


def test_stacked_cubics_are_the_stacked_elements() -> None:
    rng = np.random.default_rng(1)
    elements = tuple(
        Element(rng.normal(size=(3, 4)) + 1j * rng.normal(size=(3, 4)), np.zeros(3, int), (True,))
        for _ in range(9)
    )
    idx = np.array([0, 4, 5, 8])
    expected = np.stack([np.asarray(elements[i].cubics, complex).reshape(-1, 4) for i in idx])
    assert _stacked(elements, idx).tobytes() == expected.tobytes()


def _rect(x: float, y: float, w: float, h: float) -> Element:
    pts = np.array([x + 1j * y, x + w + 1j * y, x + w + 1j * (y + h), x + 1j * (y + h)])
    ends = np.roll(pts, -1)
    cubics = np.column_stack([pts, pts + (ends - pts) / 3, pts + 2 * (ends - pts) / 3, ends])
    return Element(cubics, np.zeros(4, np.intp), (True,))


def test_families_on_both_axes_are_the_families_of_fresh_stacks() -> None:
    from lsys_core.instancing import stretch
    from lsys_core.sorting import row_groups
    from lsys_core.svg.model import Scene

    tall = [_rect(10 * i, 0, 4, 5 + 3 * i) for i in range(5)]  # one width, heights differ: along y
    wide = [_rect(0, 50 + 10 * i, 5 + 3 * i, 4) for i in range(5)]  # one height, widths differ: along x
    other = [_rect(100, 100, 7, 7), _rect(120, 100, 7, 7)]
    scene = Scene(tuple(tall + wide + other))
    free = np.ones(len(scene.elements), bool)

    def simple(tol: float):
        out, taken = [], ~free
        structure = structure_ids(scene.elements)
        for axis in stretch._AXES:
            avail = np.flatnonzero(~taken)
            for run in sorted(stretch._runs(structure[avail]), key=lambda r: int(r[0])):
                if run.size < 2:
                    continue
                idx = avail[run]
                cubics = (
                    np.stack([np.asarray(scene.elements[i].cubics, complex).reshape(-1, 4) for i in idx])
                    * axis
                )
                key, length, _ = stretch._profiles(cubics, tol)
                for sel in stretch._runs(row_groups(list(key.T))[1]):
                    sel = sel[length[sel] > stretch._FLAT * tol]
                    if sel.size >= 2 and np.ptp(length[sel]) > tol:
                        out.append((axis, idx[sel]))
                        taken[idx[sel]] = True
        return out

    got, expected = stretch._families(scene, free, 0.1), simple(0.1)
    assert {axis for axis, _ in got} == {1, 1j}
    assert [(axis, m.tolist()) for axis, m in got] == [(axis, m.tolist()) for axis, m in expected]
