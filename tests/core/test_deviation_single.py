"""A shape drawn by one element is that element: its deviation is 0 and nothing is sampled for it."""

from __future__ import annotations

import numpy as np

from lsys_core.instancing import deviation
from lsys_core.svg.parse import parse_svg


def test_singletons_are_not_measured(monkeypatch):
    scene = parse_svg(
        b'<svg xmlns="http://www.w3.org/2000/svg"><path d="M0 0 L4 0 L4 1 Z"/>'
        b'<path d="M10 0 L14 0 L14 1.2 Z"/><path d="M0 9 C1 5 3 5 4 9 Z"/></svg>'
    )
    els = list(scene.elements)
    shapes = [els[0], els[2]]
    which = np.array([0, 0, 1])
    a = np.ones(3, complex)
    b = np.array([0, 10, 0], complex)
    sampled = []
    real = deviation.sample_elements
    monkeypatch.setattr(deviation, "sample_elements", lambda e, f: sampled.append(len(e)) or real(e, f))
    out = deviation.pose_deviations(els, shapes, which, a, b)
    assert sampled == [2]  # only the two elements that share shape 0
    assert out[2] == 0.0 and out[0] < 1e-9 and 0.19 < out[1] < 0.21
