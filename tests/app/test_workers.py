"""LatestRunner: newest result wins, cancellation through the token, errors as messages, clean shutdown."""

from __future__ import annotations

import threading
import time

from app.workers import LatestRunner, ProcessCompute
from lsys_core.errors import InferenceError


def _slow_echo(request, cancel, progress):
    """Return the request after ~0.5 s unless cancelled (checks the token every 5 ms)."""
    for i in range(100):
        cancel.check()
        progress("work", i / 100)
        time.sleep(0.005)
    return request


def test_newest_result_wins_and_previous_job_is_cancelled(qtbot):
    seen: list[tuple[object, bool]] = []
    inside = threading.Event()

    def compute(request, cancel, progress):
        inside.set()
        try:
            return _slow_echo(request, cancel, progress)
        finally:
            seen.append((request, cancel.cancelled))

    runner = LatestRunner(compute, name="lsys-test")
    results = []
    runner.resultReady.connect(results.append)
    runner.submit(1)
    # job 1 is computing (not only handed to the worker thread, which may not have run yet)
    qtbot.waitUntil(inside.is_set, timeout=120_000)
    runner.submit(2)
    runner.submit(3)
    qtbot.waitUntil(lambda: not runner.busy, timeout=120_000)
    assert results == [3]
    # job 1 was cancelled through its token, job 2 never started
    assert seen[0] == (1, True)
    assert [r for r, _ in seen] == [1, 3]
    assert runner.shutdown()


def test_debounce_runs_only_the_last_request(qtbot):
    calls = []

    def compute(request, cancel, progress):
        calls.append(request)
        return request

    runner = LatestRunner(compute, debounce_ms=80, name="lsys-test")
    results = []
    runner.resultReady.connect(results.append)
    for i in range(5):
        runner.submit(i)
        qtbot.wait(10)
    assert runner.busy
    qtbot.waitUntil(lambda: not runner.busy, timeout=120_000)
    assert calls == [4] and results == [4]
    runner.shutdown()


def test_failure_is_reported_as_message(qtbot):
    def compute(request, cancel, progress):
        if request == "bad":
            raise InferenceError("the scene has no drawable elements")
        raise ZeroDivisionError("boom")

    runner = LatestRunner(compute, name="lsys-test")
    messages = []
    runner.failed.connect(messages.append)
    with qtbot.waitSignal(runner.failed, timeout=120_000):
        runner.submit("bad")
    with qtbot.waitSignal(runner.failed, timeout=120_000):
        runner.submit("bug")
    assert messages[0] == "the scene has no drawable elements"
    assert messages[1].startswith("internal error (ZeroDivisionError")
    runner.shutdown()


def test_progress_reaches_ui_thread_and_cancel_drops_result(qtbot):
    runner = LatestRunner(_slow_echo, name="lsys-test")
    stages = []
    results = []
    main = threading.current_thread()
    runner.progress.connect(lambda s, f: stages.append((s, threading.current_thread() is main)))
    runner.resultReady.connect(results.append)
    runner.submit("x")
    qtbot.waitUntil(lambda: len(stages) > 2, timeout=120_000)
    runner.cancel()
    qtbot.waitUntil(lambda: not runner.busy, timeout=120_000)
    assert results == []
    assert all(on_main for _, on_main in stages)
    assert runner.shutdown()


def test_shutdown_joins_running_worker(qtbot):
    runner = LatestRunner(_slow_echo, name="lsys-test-shutdown")
    runner.submit("x")
    qtbot.waitUntil(lambda: runner.running, timeout=120_000)
    assert runner.shutdown(timeout=60)
    assert not [t for t in threading.enumerate() if t.name == "lsys-test-shutdown"]
    runner.submit("ignored after shutdown")
    assert not runner.busy


def test_process_compute_returns_results_and_cancels(qtbot):
    compute = ProcessCompute(_slow_echo)
    try:
        runner = LatestRunner(compute, name="lsys-test-proc")
        results = []
        stages = []
        runner.resultReady.connect(results.append)
        runner.progress.connect(lambda s, f: stages.append(s))
        runner.submit("first")
        qtbot.waitUntil(lambda: bool(stages), timeout=120_000)  # the process started and reports
        runner.submit("second")
        qtbot.waitUntil(lambda: not runner.busy, timeout=120_000)
        assert results == ["second"]
        runner.shutdown()
    finally:
        compute.close()


def test_signal_emit_keeps_reference_counts():
    """PySide6 6.12.0's ``emit`` returns ``True`` without a reference: every emit from Python
    then frees a reference it does not own, until the interpreter aborts (pinned out in
    pyproject.toml); fail early if such a version is installed."""
    import sys

    from PySide6.QtCore import QObject, Signal

    class Probe(QObject):
        ping = Signal(int)

    probe = Probe()
    before = sys.getrefcount(True)
    for i in range(50):
        probe.ping.emit(i)
    assert sys.getrefcount(True) >= before


def _stubborn(request, cancel, progress):
    """Ignore the cancel token for a long time (a stage that never checks it)."""
    progress("stuck", 0.0)
    time.sleep(30)
    return request


def test_process_that_ignores_cancel_is_killed_and_start_never_blocks(qtbot):
    from app import worker_process as workers

    compute = ProcessCompute(_stubborn)
    try:
        runner = LatestRunner(compute, name="lsys-test-stubborn")
        stages = []
        runner.progress.connect(lambda s, f: stages.append(s))
        runner.submit("x")
        qtbot.waitUntil(lambda: bool(stages), timeout=120_000)
        t0 = time.perf_counter()
        compute.start()  # a job holds the process: returns at once
        assert time.perf_counter() - t0 < 10  # not blocked by the 30 s job (a hang guard, not a speed check)
        runner.cancel()
        qtbot.waitUntil(lambda: not runner.busy, timeout=int((workers.CANCEL_GRACE_S + 5) * 1000))
        assert time.perf_counter() - t0 < 25  # killed after the grace period, not after the 30 s job
        assert compute._proc is None  # killed; the next request starts a new one
        runner.shutdown()
    finally:
        compute.close()
