"""Print the time to render 10,000 and 100,000 small leaf-like paths at 1600×1200 (not a test).

Two scenes: leaves and stems scattered at random (overlapping, random scales: full mode draws
them one by one) and leaves in rows, side by side without overlapping (full mode batches them).

Run: ``PYTHONPATH=. .venv/bin/python tests/bench/bench_render.py``
"""

from __future__ import annotations

import statistics
import time

import numpy as np

from lsys_core.derive.model import Drawing
from lsys_core.grammar.model import Terminal
from lsys_core.render.raster import Renderer

WIDTH, HEIGHT = 1600, 1200
LEAF = Terminal("A", "M0 0 C6 -6 16 -5 22 0 C15 3 6 6 0 0 Z", "fill:#2e7d32;stroke:#1b5e20;stroke-width:0.5")
STEM = Terminal("B", "M0 0 L10 0", "fill:none;stroke:#5d4037;stroke-width:1")


def make_drawing(n: int, seed: int = 0) -> Drawing:
    """Return ``n`` leaves and stems scattered over the canvas with random poses."""
    rng = np.random.default_rng(seed)
    a = rng.uniform(0.3, 1.2, n) * np.exp(1j * rng.uniform(0, 2 * np.pi, n))
    b = rng.uniform(0, WIDTH, n) + 1j * rng.uniform(0, HEIGHT, n)
    symbol = (rng.random(n) < 0.25).astype(np.int32)
    return Drawing(
        terminals=(LEAF, STEM),
        symbol=symbol,
        a=a,
        b=b,
        rule=np.zeros(n, np.int32),
        viewbox=(0.0, 0.0, float(WIDTH), float(HEIGHT)),
    )


def make_rows(n: int) -> Drawing:
    """Return ``n`` leaves in rows across the canvas, each turned a little, none overlapping."""
    cols = round(np.sqrt(n * WIDTH / HEIGHT))
    step = WIDTH / cols
    k = np.arange(n)
    a = (step / 26.0) * np.exp(1j * np.radians(0.1 * (k % cols)))
    b = (k % cols) * step + 1j * (k // cols) * step * 0.6
    return Drawing(
        terminals=(LEAF,),
        symbol=np.zeros(n, np.int32),
        a=a,
        b=b,
        rule=np.zeros(n, np.int32),
        viewbox=(0.0, -step, float(WIDTH), float(b.imag.max() + 2 * step)),
    )


def median_time(fn, runs: int) -> float:
    """Return the median wall time of ``runs`` calls of ``fn``."""
    times = []
    for _ in range(runs):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def main() -> None:
    """Print render times in full and draft mode."""
    renderer = Renderer(WIDTH, HEIGHT)
    for scene, make in (("scattered", make_drawing), ("rows", make_rows)):
        for n in (10_000, 100_000):
            drawing = make(n)
            renderer.draw(drawing)  # warm the terminal cache
            runs = 5 if n <= 10_000 else 3
            full = median_time(lambda d=drawing: renderer.draw(d, antialias=True), runs)
            draft = median_time(lambda d=drawing: renderer.draw(d, draft=True), runs)
            print(
                f"{scene:>9} {n:>7} instances at {WIDTH}x{HEIGHT}: "
                f"full {full * 1000:8.1f} ms   draft {draft * 1000:8.1f} ms",
                flush=True,
            )


if __name__ == "__main__":
    main()
