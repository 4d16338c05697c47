"""Inference speed at scale: the whole `lsys infer` process on rotating grids of leaves.

Run with `make bench` (or directly).  One line per case: elements, wall seconds, CPU seconds
(user + system of the process and its threads: on a machine shared with other work the wall time
waits for cores, the CPU time much less), peak memory (largest resident set), worker jobs, cores seen, the growth exponent from the previous size, the load average when the
case started, and the per-stage seconds of the report.  The last lines compare 2 jobs with 1.

Environment: ``BENCH_SIZES`` (default ``1200,20000,50000,100000``), ``BENCH_REPEATS`` (median
over runs for sizes up to 5,000; default 3), ``BENCH_SPEEDUP_N`` (default 50000; 0 skips the
jobs comparison), ``BENCH_SPEEDUP_PAIRS`` (1-job and 2-job runs taken in turn for it, the
median ratio printed; default 3), ``BENCH_NICE`` (niceness of the measured process, default 5).  The number of
jobs is passed as ``LSYS_JOBS`` (default: the cores this process may use).
"""

from __future__ import annotations

import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from scenes import grid_dims, rotating_grid_svg, write

LSYS = [sys.executable, "-m", "lsys_core.cli"]


def cores() -> int:
    """Cores this process may run on (affinity), as the inference counts them."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


def run_once(svg: Path, tmp: Path, jobs: int) -> tuple[float, float, dict, float]:
    """Run ``lsys infer`` once; return wall seconds, peak MiB, the JSON report and CPU seconds.

    Peak memory and CPU time are the kernel's account of the finished process (``wait4``, as
    ``/usr/bin/time`` reports them): largest resident set, user + system seconds of all its
    threads.  Nothing watches the process while it runs: sampling its ``smaps_rollup`` every
    20 ms, as this benchmark did, took CPU from the run it measured, most from the one that
    used both cores (50,052 leaves, 3 alternating pairs: 2 jobs 9.43, 9.48, 9.22 s against
    1 job 11.87, 11.80 s with the sampler; see the closing figures of the change without it).
    """
    rep = tmp / "rep.json"
    env = {**os.environ, "LSYS_JOBS": str(jobs)}
    nice = int(os.environ.get("BENCH_NICE", "5"))
    cmd = [*LSYS, "-q", "infer", str(svg), "-o", str(tmp / "r.lsys"), "--report", str(rep)]
    t = time.perf_counter()
    p = subprocess.Popen(
        cmd,
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=(lambda: os.nice(nice)) if nice else None,
    )
    assert p.stderr is not None
    err = p.stderr.read()
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t
    p.returncode = os.waitstatus_to_exitcode(status)  # reaped here: Popen must not wait again
    if p.returncode:
        raise SystemExit(err)
    return wall, usage.ru_maxrss / 1024, json.loads(rep.read_text()), usage.ru_utime + usage.ru_stime


def case(svg: Path, tmp: Path, n: int, jobs: int, repeats: int) -> tuple[float, float, dict, float, float]:
    """Median wall seconds, peak MiB, first report, load average at the start, median CPU seconds."""
    load = os.getloadavg()[0]
    runs = [run_once(svg, tmp, jobs) for _ in range(repeats if n <= 5000 else 1)]
    return (
        statistics.median(r[0] for r in runs),
        max(r[1] for r in runs),
        runs[0][2],
        load,
        statistics.median(r[3] for r in runs),
    )


def line(n: int, sec: float, cpu: float, mib: float, jobs: int, expo: str, load: float, rep: dict) -> str:
    stages = " ".join(f"{k}={v:.2f}" for k, v in rep["stages"].items() if k != "reproduction_error")
    return (
        f"{n:>8} {sec:>8.2f} {cpu:>7.2f} {mib:>8.0f} {jobs:>4} {cores():>5} {expo:>8} {load:>5.1f} "
        f"{len(rep['rules']):>5}  {stages}"
    )


def main() -> None:
    sizes = [int(x) for x in os.environ.get("BENCH_SIZES", "1200,20000,50000,100000").split(",")]
    repeats = int(os.environ.get("BENCH_REPEATS", "3"))
    speed_n = int(os.environ.get("BENCH_SPEEDUP_N", "50000"))
    jobs = int(os.environ.get("LSYS_JOBS", "0")) or cores()
    print(f"inference at scale: whole `lsys infer` on a rotating grid of leaves, {cores()} cores seen")
    print(
        f"{'n':>8} {'seconds':>8} {'cpu s':>7} {'peak MiB':>8} {'jobs':>4} {'cores':>5} {'exponent':>8} {'load':>5} {'rules':>5}  stages (s)"
    )
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        svgs = {}
        prev: tuple[int, float] | None = None
        results: dict[int, float] = {}
        for n in sizes:
            rows, cols = grid_dims(n)
            svgs[n] = write(tmp / f"grid{n}.svg", rotating_grid_svg(rows, cols))
            sec, mib, rep, load, cpu = case(svgs[n], tmp, n, jobs, repeats)
            m = rows * cols
            expo = f"{math.log(sec / prev[1]) / math.log(m / prev[0]):.2f}" if prev else "-"
            print(line(m, sec, cpu, mib, jobs, expo, load, rep), flush=True)
            prev, results[m] = (m, sec), sec
        big = [m for m in results if m >= 20000]
        if len(big) >= 2:
            lo, hi = min(big), max(big)
            e = math.log(results[hi] / results[lo]) / math.log(hi / lo)
            print(f"growth exponent {lo} -> {hi}: {e:.2f}")
        if speed_n:
            rows, cols = grid_dims(speed_n)
            svg = svgs.get(speed_n) or write(tmp / f"grid{speed_n}.svg", rotating_grid_svg(rows, cols))
            m = rows * cols
            pairs = int(os.environ.get("BENCH_SPEEDUP_PAIRS", "3"))
            ratios = []
            for _ in range(pairs):  # in turn, so that a change of the machine's speed hits both
                one = case(svg, tmp, m, 1, 1)
                print(line(m, one[0], one[4], one[1], 1, "-", one[3], one[2]), flush=True)
                two = case(svg, tmp, m, 2, 1)
                print(line(m, two[0], two[4], two[1], 2, "-", two[3], two[2]), flush=True)
                ratios.append(one[0] / two[0])
            print(
                f"speed-up at {m}, 2 jobs vs 1: {statistics.median(ratios):.2f}x "
                f"(median of {pairs} alternating pairs, {min(ratios):.2f}-{max(ratios):.2f})"
            )


if __name__ == "__main__":
    main()
