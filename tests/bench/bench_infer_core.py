"""Inference without SVG reading: analysis, rules, and re-weighting from a kept analysis.

Run with `make bench` (or directly).  The rotating grid of leaves of ``bench_infer.py`` is
built in memory (no SVG import), then, per size and number of jobs: seconds of
``analyse`` (similarity, instancing, pivots), of the first ``rules_from_analysis`` (which
clusters every level), and of a re-weighting (other weights, same analysis), with the CPU
seconds of the process and the load average.  ``BENCH_SIZES`` (default
``1200,20000,50000,100000``) and ``BENCH_JOBS`` (default ``1,2``) choose the cases.
"""

# ruff: noqa: E402  (numpy is imported after prefer_fast_sort)
from __future__ import annotations

import math
import os
import sys
import time
from pathlib import Path

from lsys_core.cpu import prefer_fast_sort, prefer_small_pages

prefer_fast_sort()  # as the lsys command and the editor do, before numpy is imported
prefer_small_pages()
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from scenes import grid_dims

from lsys_core import parallel
from lsys_core.hierarchy.rules import Weights
from lsys_core.pipeline import analyse, rules_from_analysis
from lsys_core.svg.model import Element, Scene

#: The leaf of ``scenes.rotating_grid_svg`` (two quadratic curves) as cubics.
_Q = [(0, 5 - 8j, 14 - 2j), (14 - 2j, 9 + 2j, 0)]
LEAF = np.array([[p0, p0 + 2 / 3 * (c - p0), p1 + 2 / 3 * (c - p1), p1] for p0, c, p1 in _Q], complex)


def rotating_grid(n: int) -> Scene:
    """About ``n`` leaves on a grid, turning 12° more per column (as the SVG benchmark draws them)."""
    rows, cols = grid_dims(n)
    r, c = np.divmod(np.arange(rows * cols), cols)
    a = np.exp(1j * np.deg2rad(12.0 * c))
    b = 20 + 40.0 * c + 1j * (20 + 40.0 * r)
    style = "fill:none;stroke:#1b5e20"
    sub = np.zeros(len(LEAF), int)
    return Scene(tuple(Element(ai * LEAF + bi, sub, (True,), style) for ai, bi in zip(a, b, strict=True)))


def main() -> None:
    sizes = [int(x) for x in os.environ.get("BENCH_SIZES", "1200,20000,50000,100000").split(",")]
    jobs = [int(x) for x in os.environ.get("BENCH_JOBS", "1,2").split(",")]
    print(f"inference in process (no SVG reading), {parallel.available_cores()} cores seen")
    print(
        f"{'n':>8} {'jobs':>4} {'analyse':>8} {'rules':>8} {'total':>8} {'cpu':>8} {'reweight':>9} {'load':>5}"
    )
    prev: dict[int, tuple[int, float]] = {}
    for n in sizes:
        scene = rotating_grid(n)
        for j in jobs:
            parallel.set_jobs(j)
            load = os.getloadavg()[0]
            c0, t0 = time.process_time(), time.perf_counter()
            analysis = analyse(scene)
            t1 = time.perf_counter()
            rules_from_analysis(analysis)
            t2 = time.perf_counter()
            cpu = time.process_time() - c0
            rules_from_analysis(analysis, Weights(0.6, 0.8, 0.3, 0.5))
            t3 = time.perf_counter()
            expo = ""
            if j in prev:
                m0, s0 = prev[j]
                expo = f"  exponent {math.log((t2 - t0) / s0) / math.log(len(scene.elements) / m0):.2f}"
            prev[j] = (len(scene.elements), t2 - t0)
            print(
                f"{len(scene.elements):>8} {j:>4} {t1 - t0:>8.2f} {t2 - t1:>8.2f} {t2 - t0:>8.2f} {cpu:>8.2f} "
                f"{t3 - t2:>9.2f} {load:>5.1f}{expo}",
                flush=True,
            )
    parallel.set_jobs(None)


if __name__ == "__main__":
    main()
