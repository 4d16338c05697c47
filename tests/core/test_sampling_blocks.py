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


def _elements(count: int, seed: int = 3):
    """Closed and open paths of 1-4 segments (some open ones get the Newton steps)."""
    from lsys_core.svg.model import Element

    rng = np.random.default_rng(seed)
    out = []
    for i in range(count):
        k = 1 + i % 4
        c = rng.normal(size=(k, 4)) + 1j * rng.normal(size=(k, 4)) + 10.0 * i
        out.append(Element(c, np.zeros(k, np.intp), (i % 3 != 0,)))
    return out


def _same(a, b) -> bool:
    return all(
        getattr(a, f).dtype == getattr(b, f).dtype and getattr(a, f).tobytes() == getattr(b, f).tobytes()
        for f in sampling.Samples.__dataclass_fields__
    )


def test_rows_sampled_in_blocks_are_the_rows_sampled_at_once(monkeypatch):
    els = _elements(50)
    fractions = sampling.arc_fractions(24)
    whole = sampling.sample_elements(els, fractions)
    for rows in (1, 7, 64):
        monkeypatch.setattr(sampling, "ROWS", rows)
        assert _same(sampling.sample_elements(els, fractions), whole)


def test_sample_all_is_the_same_for_any_number_of_workers():
    from lsys_core import parallel

    els = _elements(700)
    fractions = sampling.arc_fractions(32)
    got = {}
    try:
        for jobs in (1, 2, 3):
            parallel.set_jobs(jobs)
            got[jobs] = sampling.sample_all(els, fractions, 300)
    finally:
        parallel.set_jobs(None)
    for jobs in (2, 3):
        assert _same(got[jobs][0], got[1][0])
        assert all(x.tobytes() == y.tobytes() for x, y in zip(got[jobs][1:], got[1][1:], strict=True))
    # each group of 300 elements is sampled as one, the open ones precisely; described row by row
    samples, centroid, radius, desc, _ = got[1]
    precise = np.array([not e.closed[0] for e in els])
    first = sampling.sample_elements(els[300:600], fractions, precise[300:600])
    assert _same(samples.rows(slice(300, 600)), first)
    c, r, d = sampling.element_features(first)
    assert np.array_equal(centroid[300:600], c) and np.array_equal(radius[300:600], r)
    assert np.array_equal(desc[300:600], d)


def test_elements_without_segments_have_no_length_and_their_samples_at_zero():
    from lsys_core.svg.model import Element

    empty = Element(np.zeros((0, 4), complex), np.zeros(0, np.intp), ())
    els = [empty, *_elements(2), empty]
    s = sampling.sample_elements(els, sampling.arc_fractions(8))
    assert np.all(s.points[[0, 3]] == 0)
    assert np.all(s.length[[0, 3]] == 0) and np.all(s.length[1:3] > 0)
    alone = sampling.sample_elements([empty], sampling.arc_fractions(8))
    assert np.all(alone.normals == 1) and np.all(alone.segment == 0) and np.all(alone.param == 0)
