"""Path data compacted many texts at once reads as each text compacted alone."""

from __future__ import annotations

from collections import OrderedDict

import numpy as np
import pytest

from lsys_core.geometry import shapes
from lsys_core.render.compact import compact_path_data, compact_paths


def test_many_at_once_as_one_by_one(monkeypatch: pytest.MonkeyPatch) -> None:
    rng = np.random.default_rng(3)
    ds = []
    for _ in range(300):
        scale = 10 ** rng.uniform(-4, 7)
        pts = rng.normal(0, scale, (7, 2))
        ds.append(
            f"M{pts[0, 0]:.17g} {pts[0, 1]:.17g} L{pts[1, 0]:.9g},{pts[1, 1]:.9g} C"
            + " ".join(f"{v:.17g}" for v in pts[2:5].ravel())
            + " Z"
        )
    ds += [
        "",
        "M0 0",
        "M0 0 Lx",
        "M0 0 A1 1 0 0 1 2 0",
        "m1 1 l2 -0 h3z",
        "M-0.0000001 0 L1e-9 1",
        "M1\0 2 L3 4",
    ]
    ds.append("M0 0 " + " ".join(f"L{i}.1234567 {i % 7}" for i in range(400)))  # longer than a block
    expected = [compact_path_data(d) for d in ds]
    monkeypatch.setattr(shapes, "_cache", OrderedDict())
    monkeypatch.setattr(shapes, "_held", 0)
    assert compact_paths(ds, block=1000) == expected
    assert compact_paths(ds) == expected
