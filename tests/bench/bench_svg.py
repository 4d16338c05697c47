"""Print SVG import and export times for 10,000 simple paths (not a test).

Run: ``PYTHONPATH=. .venv/bin/python tests/bench/bench_svg.py``
"""

from __future__ import annotations

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


if __name__ == "__main__":
    main()
