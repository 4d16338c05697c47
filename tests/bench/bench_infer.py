"""Inference speed: whole `lsys infer` process and per-stage times, with a scaling table.

Run with `make bench` (or directly).  Prints medians over several runs, the machine's core
count, and the peak memory of the process.
"""

from __future__ import annotations

import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from scenes import grid_dims, rotating_grid_svg, write

LSYS = [sys.executable, "-m", "lsys_core.cli"]


def run_once(svg: Path, tmp: Path) -> tuple[float, dict, float]:
    rep = tmp / "rep.json"
    t = time.perf_counter()
    p = subprocess.run(
        [*LSYS, "infer", str(svg), "-o", str(tmp / "r.lsys"), "--report", str(rep)],
        capture_output=True,
        text=True,
    )
    wall = time.perf_counter() - t
    if p.returncode:
        raise SystemExit(p.stderr)
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
    return wall, json.loads(rep.read_text()), peak


def main() -> None:
    sizes = [int(x) for x in os.environ.get("BENCH_SIZES", "300,1200,5000,20000").split(",")]
    repeats = int(os.environ.get("BENCH_REPEATS", "3"))
    print(f"inference benchmark: rotating grid, {os.cpu_count()} cores, median of {repeats} runs")
    print(f"{'elements':>9} {'process s':>10} {'peak MiB':>9} {'rules':>6}  stages (s)")
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        for n in sizes:
            rows, cols = grid_dims(n)
            svg = write(tmp / f"grid{n}.svg", rotating_grid_svg(rows, cols))
            runs = [run_once(svg, tmp) for _ in range(repeats if n <= 5000 else 1)]
            wall = statistics.median(r[0] for r in runs)
            rep = runs[0][1]
            stages = " ".join(f"{k}={v:.3f}" for k, v in rep["stages"].items() if k != "reproduction_error")
            print(
                f"{rows * cols:>9} {wall:>10.2f} {max(r[2] for r in runs):>9.0f} {len(rep['rules']):>6}  {stages}",
                flush=True,
            )


if __name__ == "__main__":
    main()
