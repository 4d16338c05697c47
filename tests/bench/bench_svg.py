"""Print SVG import and export times for 10,000 simple paths, and path-data reading of 10^6 commands (not a test).

Run: ``PYTHONPATH=. .venv/bin/python tests/bench/bench_svg.py``
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from lsys_core.derive.model import Drawing
from lsys_core.geometry import d_from_cubics
from lsys_core.grammar.model import Terminal
from lsys_core.render import export_svg
from lsys_core.svg import load_svg


def write_paths(path: Path, n: int, seed: int = 0) -> None:
    """Write an SVG with ``n`` small closed leaf paths, a third of them in transformed groups."""
    rng = np.random.default_rng(seed)
    xy = rng.uniform(0, 1000, (n, 2))
    parts = ['<svg xmlns="http://www.w3.org/2000/svg" width="1000" height="1000" viewBox="0 0 1000 1000">']
    for i, (x, y) in enumerate(xy.tolist()):
        d = f"M{x:.3f},{y:.3f} c6,-6 16,-5 22,0 c-7,3 -16,6 -22,0 z"
        if i % 3 == 0:
            rotate = f"rotate({i % 360} {x:.3f} {y:.3f})"
            parts.append(f'<g transform="{rotate}"><path id="p{i}" fill="#2e7d32" d="{d}"/></g>')
        else:
            parts.append(f'<path id="p{i}" fill="none" stroke="#1b5e20" stroke-width="1" d="{d}"/>')
    parts.append("</svg>")
    path.write_text("\n".join(parts))


def main(n: int = 10_000) -> None:
    """Print the import time, then the export time of the imported elements as a drawing."""
    with tempfile.TemporaryDirectory() as tmp:
        src = Path(tmp) / "paths.svg"
        write_paths(src, n)
        t = time.perf_counter()
        scene = load_svg(src)
        t_import = time.perf_counter() - t
        terminals = tuple(
            Terminal(f"T{i}", d_from_cubics(e.cubics, e.subpaths, e.closed), e.style)
            for i, e in enumerate(scene.elements)
        )
        k = len(terminals)
        drawing = Drawing(
            terminals=terminals,
            symbol=np.arange(k, dtype=np.int32),
            a=np.ones(k, complex),
            b=np.zeros(k, complex),
            rule=np.full(k, -1, np.int32),
            viewbox=scene.viewbox,
            size=scene.size,
        )
        t = time.perf_counter()
        export_svg(drawing, Path(tmp) / "out.svg")
        t_export = time.perf_counter() - t
    print(f"import {n} paths: {t_import * 1000:.0f} ms ({len(scene.elements)} elements)")
    print(f"export {k} instances: {t_export * 1000:.0f} ms")


_PATH_DATA_CHILD = """
import resource, sys, time
from lsys_core.geometry.paths import cubics_from_d
n, kind = int(sys.argv[1]), sys.argv[2]
if kind == "L":
    d = "M0 0 " + " ".join(f"L{i % 1000}.5 {i // 1000}" for i in range(n))
else:
    d = "M0 0 " + " ".join(f"A5 3 {i % 90} {i % 2} 1 {i % 1000}.5 {i // 1000}" for i in range(n))
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
t = time.perf_counter()
cubics, _, _ = cubics_from_d(d)
dt = time.perf_counter() - t
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print(f"{dt:.2f} s, peak {peak / 1024:.0f} MiB (text and interpreter: {before / 1024:.0f} MiB), {len(cubics):,} cubics")
"""


def path_data(n: int = 1_000_000) -> None:
    """Print the time and peak memory of reading path data of ``n`` line and ``n`` arc commands."""
    for kind, label in (("L", "line"), ("A", "arc")):
        out = subprocess.run(
            [sys.executable, "-c", _PATH_DATA_CHILD, str(n), kind], capture_output=True, text=True, check=True
        )
        print(f"path data of {n:,} {label} commands: {out.stdout.strip()}")


if __name__ == "__main__":
    main()
    path_data()
