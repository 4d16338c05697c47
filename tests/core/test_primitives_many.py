"""The bulk shape test (primitives_many) gives the full test's answers, and rejects in bulk."""

from __future__ import annotations

import math
from collections import OrderedDict

import numpy as np
import pytest

from lsys_core.geometry import shapes
from lsys_core.geometry.paths import cubics_from_d, d_from_cubics
from lsys_core.render import primitives_many
from lsys_core.render.primitives import TOLERANCE, primitive_of
from lsys_core.render.primitives_many import primitives


def _ellipse(rng, n_arcs: int, noise: float, round_: bool) -> str:
    """An ellipse (or circle) of ``n_arcs`` cubic arcs with control points moved by ``noise``."""
    rx = rng.uniform(0.5, 50)
    ry = rx if round_ else rx * rng.uniform(0.2, 0.95)
    centre = complex(*rng.uniform(-100, 100, 2)) if rng.random() < 0.7 else 0j
    turn = complex(np.exp(1j * rng.uniform(0, math.pi)))
    k = 4 / 3 * math.tan(math.pi / (2 * n_arcs))
    theta = np.linspace(0, 2 * math.pi, n_arcs + 1) + rng.uniform(0, 1)
    unit = np.exp(1j * theta)
    p0, p3 = unit[:-1], unit[1:]
    rows = np.stack([p0, p0 + 1j * k * p0, p3 - 1j * k * p3, p3], axis=1)
    cubics = (rows.real * rx + 1j * rows.imag * ry) * turn + centre
    cubics = cubics + noise * 2 * (rx + ry) * (
        rng.normal(size=cubics.shape) + 1j * rng.normal(size=cubics.shape)
    )
    cubics[1:, 0] = cubics[:-1, 3]
    cubics[-1, 3] = cubics[0, 0]
    return d_from_cubics(cubics, None, (True,))


def _polygon(rng, noise: float, rounded: bool) -> str:
    """A (turned, maybe rounded) rectangle with its corners moved by ``noise``."""
    w, h = rng.uniform(1, 80, 2).tolist()
    turn = complex(np.exp(1j * rng.choice([0.0, rng.uniform(0, math.pi)])))
    corners = np.array([0, w, w + 1j * h, 1j * h]) + noise * (w + h) * rng.normal(size=4)
    if not rounded:
        pts = (corners + complex(*rng.uniform(-50, 50, 2))) * turn
        return "M" + " L".join(f"{z.real:.17g} {z.imag:.17g}" for z in pts) + " Z"
    r = float(rng.uniform(0.05, 0.5)) * min(w, h)
    d = ""
    for i in range(4):
        a, b, c = corners[i - 1], corners[i], corners[(i + 1) % 4]
        start, end = b + (a - b) / abs(a - b) * r, b + (c - b) / abs(c - b) * r
        s, e = start * turn, end * turn
        d += f"{'M' if not d else 'L'}{s.real:.17g} {s.imag:.17g} A{r!r} {r!r} 0 0 1 {e.real:.17g} {e.imag:.17g} "
    return d + "Z"


def _line(rng, noise: float) -> str:
    p, q = complex(*rng.uniform(-50, 50, 2)), complex(*rng.uniform(-50, 50, 2))
    c1, c2 = p + (q - p) / 3, p + 2 * (q - p) / 3
    off = noise * abs(q - p) * complex(rng.normal(), rng.normal())
    if rng.random() < 0.5:
        c1 += off
    else:
        c2 += off
    return f"M{p.real!r} {p.imag!r} C{c1.real!r} {c1.imag!r} {c2.real!r} {c2.imag!r} {q.real!r} {q.imag!r}"


def _leaf(rng) -> str:
    x, y = rng.uniform(0, 1000, 2)
    a, b = rng.uniform(2, 10, 2)
    return f"M{x:.3f},{y:.3f} c{a},-{b} 16,-5 22,0 c-7,3 -16,{b} -22,0 z"


def _cases(seed: int) -> list[str]:
    rng = np.random.default_rng(seed)
    # noise around the tolerance: some shapes pass, some fail, a few lie near the threshold
    noise = lambda: TOLERANCE * 10 ** rng.uniform(-3, 0.7)  # noqa: E731
    ds = []
    for _ in range(60):
        ds.append(_ellipse(rng, int(rng.integers(2, 9)), noise(), round_=rng.random() < 0.5))
        ds.append(_polygon(rng, 10 ** rng.uniform(-9, -4), rounded=rng.random() < 0.4))  # right angles: 1e-6
        ds.append(_line(rng, 10 ** rng.uniform(-6, -1.5)))
        ds.append(_leaf(rng))
    ds += ["", "M0 0 L1 0 M5 5 L6 5", "M0 0 L10 0 L10 5 L0 5", "M0 0 Lx", "M0 0 C1 1 2 1 3 0 Z", "M1 1 L1 1"]
    return ds


def _full(d: str):
    try:
        cubics, _, closed = cubics_from_d(d) if d.strip() else (np.zeros((0, 4), complex), None, ())
    except Exception:
        return None
    return primitive_of(cubics, closed)


@pytest.mark.parametrize("seed,block", [(0, 1 << 14), (1, 1 << 14), (2, 7)])
def test_bulk_answers_are_the_full_tests(monkeypatch: pytest.MonkeyPatch, seed: int, block: int) -> None:
    monkeypatch.setattr(primitives_many, "_BLOCK", block)  # 7: many blocks, paths across their ends
    ds = _cases(seed)
    expected = [_full(d) for d in ds]
    monkeypatch.setattr(shapes, "_cache", OrderedDict())  # parse anew, in one pass
    monkeypatch.setattr(shapes, "_held", 0)
    assert primitives(ds) == expected
    tags = {e[0] for e in expected if e is not None}
    assert tags == {"circle", "ellipse", "rect", "line"}  # the cases reach every kind …
    assert sum(e is None for e in expected) > len(ds) // 4  # … and many are none


def test_leaves_are_rejected_without_the_full_test(monkeypatch: pytest.MonkeyPatch) -> None:
    rng = np.random.default_rng(5)
    ds = [_leaf(rng) for _ in range(200)]
    calls = []
    monkeypatch.setattr(primitives_many, "primitive_of", lambda *a: calls.append(a))
    assert primitives(ds) == [None] * len(ds)
    assert not calls


def test_answers_at_the_straightness_thresholds() -> None:
    """Lines whose ends leave the chord at about the largest angle, or as far off as allowed."""
    ds = []
    for e in [0.0] + [s * 10.0**-k for k in range(1, 16) for s in (1, -1)]:
        turn = complex(np.exp(1j * 1e-3 * (1 + e)))
        for length in (30.0, 0.37, 1234.5):
            c1 = length / 3 * turn
            ds.append(f"M0 0 C{c1.real!r} {c1.imag!r} {2 * length / 3!r} 0 {length!r} 0")
            size = length * (1 + 1e-3 * (1 + e))  # the control point leaves the chord towards +y
            far = complex(length * 0.999, 1e-3 * size * (1 + e))  # as far off as the tolerance
            ds.append(f"M0 0 C{far.real!r} {far.imag!r} {far.real!r} {far.imag!r} {length!r} 0")
    expected = [_full(d) for d in ds]
    assert primitives(ds) == expected
    assert 0 < sum(e is None for e in expected) < len(ds)
