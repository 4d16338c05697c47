"""Print timings of similarity detection on synthetic scenes.

Run from the repository root::

    PYTHONPATH=. .venv/bin/python tests/bench/bench_similarity.py

Scenes: copies of one leaf (exact control points: the closed-form path), the same leaf
redrawn (split curves, reversed, other start point: the vote + ICP path), and a mix of
four shapes with mirror images and jitter.
"""

from __future__ import annotations

import time
from itertools import pairwise

import numpy as np

from lsys_core.instancing.similarity import detect_similarity
from lsys_core.svg.model import Element, Scene

REPEAT = 3
STYLE = "fill:none;stroke:#1b5e20;stroke-width:1"
LEAF = np.array(
    [
        [0, 4 - 1.5j, 11.5 - 3j, 19.25 - 3.375j],
        [19.25 - 3.375j, 27 - 3.75j, 35 - 3j, 40],
        [40, 35 + 2j, 28.5 + 3.25j, 21.5 + 3.375j],
        [21.5 + 3.375j, 14.5 + 3.5j, 7 + 2.5j, 0],
    ]
)


def _lines(points) -> np.ndarray:
    p = [*points, points[0]]
    return np.array([[p0, p0 + (p3 - p0) / 3, p0 + 2 * (p3 - p0) / 3, p3] for p0, p3 in pairwise(p)])


def _split(c: np.ndarray) -> np.ndarray:
    p0, p1, p2, p3 = c.T
    a, b, cc = (p0 + p1) / 2, (p1 + p2) / 2, (p2 + p3) / 2
    d, e = (a + b) / 2, (b + cc) / 2
    f = (d + e) / 2
    out = np.empty((2 * len(c), 4), complex)
    out[0::2] = np.column_stack([p0, a, d, f])
    out[1::2] = np.column_stack([f, e, cc, p3])
    return out


SHAPES = [
    LEAF,
    _lines([0, 16, 16 - 4j, 24 + 2j, 16 + 8j, 16 + 4j, 4j]),  # arrow
    _lines([0, 14, 3 + 9j]),  # triangle
    _lines([0, 10, 14 + 6j, 3 + 9j]),  # kite
]


def _el(cubics) -> Element:
    return Element(cubics, np.zeros(len(cubics), int), (True,), STYLE)


def scene_exact(n: int, rng) -> Scene:
    """Return ``n`` leaves under random similarities, control points kept."""
    a = rng.uniform(0.5, 2, n) * np.exp(1j * rng.uniform(-np.pi, np.pi, n))
    b = rng.uniform(0, 1000, n) + 1j * rng.uniform(0, 1000, n)
    return Scene(tuple(_el(a[i] * LEAF + b[i]) for i in range(n)))


def scene_redrawn(n: int, rng) -> Scene:
    """Return ``n`` leaves, each redrawn (split, reversed, restarted) under random similarities."""
    a = rng.uniform(0.5, 2, n) * np.exp(1j * rng.uniform(-np.pi, np.pi, n))
    b = rng.uniform(0, 1000, n) + 1j * rng.uniform(0, 1000, n)
    variants = [_split(LEAF), LEAF[::-1, ::-1], _split(np.roll(LEAF, 1, axis=0))[::-1, ::-1]]
    els = [_el(LEAF)] + [_el(a[i] * variants[i % 3] + b[i]) for i in range(1, n)]
    return Scene(tuple(els))


def scene_mixed(n: int, rng) -> Scene:
    """Return ``n`` elements of four shapes, a quarter mirrored, a third redrawn, coordinates rounded."""
    a = rng.uniform(0.5, 2, n) * np.exp(1j * rng.uniform(-np.pi, np.pi, n))
    b = rng.uniform(0, 1000, n) + 1j * rng.uniform(0, 1000, n)
    els = []
    for i in range(n):
        shape = SHAPES[i % len(SHAPES)]
        if (i // len(SHAPES)) % 4 == 1:
            shape = np.conj(shape)
        if i % 3 == 2:
            shape = _split(shape)
        els.append(_el(np.round(a[i] * shape + b[i], 4)))
    return Scene(tuple(els))


def main() -> None:
    rng = np.random.default_rng(0)
    detect_similarity(scene_exact(50, rng))  # warm up imports and caches
    print(f"{'scene':10s} {'elements':>9s} {'groups':>7s} {'seconds':>8s}  (best of {REPEAT})")
    for name, make, sizes in (
        ("exact", scene_exact, (300, 1200, 5000)),
        ("redrawn", scene_redrawn, (300, 1200, 5000)),
        ("mixed", scene_mixed, (300, 1200, 5000, 10000)),
    ):
        for n in sizes:
            scene = make(n, rng)
            best = float("inf")
            for _ in range(REPEAT if n <= 5000 else 1):
                t0 = time.perf_counter()
                inst = detect_similarity(scene)
                best = min(best, time.perf_counter() - t0)
            print(f"{name:10s} {n:9d} {len(inst.terminals):7d} {best:8.3f}")


if __name__ == "__main__":
    main()
