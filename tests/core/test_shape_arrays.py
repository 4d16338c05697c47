"""Terminal path data is parsed once: shared read-only arrays, bounded cache, errors not cached."""

from __future__ import annotations

import numpy as np
import pytest

from lsys_core.errors import SvgError
from lsys_core.geometry import shapes
from lsys_core.geometry.paths import cubics_from_d
from lsys_core.geometry.shapes import shape_arrays


def test_same_text_gives_the_same_read_only_arrays() -> None:
    d = "M0 0 L10 0 C12 1 12 4 10 5 Z"
    first = shape_arrays(d)
    again = shape_arrays(d)
    assert again[0] is first[0] and again[1] is first[1]
    expected = cubics_from_d(d)
    np.testing.assert_array_equal(first[0], expected[0])
    np.testing.assert_array_equal(first[1], expected[1])
    assert first[2] == expected[2]
    with pytest.raises(ValueError):
        first[0][0, 0] = 99.0  # shared by every caller: nobody may change it


def test_blank_text_is_an_empty_shape() -> None:
    cubics, subpaths, closed = shape_arrays("  ")
    assert cubics.shape == (0, 4) and subpaths.shape == (0,) and closed == ()


def test_bad_path_data_raises_every_time() -> None:
    for _ in range(2):
        with pytest.raises(SvgError):
            shape_arrays("M0 0 Lx")
    assert "M0 0 Lx" not in shapes._cache


def test_cache_holds_a_bounded_number_of_segments(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(shapes, "CACHE_SEGMENTS", 10)
    monkeypatch.setattr(shapes, "_cache", type(shapes._cache)())
    monkeypatch.setattr(shapes, "_held", 0)
    for i in range(20):
        shape_arrays(f"M{i} 0 L{i + 1} 0 L{i + 1} 1")  # two segments each
    assert shapes._held <= 10
    assert sum(len(v[0]) for v in shapes._cache.values()) == shapes._held
    big = "M0 0 " + " ".join(f"L{i} {i % 2}" for i in range(1, 30))
    assert len(shape_arrays(big)[0]) > 10 and big not in shapes._cache


def test_the_last_large_shape_is_parsed_once(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(shapes, "CACHE_SEGMENTS", 10)
    monkeypatch.setattr(shapes, "_cache", type(shapes._cache)())
    monkeypatch.setattr(shapes, "_held", 0)
    monkeypatch.setattr(shapes, "_large", None)
    parsed: list[str] = []
    real = shapes.cubics_from_d
    monkeypatch.setattr(shapes, "cubics_from_d", lambda d: parsed.append(d) or real(d))
    big = "M0 0 " + " ".join(f"L{i} {i % 2}" for i in range(1, 30))
    other = "M0 0 " + " ".join(f"L{i} {i % 3}" for i in range(1, 30))
    first = shape_arrays(big)
    assert shape_arrays(big) is first and parsed == [big]
    shape_arrays(other)  # takes the slot: one large shape is held, not every one
    assert shape_arrays(big) is not first and parsed == [big, other, big]
    assert shapes._held == 0


def test_many_texts_parse_as_each_alone(monkeypatch: pytest.MonkeyPatch) -> None:
    """Absolute texts are parsed in one pass, the others one by one: the arrays are the same, bit for bit."""
    monkeypatch.setattr(shapes, "_cache", type(shapes._cache)())
    monkeypatch.setattr(shapes, "_held", 0)
    rng = np.random.default_rng(2)
    ds = []
    for _ in range(300):
        pts = rng.normal(0, 10 ** rng.uniform(-3, 6), (7, 2))
        d = f"M{pts[0, 0]:.17g} {pts[0, 1]:.17g} L{pts[1, 0]:.9g},{pts[1, 1]:.9g}"
        d += " C" + " ".join(f"{v:.9g}" for v in pts[2:5].ravel()) + (" Z" if rng.random() < 0.5 else "")
        d += (
            f" M{pts[5, 0]:.17g} {pts[5, 1]:.17g} L{pts[6, 0]:.17g} {pts[6, 1]:.17g}Z"
            if rng.random() < 0.3
            else ""
        )
        ds.append(d)
    ds += ["", " ", "M0 0 Lx", "m0.1 0.2 l1 1 h3z", "M1 1 L2 2 M3 3 L 4 4Z", "M1e3 2E-2L3 4", ds[0]]
    got = shapes.shapes_arrays(ds)
    for d, arrays in zip(ds, got, strict=True):
        if d == "M0 0 Lx":
            assert arrays is None
            continue
        expected = cubics_from_d(d) if d.strip() else (np.zeros((0, 4), complex), np.zeros(0, np.intp), ())
        assert arrays is not None and arrays[2] == expected[2]
        assert arrays[0].view(np.uint64).tolist() == expected[0].view(np.uint64).tolist()
        np.testing.assert_array_equal(arrays[1], expected[1])
        assert not arrays[0].flags.writeable and arrays[0].base is None  # owns its memory
        assert shape_arrays(d) is arrays  # cached
