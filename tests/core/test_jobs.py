"""The number of workers never changes the result: rules and derived drawing for 1 and 2 jobs."""

from __future__ import annotations

import itertools
import os
import subprocess
import sys

import numpy as np
import pytest

from lsys_core import parallel
from lsys_core.derive.derivation import derive
from lsys_core.errors import LsysError
from lsys_core.grammar import format_grammar
from lsys_core.pipeline import infer

from .scenes import LEAF, place, pose, scene
from .shared import ROOT


def _rotating_grid(rows: int, cols: int):
    """A grid of leaves whose rotation grows 12° per column: several similarity chunks, linear rows."""
    frames = [pose(40.0 * c, 40.0 * r, 12.0 * c) for r in range(rows) for c in range(cols)]
    return scene(place(LEAF, frames))


@pytest.fixture
def restore_jobs():
    yield
    parallel.set_jobs(None)


def test_rules_and_drawing_are_the_same_for_one_and_two_jobs(restore_jobs) -> None:
    grid = _rotating_grid(30, 44)  # 1,320 elements: two chunks of candidates per representative
    out = {}
    for n in (1, 2):
        parallel.set_jobs(n)
        assert parallel.jobs() == n
        result = infer(grid)
        out[n] = (format_grammar(result.grammar), derive(result.grammar), result.log)
    (g1, d1, log1), (g2, d2, log2) = out[1], out[2]
    assert g1 == g2 and log1 == log2
    assert np.array_equal(d1.symbol, d2.symbol)
    assert np.array_equal(d1.a, d2.a) and np.array_equal(d1.b, d2.b)
    assert d1.symbol.size == 30 * 44


def test_pmap_keeps_order_and_raises_the_workers_errors(restore_jobs) -> None:
    parallel.set_jobs(3)
    assert parallel.pmap(lambda x: x * x, range(10)) == [x * x for x in range(10)]

    def fail(x: int) -> int:
        if x == 3:
            raise ValueError("three")
        return x

    with pytest.raises(ValueError, match="three"):
        parallel.pmap(fail, range(6))
    with pytest.raises(ValueError, match="three"):
        parallel.submit(fail, 3).result()
    assert parallel.submit(fail, 2).result() == 2


def test_nested_work_never_computes_on_more_threads_than_jobs(restore_jobs) -> None:
    """pmap inside pmap inside submit: every result, and at most jobs() tasks running at once."""
    import threading
    import time

    parallel.set_jobs(2)
    lock = threading.Lock()
    running, most = [0], [0]

    def leaf(x: int) -> int:
        with lock:
            running[0] += 1
            most[0] = max(most[0], running[0])
        time.sleep(0.01)  # long enough for the others to start if nothing held them back
        with lock:
            running[0] -= 1
        return x * x

    def middle(x: int) -> list[int]:
        return parallel.pmap(leaf, range(x, x + 4))

    def outer() -> list[list[int]]:
        return parallel.pmap(middle, range(0, 12, 4))

    beside = parallel.submit(outer)
    here = parallel.pmap(middle, range(100, 112, 4))
    assert beside.result() == [[x * x for x in range(k, k + 4)] for k in range(0, 12, 4)]
    assert here == [[x * x for x in range(k, k + 4)] for k in range(100, 112, 4)]
    assert 1 <= most[0] <= 2


def test_jobs_follow_the_environment_and_reject_nonsense(monkeypatch, restore_jobs) -> None:
    parallel.set_jobs(None)
    monkeypatch.setenv("LSYS_JOBS", "3")
    assert parallel.jobs() == 3
    monkeypatch.delenv("LSYS_JOBS")
    assert parallel.jobs() == parallel.available_cores() >= 1
    for bad in ("0", "-2", "two", "100000"):
        with pytest.raises(LsysError):
            parallel.set_jobs(bad)
    monkeypatch.setenv("LSYS_JOBS", "lots")
    with pytest.raises(LsysError, match="LSYS_JOBS"):
        parallel.jobs()


def test_cli_jobs_option_and_variable(tmp_path) -> None:
    svg = ROOT / "resources" / "examples" / "helix.svg"
    env = {**os.environ, "LSYS_JOBS": "1"}
    cmd = [sys.executable, "-m", "lsys_core.cli", "infer", str(svg)]
    one = subprocess.run([*cmd, "--jobs", "1"], capture_output=True, text=True, timeout=300, env=env)
    two = subprocess.run([*cmd, "--jobs", "2"], capture_output=True, text=True, timeout=300, env=env)
    assert one.returncode == 0 and one.stdout == two.stdout
    bad = subprocess.run([*cmd, "--jobs", "0"], capture_output=True, text=True, timeout=300, env=env)
    assert bad.returncode != 0 and bad.stderr.count("\n") == 1 and "--jobs" in bad.stderr
    env["LSYS_JOBS"] = "many"
    bad = subprocess.run(cmd, capture_output=True, text=True, timeout=300, env=env)
    assert bad.returncode != 0 and bad.stderr.count("\n") == 1 and "LSYS_JOBS" in bad.stderr


def test_linear_sequences_taking_turns_give_the_same_rules(restore_jobs, monkeypatch) -> None:
    from lsys_core.hierarchy import analysis

    grid = _rotating_grid(6, 9)
    parallel.set_jobs(2)
    monkeypatch.setattr(analysis, "BESIDE_MIN_PAIRS", 0)  # as a scene of 10^4 pairs and more does
    beside = format_grammar(infer(grid).grammar)
    monkeypatch.setattr(analysis, "BESIDE_PAIRS", 0)  # as a scene of millions of pairs does
    assert format_grammar(infer(grid).grammar) == beside


def test_small_levels_start_no_threads_beside_and_give_the_same_rules(restore_jobs, monkeypatch) -> None:
    """Below LEDGER_BESIDE nodes and BESIDE_MIN_PAIRS pairs a level's parts run one after another."""
    from lsys_core.hierarchy import analysis, rules

    started: list[str] = []

    def counting(module):
        def submit(fn, *args):
            started.append(fn.__name__)
            return parallel.submit(fn, *args)

        monkeypatch.setattr(module, "submit", submit)

    counting(analysis)
    counting(rules)
    grid = _rotating_grid(6, 9)
    parallel.set_jobs(2)
    alone = format_grammar(infer(grid).grammar)
    assert started == []
    monkeypatch.setattr(analysis, "BESIDE_MIN_PAIRS", 0)
    monkeypatch.setattr(rules, "LEDGER_BESIDE", 0)
    assert format_grammar(infer(grid).grammar) == alone
    assert "Ledger" in started and "linear_candidates" in started


def test_step_clusters_solved_in_parts_and_batches_give_the_same_rules(restore_jobs, monkeypatch) -> None:
    from lsys_core.hierarchy import linear

    grid = _rotating_grid(6, 9)
    parallel.set_jobs(1)
    whole = infer(grid)
    split = []
    runs = parallel.runs
    # every (d, s) cluster a part of its own and every step cluster a run of its own, as a
    # scene of millions of consecutive pairs has them, on three workers
    monkeypatch.setattr(linear, "_PART", 1)
    monkeypatch.setattr(linear, "_SPLIT", 0)
    monkeypatch.setattr(linear, "_BATCH", 1)
    monkeypatch.setattr(parallel, "runs", lambda *a: split.append(runs(*a)) or split[-1])
    parallel.set_jobs(3)
    parts = infer(grid)
    assert max(len(r) for r in split) >= 2
    assert format_grammar(parts.grammar) == format_grammar(whole.grammar) and parts.log == whole.log


def test_threads_switch_often_within_the_block_only() -> None:
    """The interval is shortened inside the block (never lengthened) and restored after it, even on error."""
    before = sys.getswitchinterval()
    try:
        sys.setswitchinterval(0.005)
        with parallel.switching_often():
            assert sys.getswitchinterval() == pytest.approx(parallel.SWITCH_INTERVAL, abs=1e-5)
        assert sys.getswitchinterval() == pytest.approx(0.005, abs=1e-5)
        sys.setswitchinterval(0.0002)
        with pytest.raises(ValueError), parallel.switching_often():
            assert sys.getswitchinterval() == pytest.approx(0.0002, abs=1e-5)
            raise ValueError
        assert sys.getswitchinterval() == pytest.approx(0.0002, abs=1e-5)
    finally:
        sys.setswitchinterval(before)


def test_runs_cover_every_item_once_in_order() -> None:
    _runs = parallel.runs
    assert _runs([], 10) == []
    assert _runs([5, 5], 10) == [(0, 2)]
    for sizes in ([300_000] * 5, [1, 900_000, 1, 1], [400_000, 1], [700_000] * 9, [3_000_000, 10, 10]):
        for cap in (1, 500_000, 10**9):
            runs = _runs(sizes, cap)
            assert runs[0][0] == 0 and runs[-1][1] == len(sizes)
            assert all(a < b for a, b in runs) and all(x[1] == y[0] for x, y in itertools.pairwise(runs))
            # no run holds more than the cap unless it is a single item
            assert all(sum(sizes[a:b]) <= cap or b - a == 1 for a, b in runs)


def test_mean_shift_binned_in_blocks_is_the_same(monkeypatch) -> None:
    from lsys_core.hierarchy import clustering

    pts = np.random.default_rng(3).normal(size=(500, 3)) * 3.0
    whole = clustering.mean_shift(pts)
    monkeypatch.setattr(clustering, "_BLOCK", 7)
    blocks = clustering.mean_shift(pts)
    np.testing.assert_array_equal(blocks[0], whole[0])
    np.testing.assert_array_equal(blocks[1], whole[1])


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc malloc arenas")
def test_one_malloc_arena_is_asked_for_on_glibc() -> None:
    import platform

    assert (platform.libc_ver()[0] == "glibc") == parallel.ONE_ARENA


_FAULTS = """
import resource, sys
import numpy as np
from lsys_core import parallel
if sys.argv[1] == "keep":
    assert parallel.keep_freed_memory()
def touch():
    a = np.ones(8 << 20)  # 64 MiB, above glibc's largest own threshold for pages of their own
    del a
touch()
before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
for _ in range(5):
    touch()
print(resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before)
"""


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc malloc")
def test_a_command_process_reuses_freed_large_arrays() -> None:
    import platform
    import subprocess

    if platform.libc_ver()[0] != "glibc":
        pytest.skip("glibc only")

    def faults(mode: str) -> int:
        out = subprocess.run(
            [sys.executable, "-c", _FAULTS, mode], capture_output=True, text=True, check=True
        )
        return int(out.stdout)

    # 64 MiB given back and cleared again (page faults: 2,720 here with huge pages) five times,
    # unless kept for reuse (0 here)
    assert faults("keep") * 10 < faults("plain")


@pytest.mark.parametrize("seed", range(3))
def test_clusters_linked_in_parts_are_linked_as_at_once(seed, restore_jobs, monkeypatch) -> None:
    from lsys_core.hierarchy import chains

    rng = np.random.default_rng(seed)
    n_nodes, n_pairs = 300, 4_000
    src, dst = rng.integers(0, n_nodes, n_pairs), rng.integers(0, n_nodes, n_pairs)
    sizes = rng.integers(1, 400, 30)
    sizes = sizes[np.cumsum(sizes) <= n_pairs]
    members = np.split(rng.permutation(n_pairs)[: sizes.sum()], np.cumsum(sizes)[:-1])
    clusters = [np.sort(m) for m in members]
    costs = np.round(rng.uniform(0, 3, int(sizes.sum())), 1)  # ties: pair order decides
    monkeypatch.setattr(chains, "_SPLIT", 10)
    runs = {}
    for jobs in (1, 2, 3):
        parallel.set_jobs(jobs)
        assert len(chains._parts(sizes, jobs)) == min(jobs, sizes.size)
        runs[jobs] = chains.link_clusters(clusters, costs, src, dst, n_nodes)
    for jobs in (2, 3):
        for a, b in zip(runs[1], runs[jobs], strict=True):
            assert a.chains.tolist() == b.chains.tolist()
            assert (
                np.array_equal(a.used, b.used)
                and np.array_equal(a.src, b.src)
                and np.array_equal(a.dst, b.dst)
            )
