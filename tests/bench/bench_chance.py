"""Chance coincidences: copies of one shape at random places must not become rules (issue #13).

Run with `make bench` (or directly).  Whole `lsys infer` processes on (1) 3,000 copies of one
triangle in one pose at random places, whose offsets coincide by chance (target: at most 3
productions, at most 3 s on 2 cores), and (2) 20 copies at random angles (target: no rule
claims a rotation sequence), and (3) distinct blobs at random places, a map (nothing to group or
repeat: the time shows what the similarity search costs when every candidate fails).  Prints
productions, repetition rules found, seconds and the load.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from scenes import blobs_svg, scattered_svg, write

LSYS = [sys.executable, "-m", "lsys_core.cli"]


def run(svg: Path, out: Path) -> tuple[float, dict]:
    """Infer ``svg`` in a new process; return wall seconds and the JSON report."""
    report = out.with_suffix(".json")
    t0 = time.perf_counter()
    subprocess.run([*LSYS, "infer", str(svg), "-o", str(out), "--report", str(report)], check=True)
    return time.perf_counter() - t0, json.loads(report.read_text(encoding="utf-8"))


def main() -> int:
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        for n, turn, target in ((3000, False, "≤ 3 productions, ≤ 3 s"), (20, True, "no rotation sequence")):
            svg = write(work / f"scattered-{n}.svg", scattered_svg(n, turn=turn))
            load = os.getloadavg()[0]
            seconds, report = run(svg, work / f"scattered-{n}.lsys")
            grammar = (work / f"scattered-{n}.lsys").read_text(encoding="utf-8")
            productions = sum(1 for line in grammar.splitlines() if "->" in line)
            sequences = [line for line in report.get("log", []) if "lengths" in line]
            print(
                f"{n:>5,} copies at random {'angles' if turn else 'places'}: {productions} productions, "
                f"{len(sequences)} sequence rules, explained {report.get('explained', 0):.0%}, "
                f"{seconds:.2f} s (load {load:.1f}; target {target})",
                flush=True,
            )
        for n in (100, 250):
            svg = write(work / f"blobs-{n}.svg", blobs_svg(n))
            load = os.getloadavg()[0]
            seconds, report = run(svg, work / f"blobs-{n}.lsys")
            stages = report.get("stages", {})
            print(
                f"{n:>5,} distinct blobs: {report.get('explained', 0):.0%} explained, {seconds:.2f} s "
                f"(similarity {stages.get('similarity', 0):.2f} s; load {load:.1f})",
                flush=True,
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
