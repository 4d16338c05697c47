"""Background computation for the editor: request → compute → apply, the newest result wins.

With :mod:`app.worker_process`, the only module of the editor that starts threads.  A
:class:`LatestRunner` takes requests on the UI thread (a snapshot of immutable values),
computes them one at a time on a worker thread, and hands the result back to the UI thread
through a queued signal.  A new request cancels the running computation through its
:class:`~lsys_core.cancel.CancelToken`, replaces any request still waiting, and only the result
of the newest request is applied.  Requests can be debounced so that a slider drag runs one
computation per pause, not per pixel.

Work that holds the GIL for long stretches (pure-Python loops) starves the UI thread; such work
runs in a worker process instead (:class:`~app.worker_process.ProcessCompute`, the same
request → compute → apply interface): the worker thread then only waits on a pipe,
cancellation is forwarded to the process's own token, and a process that ignores it is killed.
Measured with ``tests/bench/bench_editor.py`` (2 cores): inference of a 1,200-element scene in
a worker thread stalled the UI thread for 80–110 ms at worst; in a worker process, under 5 ms.
Inference therefore runs in a process; derivation and rendering (numpy and skia, short GIL
holds) in threads, whose cancel tokens also share the GIL at every check
(:class:`~lsys_core.cancel.CancelToken` ``share_gil``: many short numpy calls otherwise keep
the UI thread out for tens of milliseconds).
"""

from __future__ import annotations

import logging
import threading
import time
import traceback
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from PySide6.QtCore import QObject, Qt, QTimer, Signal

from lsys_core.cancel import CancelToken
from lsys_core.errors import Cancelled, LsysError

from .worker_process import (
    PROGRESS_INTERVAL,
    Compute,
    ProcessCompute,
    RemoteBug,
    RemoteError,
    error_message,
)

__all__ = ["Compute", "LatestRunner", "ProcessCompute", "RemoteBug", "RemoteError", "error_message"]

log = logging.getLogger(__name__)


class _JobSignals(QObject):
    """Signals a worker thread emits; they are queued to the runner on the UI thread."""

    progress = Signal(int, str, float)
    done = Signal(int, object)
    failed = Signal(int, str)
    cancelled = Signal(int)


@dataclass
class _Job:
    generation: int
    request: Any
    token: CancelToken


class LatestRunner(QObject):
    """Run a computation off the UI thread, one job at a time, applying only the newest result.

    Parameters
    ----------
    compute : callable
        ``compute(request, cancel, progress) -> result``, called on a worker thread; it must
        only read ``request`` (an immutable snapshot) and check ``cancel`` regularly.
    debounce_ms : int
        Delay before a submitted request starts; every new request restarts the delay.
    name : str
        Name of the worker threads (for logs and debuggers).
    prepare : callable, optional
        ``prepare(request) -> request``, called on the UI thread just before a job starts, to
        complete the snapshot with resources that depend on what is on screen at that moment.
    finish_running : callable, optional
        ``finish_running(request) -> bool`` of the running job's request: when it is true (a
        draft during a drag), a new request does not cancel that job, and its result is still
        delivered; the newest request starts when it ends.  So frames keep coming while the pointer moves faster than they are made
        (cancelling them, a fast drag showed nothing until the pointer stopped).

    Signals
    -------
    started()
        A job started on the worker thread.
    progress(stage, fraction)
        Progress of the newest job.
    resultReady(result)
        The newest request's result, on the UI thread.
    failed(message)
        The newest request failed; ``message`` is one readable line.
    busyChanged()
        :attr:`busy` changed.
    """

    started = Signal()
    progress = Signal(str, float)
    resultReady = Signal(object)
    failed = Signal(str)
    busyChanged = Signal()

    def __init__(
        self,
        compute: Compute,
        *,
        debounce_ms: int = 0,
        name: str = "worker",
        prepare: Callable[[Any], Any] | None = None,
        finish_running: Callable[[], bool] | None = None,
        parent: QObject | None = None,
    ) -> None:
        super().__init__(parent)
        self._compute = compute
        self._prepare = prepare
        self.finish_running: Callable[[Any], bool] = finish_running or (lambda _request: False)
        self._name = name
        self._generation = 0
        self._pending: tuple[int, Any] | None = None
        self._running: _Job | None = None
        self._busy = False
        self._closed = False
        # One long-lived worker thread per runner (started on the first job): starting a thread
        # per job would cost the UI thread milliseconds each time.
        self._thread: threading.Thread | None = None
        self._cv = threading.Condition()
        self._handoff: _Job | None = None
        self._stop = False
        self._signals = _JobSignals()
        queued = Qt.ConnectionType.QueuedConnection
        self._signals.progress.connect(self._on_progress, queued)
        self._signals.done.connect(self._on_done, queued)
        self._signals.failed.connect(self._on_failed, queued)
        self._signals.cancelled.connect(self._on_cancelled, queued)
        self._timer = QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.setInterval(debounce_ms)
        self._timer.timeout.connect(self._start_pending)

    # -- requests -------------------------------------------------------------------------
    def submit(self, request: Any, *, immediate: bool = False) -> None:
        """Ask for ``request`` to be computed; supersedes every earlier request.

        The running job (if any) is cancelled through its token; the new request starts when
        it has stopped, after the debounce delay unless ``immediate``.
        """
        if self._closed:
            return
        self._generation += 1
        self._pending = (self._generation, request)
        if self._running is not None and not self.finish_running(self._running.request):
            self._running.token.cancel()
        if immediate or self._timer.interval() <= 0:
            self._timer.stop()
            self._start_pending()
        else:
            self._timer.start()
        self._update_busy()

    def cancel(self) -> None:
        """Drop the waiting request and cancel the running job; no result will be applied."""
        self._generation += 1
        self._pending = None
        self._timer.stop()
        if self._running is not None:
            self._running.token.cancel()
        self._update_busy()

    def shutdown(self, timeout: float = 10.0) -> bool:
        """Cancel everything and wait for the worker thread to end.

        Returns
        -------
        bool
            Whether the worker thread has ended within ``timeout`` seconds.
        """
        self.cancel()
        self._closed = True
        with self._cv:
            self._stop = True
            self._cv.notify()
        if self._thread is not None:
            self._thread.join(timeout)
            if self._thread.is_alive():
                log.warning("%s: worker thread still running after %.1f s", self._name, timeout)
                return False
            self._thread = None
        self._running = None
        self._update_busy()
        return True

    @property
    def busy(self) -> bool:
        """Whether a request is waiting (debounce) or a job is running."""
        return self._running is not None or self._pending is not None

    @property
    def running(self) -> bool:
        """Whether a job is running on the worker thread."""
        return self._running is not None

    # -- internals (UI thread) ---------------------------------------------------------------
    def _update_busy(self) -> None:
        busy = self.busy
        if busy != self._busy:
            self._busy = busy
            self.busyChanged.emit()

    def _start_pending(self) -> None:
        if self._running is not None or self._pending is None or self._closed:
            return
        if self._timer.isActive():
            return
        generation, request = self._pending
        self._pending = None
        if self._prepare is not None:
            request = self._prepare(request)
        job = _Job(generation, request, CancelToken(share_gil=True))
        self._running = job
        with self._cv:
            self._handoff = job
            self._cv.notify()
        if self._thread is None:
            self._thread = threading.Thread(target=self._loop, name=self._name, daemon=True)
            self._thread.start()
        self.started.emit()

    def _finish(self, generation: int) -> bool:
        """Forget the finished job; return whether its result is the newest."""
        job = self._running
        if job is not None and job.generation == generation:
            self._running = None
        return generation == self._generation

    def _after(self) -> None:
        self._start_pending()
        self._update_busy()

    def _on_progress(self, generation: int, stage: str, fraction: float) -> None:
        if generation == self._generation:
            self.progress.emit(stage, fraction)

    def _on_done(self, generation: int, result: Any) -> None:
        job = self._running
        newest = self._finish(generation)
        finished = job is not None and job.generation == generation and self._pending is not None
        if newest or (finished and self.finish_running(job.request)):  # (a drag's draft: shown)
            self._update_busy()
            self.resultReady.emit(result)
        self._after()

    def _on_failed(self, generation: int, message: str) -> None:
        newest = self._finish(generation)
        if newest:
            self._update_busy()
            self.failed.emit(message)
        self._after()

    def _on_cancelled(self, generation: int) -> None:
        self._finish(generation)
        self._after()

    # -- worker thread -------------------------------------------------------------------------
    def _loop(self) -> None:
        while True:
            with self._cv:
                while self._handoff is None and not self._stop:
                    self._cv.wait()
                if self._stop:
                    return
                job, self._handoff = self._handoff, None
            self._work(job)

    def _work(self, job: _Job) -> None:
        signals = self._signals
        last = {"stage": None, "t": 0.0}

        def progress(stage: str, fraction: float) -> None:
            now = time.monotonic()
            if stage != last["stage"] or fraction >= 1.0 or now - last["t"] >= PROGRESS_INTERVAL:
                last["stage"], last["t"] = stage, now
                signals.progress.emit(job.generation, stage, float(fraction))

        try:
            job.token.check()
            result = self._compute(job.request, job.token, progress)
        except Cancelled:
            signals.cancelled.emit(job.generation)
        except Exception as exc:
            if not isinstance(exc, (LsysError, RemoteBug)):
                log.error("%s failed:\n%s", self._name, traceback.format_exc())
            signals.failed.emit(job.generation, error_message(exc))
        else:
            signals.done.emit(job.generation, result)
